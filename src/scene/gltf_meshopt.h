// EXT_meshopt_compression (gltfpack's output; docs/loading.md, "Compressed glTF"): bufferViews whose
// bytes are stored compressed in another buffer, decoded with meshoptimizer's own decoders.
//
// How it fits tinygltf: the uncompressed bytes belong to a "fallback" buffer that has no data of its own
// (no uri, or a GLB buffer past the BIN chunk), which tinygltf would refuse. So before tinygltf reads the
// file, meshopt_stand_in gives each fallback buffer a one-byte stand-in and remembers its real size; after,
// meshopt_decode sizes those buffers and decodes every compressed bufferView into its place. A file
// without the extension is left untouched.
//
// Errors: a message naming the bufferView or buffer (a compressed stream that does not decode, a span
// outside its buffer, an unknown mode or filter); the caller reports it with the file's name.
#ifndef LM_GLTF_MESHOPT_H
#define LM_GLTF_MESHOPT_H

#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace tinygltf {
class Model;
}

struct MeshoptFallback {
    size_t buffer;     // its index in the file's buffers
    size_t byte_length; // its real size
};

// j: the file's JSON, its fallback buffers given their stand-ins (the caller writes j back into the file
// when fallbacks is not empty). Returns an error message, empty on success.
std::string meshopt_stand_in(nlohmann::json &j, bool glb, std::vector<MeshoptFallback> &fallbacks);
// Every bufferView with EXT_meshopt_compression decoded into its buffer. Returns an error, empty on success.
std::string meshopt_decode(tinygltf::Model &m, const std::vector<MeshoptFallback> &fallbacks);

#endif
