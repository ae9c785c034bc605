// Giving an accessor values of its own: the loader's steps that make an accessor's data anew (sparse
// accessors made dense, Draco streams decoded) store it in a buffer and bufferView of its own.
#ifndef LM_GLTF_VIEWS_H
#define LM_GLTF_VIEWS_H

#include <tiny_gltf.h>

#include <utility>
#include <vector>

// Accessor `acc` of m now reads `bytes`, from offset 0 of a new buffer and bufferView, densely.
inline void gltf_own_view(tinygltf::Model &m, size_t acc, std::vector<unsigned char> &&bytes)
{
    tinygltf::Buffer b;
    b.data = std::move(bytes);
    tinygltf::BufferView v;
    v.buffer = int(m.buffers.size());
    v.byteLength = b.data.size();
    m.buffers.push_back(std::move(b));
    m.bufferViews.push_back(std::move(v));
    tinygltf::Accessor &a = m.accessors[acc];
    a.bufferView = int(m.bufferViews.size()) - 1;
    a.byteOffset = 0;
    a.sparse.isSparse = false;
}

#endif
