// KHR_draco_mesh_compression decoded with Draco (gltf_draco.h).
#include "gltf_draco.h"
#include "gltf_views.h"

#include <tiny_gltf.h>

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <cstdint>
#include <cstring>
#include <memory>

namespace {

const char k_ext[] = "KHR_draco_mesh_compression";

template <typename T>
bool convert_points(const draco::PointAttribute &att, size_t points, int ncomp, std::vector<unsigned char> &out)
{
    out.resize(points * size_t(ncomp) * sizeof(T));
    T *dst = reinterpret_cast<T *>(out.data());
    for (size_t p = 0; p < points; p++)
        if (!att.ConvertValue<T>(att.mapped_index(draco::PointIndex(uint32_t(p))), int8_t(ncomp), dst + p * size_t(ncomp)))
            return false;
    return true;
}

// The decoded values of attribute `att` for every point, in accessor a's component type.
bool attribute_bytes(const draco::PointAttribute &att, const tinygltf::Accessor &a, size_t points,
                     std::vector<unsigned char> &out)
{
    int n = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    if (n <= 0 || att.num_components() < n)
        return false;
    switch (a.componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return convert_points<float>(att, points, n, out);
    case TINYGLTF_COMPONENT_TYPE_BYTE: return convert_points<int8_t>(att, points, n, out);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return convert_points<uint8_t>(att, points, n, out);
    case TINYGLTF_COMPONENT_TYPE_SHORT: return convert_points<int16_t>(att, points, n, out);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return convert_points<uint16_t>(att, points, n, out);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return convert_points<uint32_t>(att, points, n, out);
    default: return false;
    }
}

std::string where(size_t mesh, size_t prim) { return "mesh " + std::to_string(mesh) + " primitive " + std::to_string(prim) + " (" + k_ext + ")"; }

// The decoded triangles as accessor `acc`'s indices (32-bit: the loader reads any index type).
std::string set_indices(tinygltf::Model &m, int acc, const draco::Mesh &mesh, const std::string &at)
{
    if (acc < 0 || size_t(acc) >= m.accessors.size())
        return at + ": its indices accessor is out of range";
    tinygltf::Accessor &a = m.accessors[size_t(acc)];
    size_t faces = mesh.num_faces();
    if (a.count != 3 * faces)
        return at + ": " + std::to_string(faces) + " triangles decoded, its indices accessor has " + std::to_string(a.count) + " indices";
    std::vector<unsigned char> bytes(3 * faces * sizeof(uint32_t));
    uint32_t *out = reinterpret_cast<uint32_t *>(bytes.data());
    for (size_t f = 0; f < faces; f++)
        for (int k = 0; k < 3; k++)
            out[3 * f + size_t(k)] = mesh.face(draco::FaceIndex(uint32_t(f)))[k].value();
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.type = TINYGLTF_TYPE_SCALAR;
    gltf_own_view(m, size_t(acc), std::move(bytes));
    return "";
}

std::string decode_primitive(tinygltf::Model &m, tinygltf::Primitive &p, const tinygltf::Value &ext, const std::string &at)
{
    if (!ext.IsObject() || !ext.Has("bufferView") || !ext.Get("bufferView").IsNumber() || !ext.Has("attributes") ||
        !ext.Get("attributes").IsObject())
        return at + ": bufferView or attributes missing";
    int view = ext.Get("bufferView").GetNumberAsInt();
    if (view < 0 || size_t(view) >= m.bufferViews.size())
        return at + ": bufferView " + std::to_string(view) + " out of range";
    const tinygltf::BufferView &v = m.bufferViews[size_t(view)];
    if (v.buffer < 0 || size_t(v.buffer) >= m.buffers.size() || v.byteOffset > m.buffers[size_t(v.buffer)].data.size() ||
        v.byteLength > m.buffers[size_t(v.buffer)].data.size() - v.byteOffset)
        return at + ": bufferView " + std::to_string(view) + " lies outside its buffer";
    draco::DecoderBuffer in;
    in.Init(reinterpret_cast<const char *>(m.buffers[size_t(v.buffer)].data.data() + v.byteOffset), v.byteLength);
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&in);
    if (!decoded.ok() || !decoded.value())
        return at + ": the Draco stream does not decode (" + (decoded.ok() ? "no mesh" : decoded.status().error_msg_string()) + ")";
    std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
    size_t points = mesh->num_points();
    std::string err = p.indices >= 0 ? set_indices(m, p.indices, *mesh, at) : "";
    const tinygltf::Value &names = ext.Get("attributes");
    for (const std::string &name : names.Keys()) {
        auto acc = p.attributes.find(name);
        const tinygltf::Value &id = names.Get(name);
        if (!err.empty() || acc == p.attributes.end())
            continue; // an attribute the primitive does not name: nothing reads it
        const draco::PointAttribute *att = id.IsNumber() ? mesh->GetAttributeByUniqueId(uint32_t(id.GetNumberAsInt())) : nullptr;
        if (!att || acc->second < 0 || size_t(acc->second) >= m.accessors.size())
            return at + ": attribute " + name + " is not in the Draco stream";
        tinygltf::Accessor &a = m.accessors[size_t(acc->second)];
        std::vector<unsigned char> bytes;
        if (a.count != points)
            return at + ": " + std::to_string(points) + " points decoded, " + name + "'s accessor has " + std::to_string(a.count);
        if (!attribute_bytes(*att, a, points, bytes))
            return at + ": attribute " + name + " does not convert to its accessor's type";
        gltf_own_view(m, size_t(acc->second), std::move(bytes));
    }
    return err;
}

} // namespace

bool draco_stand_in(nlohmann::json &j)
{
    bool changed = false;
    if (!j.is_object() || !j.contains("meshes") || !j["meshes"].is_array() || !j.contains("accessors") ||
        !j["accessors"].is_array())
        return false;
    nlohmann::json &accessors = j["accessors"];
    for (nlohmann::json &mesh : j["meshes"]) {
        if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array())
            continue;
        for (nlohmann::json &p : mesh["primitives"]) {
            if (!p.is_object() || !p.contains("extensions") || !p["extensions"].is_object() ||
                !p["extensions"].contains(k_ext) || !p["extensions"][k_ext].is_object() || !p.contains("indices"))
                continue;
            const nlohmann::json &ext = p["extensions"][k_ext], &idx = p["indices"];
            if (!idx.is_number_unsigned() || idx.get<size_t>() >= accessors.size() || !ext.contains("bufferView"))
                continue;
            nlohmann::json &acc = accessors[idx.get<size_t>()];
            if (acc.is_object() && !acc.contains("bufferView")) {
                acc["bufferView"] = ext["bufferView"];
                changed = true;
            }
        }
    }
    return changed;
}

std::string draco_decode(tinygltf::Model &m)
{
    for (size_t i = 0; i < m.meshes.size(); i++)
        for (size_t k = 0; k < m.meshes[i].primitives.size(); k++) {
            tinygltf::Primitive &p = m.meshes[i].primitives[k];
            auto e = p.extensions.find(k_ext);
            if (e == p.extensions.end())
                continue;
            std::string err = decode_primitive(m, p, e->second, where(i, k));
            if (!err.empty())
                return err;
        }
    return "";
}
