// EXT_meshopt_compression decoded with meshoptimizer (gltf_meshopt.h).
#include "gltf_meshopt.h"

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <meshoptimizer.h>

#include <cmath>
#include <cstdint>
#include <cstring>

namespace {

const char k_ext[] = "EXT_meshopt_compression";

// A buffer whose bytes only decoding gives: the extension says so, or (in a GLB) it has no uri and is not
// the BIN chunk's buffer 0.
bool is_fallback(const nlohmann::json &buf, size_t i, bool glb)
{
    if (!buf.is_object())
        return false;
    auto e = buf.find("extensions");
    if (e != buf.end() && e->is_object() && e->contains(k_ext) && (*e)[k_ext].is_object() &&
        (*e)[k_ext].value("fallback", false))
        return !buf.contains("uri") || (glb && i > 0);
    return false;
}

// A number the extension gives, checked to be a whole number in [0, max].
bool whole(const tinygltf::Value &o, const char *key, double max, size_t &out, bool required = true)
{
    if (!o.Has(key))
        return !required && (out = 0, true);
    const tinygltf::Value &v = o.Get(key);
    if (!v.IsNumber())
        return false;
    double d = v.GetNumberAsDouble();
    if (!(d >= 0.0 && d <= max && std::floor(d) == d))
        return false;
    out = size_t(d);
    return true;
}

std::string view_error(size_t i, const std::string &what) { return "bufferView " + std::to_string(i) + " (" + k_ext + "): " + what; }

// Decodes view i, whose extension is ext, into its own buffer's bytes.
std::string decode_view(tinygltf::Model &m, size_t i, const tinygltf::Value &ext)
{
    tinygltf::BufferView &v = m.bufferViews[i];
    size_t src_buffer, src_offset, src_length, stride, count;
    if (!whole(ext, "buffer", double(m.buffers.size()) - 1.0, src_buffer) ||
        !whole(ext, "byteOffset", 4294967295.0, src_offset, false) || !whole(ext, "byteLength", 4294967295.0, src_length) ||
        !whole(ext, "byteStride", 256.0, stride) || !whole(ext, "count", 4294967295.0, count) || stride == 0)
        return view_error(i, "buffer, byteOffset, byteLength, byteStride or count missing or out of range");
    std::string mode = ext.Has("mode") && ext.Get("mode").IsString() ? ext.Get("mode").Get<std::string>() : "";
    std::string filter = ext.Has("filter") && ext.Get("filter").IsString() ? ext.Get("filter").Get<std::string>() : "NONE";
    const std::vector<unsigned char> &src = m.buffers[src_buffer].data;
    if (src_offset > src.size() || src_length > src.size() - src_offset)
        return view_error(i, "its compressed bytes lie outside buffer " + std::to_string(src_buffer));
    if (v.buffer < 0 || size_t(v.buffer) >= m.buffers.size())
        return view_error(i, "no buffer to decode into");
    std::vector<unsigned char> &dst = m.buffers[size_t(v.buffer)].data;
    uint64_t bytes = uint64_t(count) * stride;
    if (bytes > v.byteLength || v.byteOffset > dst.size() || bytes > dst.size() - v.byteOffset)
        return view_error(i, std::to_string(count) + " x " + std::to_string(stride) + " bytes do not fit the view");
    unsigned char *out = dst.data() + v.byteOffset;
    const unsigned char *in = src.data() + src_offset;
    int rc;
    if (mode == "ATTRIBUTES")
        rc = stride % 4 ? -1 : meshopt_decodeVertexBuffer(out, count, stride, in, src_length);
    else if (mode == "TRIANGLES")
        rc = (stride != 2 && stride != 4) || count % 3 ? -1 : meshopt_decodeIndexBuffer(out, count, stride, in, src_length);
    else if (mode == "INDICES")
        rc = stride != 2 && stride != 4 ? -1 : meshopt_decodeIndexSequence(out, count, stride, in, src_length);
    else
        return view_error(i, "unknown mode \"" + mode + "\"");
    if (rc != 0)
        return view_error(i, "the " + mode + " stream of " + std::to_string(count) + " elements of " +
                                 std::to_string(stride) + " bytes does not decode");
    if (filter == "OCTAHEDRAL" && (stride == 4 || stride == 8))
        meshopt_decodeFilterOct(out, count, stride);
    else if (filter == "QUATERNION" && stride == 8)
        meshopt_decodeFilterQuat(out, count, stride);
    else if (filter == "EXPONENTIAL" && stride % 4 == 0)
        meshopt_decodeFilterExp(out, count, stride);
    else if (filter != "NONE")
        return view_error(i, "filter \"" + filter + "\" with a stride of " + std::to_string(stride));
    return "";
}

} // namespace

std::string meshopt_stand_in(nlohmann::json &j, bool glb, std::vector<MeshoptFallback> &fallbacks)
{
    fallbacks.clear();
    if (!j.is_object() || !j.contains("buffers") || !j["buffers"].is_array())
        return ""; // tinygltf's parser says what is wrong
    nlohmann::json &buffers = j["buffers"];
    for (size_t i = 0; i < buffers.size(); i++) {
        if (!is_fallback(buffers[i], i, glb))
            continue;
        double n = buffers[i].value("byteLength", 0.0);
        if (!(n >= 1.0 && n <= 4294967295.0))
            return "buffer " + std::to_string(i) + " (" + k_ext + " fallback): byteLength out of range";
        fallbacks.push_back({i, size_t(n)});
        buffers[i]["byteLength"] = 1; // one zero byte: tinygltf reads it; meshopt_decode gives it its size
        buffers[i]["uri"] = "data:application/octet-stream;base64,AA==";
    }
    return "";
}

std::string meshopt_decode(tinygltf::Model &m, const std::vector<MeshoptFallback> &fallbacks)
{
    for (const MeshoptFallback &f : fallbacks)
        if (f.buffer < m.buffers.size())
            m.buffers[f.buffer].data.assign(f.byte_length, 0);
    for (size_t i = 0; i < m.bufferViews.size(); i++) {
        auto e = m.bufferViews[i].extensions.find(k_ext);
        if (e == m.bufferViews[i].extensions.end())
            continue;
        if (!e->second.IsObject())
            return view_error(i, "not an object");
        std::string err = decode_view(m, i, e->second);
        if (!err.empty())
            return err;
    }
    return "";
}
