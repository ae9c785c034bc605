// KHR_draco_mesh_compression (docs/loading.md, "Compressed glTF"): primitives whose indices and attributes
// are one Draco-compressed stream in a bufferView, decoded with Debian's Draco (libdraco).
//
// How it fits the loader: after tinygltf has read the file, draco_decode decodes every such primitive and
// gives each accessor the primitive names (its indices and the attributes the extension maps) a buffer
// and bufferView of its own holding the decoded values, in the accessor's own component type; the loader
// then reads them as any other accessor. Whatever uncompressed fallback the file carries is not used.
//
// Errors: a message naming the mesh and primitive (a stream that does not decode, a point or index count
// that does not match its accessor, an attribute the stream lacks); the caller adds the file's name.
#ifndef LM_GLTF_DRACO_H
#define LM_GLTF_DRACO_H

#include <nlohmann/json.hpp>

#include <string>

namespace tinygltf {
class Model;
}

// Before tinygltf reads the file (j: its JSON): a Draco primitive's indices accessor without a bufferView
// (the compressed file's usual form), which tinygltf would refuse, is given the primitive's compressed
// bufferView as a stand-in until draco_decode gives it its own. Returns whether j changed.
bool draco_stand_in(nlohmann::json &j);
// Returns an error message, empty on success (a file without the extension: nothing to do).
std::string draco_decode(tinygltf::Model &m);

#endif
