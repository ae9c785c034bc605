// glTF loading: the one C++ file around tinygltf. It reads tinygltf's model into an lm_scene and leaves
// everything format-independent (decoding, triangulation, normals, node resolution) to scene_build.c.
// Every check against the file's own numbers (indices, accessor spans, bufferViews) is done here:
// tinygltf 2.7 parses the JSON but does not validate those. docs/loading.md lists what is accepted.
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <sys/stat.h>
#include <memory>
#include <new>
#include <omp.h>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

extern "C" {
#include "../core/error.h"
#include "../core/image.h"
#include "../core/log.h"
#include "../core/memory.h"
#include "scene.h"
#include "image_decode.h"
#include "scene_build.h"
#include "sky.h"
#include "../core/vecmath.h"
}
#include "gltf_draco.h"
#include "gltf_meshopt.h"
#include "gltf_views.h"

namespace {

const char *const k_supported_required[] = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                            "KHR_materials_transmission", "KHR_materials_ior",
                                            "KHR_texture_transform", "EXT_texture_webp", "EXT_meshopt_compression",
                                            "KHR_draco_mesh_compression", "KHR_mesh_quantization",
                                            "EXT_lights_image_based"};
// Optional extensions lmgi knows and has no use for, read without a warning: its own export's lightmap
// (a scene lmgi loads is lit again, docs/api.md, "The lightmap in engines").
const char *const k_known_unread[] = {"LMGI_lightmap"};
const size_t k_max_unbacked_elems = 1u << 24;    // accessors without a bufferView (all zeros)
const uint32_t k_glb_json = 0x4E4F534Au, k_glb_bin = 0x004E4942u;

struct SceneDeleter {
    void operator()(lm_scene *s) const { lm_scene_free(s); }
};
using ScenePtr = std::unique_ptr<lm_scene, SceneDeleter>;

// A located accessor: where its elements are and how to decode them.
struct Span {
    const uint8_t *data = nullptr; // null: no bufferView, all zeros
    size_t count = 0, stride = 0;
    int comp_type = 0, ncomp = 0;
    bool normalized = false;
};

template <typename T> T *copy_out(const std::vector<T> &v)
{
    if (v.empty())
        return nullptr;
    T *p = static_cast<T *>(malloc(v.size() * sizeof(T)));
    if (!p)
        throw std::bad_alloc();
    memcpy(p, v.data(), v.size() * sizeof(T));
    return p;
}

template <typename T> T *calloc_n(size_t n)
{
    if (n == 0)
        return nullptr;
    T *p = static_cast<T *>(calloc(n, sizeof(T)));
    if (!p)
        throw std::bad_alloc();
    return p;
}

const tinygltf::Value *ext_obj(const tinygltf::ExtensionMap &m, const char *name)
{
    auto it = m.find(name);
    return it != m.end() && it->second.IsObject() ? &it->second : nullptr;
}

double num(const tinygltf::Value *o, const char *key, double def)
{
    if (!o || !o->Has(key) || !o->Get(key).IsNumber())
        return def;
    return o->Get(key).GetNumberAsDouble();
}

// A number's value, NaN when v is not one (a string, null, absent: what a message then shows as nan).
double number_or_nan(const tinygltf::Value &v) { return v.IsNumber() ? v.GetNumberAsDouble() : NAN; }

// An integer property, or def when absent or not an integer in int range.
int int_prop(const tinygltf::Value *o, const char *key, int def)
{
    double d = num(o, key, NAN);
    return std::isfinite(d) && d >= -2147483648.0 && d <= 2147483647.0 && d == std::floor(d) ? int(d) : def;
}

void vec_or(const std::vector<double> &v, size_t n, const float *def, float *out)
{
    for (size_t i = 0; i < n; i++)
        out[i] = v.size() == n ? float(v[i]) : def[i];
}

bool finite_all(const float *v, size_t n) { return lm_first_nonfinite(v, n) < 0; }

// tinygltf's image callback: keeps the encoded bytes (img->as_is) for Loader::decode_used_images, which decodes only
// the images a material uses, at the size lmgi needs (image_decode.h); decoding every image here held
// them all at full size at once. An image whose bufferView lies outside its buffer is an error: tinygltf
// hands us a pointer it never checked.
bool keep_image_bytes(tinygltf::Image *img, const int idx, std::string *err, std::string *, int, int,
                      const unsigned char *bytes, int size, void *user)
{
    const tinygltf::Model *model = static_cast<const tinygltf::Model *>(user);
    if (img->bufferView >= 0) {
        const tinygltf::BufferView &bv = model->bufferViews[size_t(img->bufferView)]; // range checked by tinygltf
        const tinygltf::Buffer &buf = model->buffers[size_t(bv.buffer)];
        if (!lm_span_fits(bv.byteOffset, 1, 0, bv.byteLength, buf.data.size()) || bv.byteLength > INT32_MAX) {
            *err += "image " + std::to_string(idx) + ": bufferView " + std::to_string(img->bufferView) +
                    " lies outside its buffer\n";
            return false;
        }
    }
    img->image.assign(bytes, bytes + (size > 0 ? size : 0));
    img->as_is = true;
    img->width = img->height = 0;
    return true;
}

std::string first_line(const std::string &s)
{
    size_t e = s.find('\n');
    return e == std::string::npos ? s : s.substr(0, e);
}

class Loader {
  public:
    Loader(const char *path, const lm_load_options *opt, lm_error *err) : path_(path), err_(err)
    {
        strict_ = opt && opt->strict;
        untrusted_ = opt && opt->untrusted;
        if (opt && opt->data) {
            mem_ = static_cast<const unsigned char *>(opt->data);
            mem_size_ = opt->size;
        }
    }
    ~Loader()
    {
        for (lm_texture &t : textures_) // only textures not yet handed to the scene
            free(t.rgba);
    }
    Loader(const Loader &) = delete;
    Loader &operator=(const Loader &) = delete;
    lm_status run(lm_scene **out);

  private:
    lm_status fail(lm_status st, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
    lm_status read_file(std::vector<unsigned char> &bytes);
    lm_status check_glb(const std::vector<unsigned char> &b);
    lm_status check_buffers(const nlohmann::json &j, const std::vector<unsigned char> &b, bool glb);
    lm_status parse(std::vector<unsigned char> &bytes);
    lm_status decode_compressed();
    lm_status stand_in_compressed(nlohmann::json &j, std::vector<unsigned char> &bytes, bool glb);
    lm_status check_extensions();
    lm_status densify_sparse();
    lm_status densify(int acc);
    lm_status locate(int acc, int type, const char *what, const std::string &ctx, Span &sp);
    lm_status read_floats(int acc, int type, bool force_norm, const char *what, const std::string &ctx,
                          std::vector<float> &out, size_t &count);
    int image_of(int tex_index) const;
    lm_status decode_used_images();
    int texture(int tex_index, const std::string &ctx);
    void metal_rough_from_texture(const tinygltf::PbrMetallicRoughness &pbr, lm_material &d);
    lm_status materials();
    lm_status nodes();
    lm_status node_instances();
    lm_status geometry();
    lm_status primitive(int node, int mesh, int prim);
    lm_status animations();
    lm_status finish();
    lm_status sky();
    const tinygltf::Value *ibl_reference(int *scene) const;
    lm_status ibl_sky(const tinygltf::Value &ref, int scene);
    lm_status ibl_params(const tinygltf::Value &light, const std::string &what, float *intensity, float rotation[4]);
    lm_status ibl_faces(const tinygltf::Value &light, const std::string &what, std::vector<uint8_t> faces[6], int *n);
    std::string scene_dir() const;

    const char *path_;
    const unsigned char *mem_ = nullptr; // the scene's bytes when it comes from memory
    size_t mem_size_ = 0;
    lm_error *err_;
    bool strict_ = false, untrusted_ = false;
    std::string escaped_; // untrusted: the first file the scene named outside its folder (refused)
    std::vector<MeshoptFallback> fallbacks_; // EXT_meshopt_compression's buffers that decoding fills
    bool quantized_ = false; // the file uses KHR_mesh_quantization (check_extensions)
    tinygltf::Model model_;
    ScenePtr s_;
    std::vector<int> image_tex_;             // glTF image -> lm texture (-1 not yet converted)
    struct Decoded {                         // an image as decode_used_images left it
        std::vector<uint8_t> rgba;           // 8-bit RGBA; empty: unused or undecodable
        int w = 0, h = 0;
        lm_status status = LM_OK;
        const char *why = "";
    };
    std::vector<Decoded> decoded_;
    std::vector<lm_texture> textures_;
    std::vector<unsigned char> animated_;
    bool need_default_material_ = false;
    bool any_uv1_ = false;
    std::vector<float> pos_, nrm_, uv0_, uv1_;
    std::vector<uint32_t> vnode_, tris_, tnode_;
    std::vector<int> tmat_;
    std::vector<float> portal_local_; // portals' triangles, their nodes' local space, 9 floats each
    std::vector<int> portal_node_;    // and each one's node
};

lm_status Loader::fail(lm_status st, const char *fmt, ...)
{
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return lm_fail(err_, st, "%s: %s", path_, msg);
}

// A regular file is read whole up to 4 GiB (tinygltf takes a 32-bit size); anything else (a pipe, a
// device: /dev/zero never ends) up to k_max_stream_bytes, so no input reads forever; a directory is not
// read at all (an ifstream of one reports a size of 2^63, which tinygltf then allocated). The scene file
// and every file it names (buffers, images: the tinygltf callback below) go through here. Returns an
// empty string, or what was wrong; *format tells a malformed input from an unreadable one.
const uint64_t k_max_file_bytes = UINT32_MAX, k_max_stream_bytes = 256ull << 20;
const float k_max_uv = 1e6f;

std::string read_capped(const char *path, std::vector<unsigned char> &bytes, bool *format)
{
    *format = false;
    struct stat st;
    if (stat(path, &st) != 0)
        return std::string("cannot open file: ") + strerror(errno);
    if (S_ISDIR(st.st_mode))
        return "is a directory, not a file";
    bool regular = S_ISREG(st.st_mode);
    uint64_t cap = regular ? k_max_file_bytes : k_max_stream_bytes;
    char msg[160];
    if (regular && uint64_t(st.st_size) > cap) {
        *format = true;
        snprintf(msg, sizeof msg, "%llu bytes: larger than the 4 GiB a file may have here",
                 (unsigned long long)st.st_size);
        return msg;
    }
    FILE *f = fopen(path, "rb");
    if (!f)
        return std::string("cannot open file: ") + strerror(errno);
    if (regular)
        bytes.reserve(size_t(st.st_size));
    unsigned char buf[65536];
    size_t n;
    while (bytes.size() <= cap && (n = fread(buf, 1, sizeof buf, f)) > 0)
        bytes.insert(bytes.end(), buf, buf + n);
    bool bad = ferror(f);
    fclose(f);
    if (bad)
        return std::string("read error: ") + strerror(errno);
    if (bytes.size() > cap) {
        *format = true;
        snprintf(msg, sizeof msg, "more than %llu MiB from a %s: not a scene file", (unsigned long long)(cap >> 20),
                 regular ? "file" : "device or pipe");
        return msg;
    }
    return "";
}

// Whether `path` lies inside `dir` once both are resolved (realpath: "..", links); *where gets the resolved
// path. A file that does not exist is not inside anything.
bool inside_folder(const std::string &dir, const std::string &path, std::string *where)
{
    char d[PATH_MAX], p[PATH_MAX];
    if (!realpath(dir.c_str(), d) || !realpath(path.c_str(), p)) {
        *where = path;
        return false;
    }
    *where = p;
    size_t n = strlen(d);
    return strncmp(p, d, n) == 0 && (p[n] == '/' || (n == 1 && d[0] == '/'));
}

// The folder rule for a file the scene names (lm_load_options.untrusted): in untrusted mode one outside
// its folder is refused (recorded for the load's error), else read with a warning that says where.
struct Confine {
    std::string dir, *escaped;
    bool untrusted;
    const char *scene;
};

bool confined(const Confine &c, const std::string &path, std::string *err)
{
    std::string where;
    if (inside_folder(c.dir, path, &where))
        return true;
    struct stat st;
    if (stat(path.c_str(), &st) != 0)
        return true; // missing: reported as missing by the reader
    if (c.untrusted) {
        std::string why = path + " lies outside the scene's folder (it is " + where + "): an untrusted scene may "
                          "name only files inside its own folder";
        if (c.escaped->empty())
            *c.escaped = why;
        if (err)
            *err += why + "\n";
        return false;
    }
    lm_warn("%s: reads %s, which lies outside the scene's folder", c.scene, where.c_str());
    return true;
}

// A file the scene names (a buffer, an image): a regular file or nothing (lm_check_regular_file), inside
// the scene's folder when it is untrusted (confined).
bool read_whole_file(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user)
{
    bool format = false;
    out->clear();
    if (user && !confined(*static_cast<const Confine *>(user), path, err))
        return false;
    lm_error e;
    if (lm_check_regular_file(path.c_str(), "the file", &e) != LM_OK) {
        if (err)
            *err += std::string(e.msg) + "\n";
        return false;
    }
    std::string why = read_capped(path.c_str(), *out, &format);
    if (!why.empty() && err)
        *err += path + ": " + why + "\n";
    return why.empty();
}

// Whether a file the scene names exists, by stat alone: tinygltf's own check opens it, and opening a FIFO
// blocks until a writer comes (lmgi info hung on one until killed). read_whole_file then refuses what is
// not a regular file, naming it.
bool file_exists(const std::string &path, void *)
{
    struct stat st;
    return stat(path.c_str(), &st) == 0;
}

// A scene from memory has no directory to find other files in: every file it names "exists", so that
// reading it is refused with the reason rather than reported missing.
bool any_file_exists(const std::string &, void *) { return true; }

bool refuse_external_file(std::vector<unsigned char> *, std::string *err, const std::string &path, void *)
{
    if (err)
        *err += path + ": a scene from memory cannot name external files; embed them (a .glb's buffer or "
                       "data: URIs)\n";
    return false;
}

lm_status Loader::read_file(std::vector<unsigned char> &bytes)
{
    if (mem_) {
        if (mem_size_ > k_max_file_bytes)
            return fail(LM_ERR_FORMAT, "%llu bytes is more than the 4 GiB a scene may have here",
                        (unsigned long long)mem_size_);
        bytes.assign(mem_, mem_ + mem_size_);
        return LM_OK;
    }
    bool format = false;
    std::string why = read_capped(path_, bytes, &format);
    return why.empty() ? LM_OK : fail(format ? LM_ERR_FORMAT : LM_ERR_IO, "%s", why.c_str());
}

uint32_t le32(const unsigned char *p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }

// The GLB container: header, JSON chunk, optional BIN chunk, all lengths inside the file.
lm_status Loader::check_glb(const std::vector<unsigned char> &b)
{
    uint64_t size = b.size();
    if (size < 20)
        return fail(LM_ERR_FORMAT, "truncated .glb: %llu bytes, shorter than the GLB header", (unsigned long long)size);
    if (le32(&b[4]) != 2)
        return fail(LM_ERR_FORMAT, "unsupported GLB container version %u", le32(&b[4]));
    uint64_t total = le32(&b[8]), json_len = le32(&b[12]);
    if (total > size)
        return fail(LM_ERR_FORMAT, "truncated .glb: header says %llu bytes, file has %llu", (unsigned long long)total,
                    (unsigned long long)size);
    if (le32(&b[16]) != k_glb_json)
        return fail(LM_ERR_FORMAT, "malformed .glb: first chunk is not JSON");
    if (20 + json_len > total)
        return fail(LM_ERR_FORMAT, "truncated .glb: JSON chunk of %llu bytes runs past the end", (unsigned long long)json_len);
    uint64_t bin = 20 + ((json_len + 3) & ~3ull);
    if (bin + 8 <= total) {
        uint64_t bin_len = le32(&b[bin]);
        if (le32(&b[bin + 4]) != k_glb_bin)
            return fail(LM_ERR_FORMAT, "malformed .glb: second chunk is not BIN");
        if (bin + 8 + bin_len > total)
            return fail(LM_ERR_FORMAT, "truncated .glb: BIN chunk of %llu bytes runs past the end",
                        (unsigned long long)bin_len);
    }
    return LM_OK;
}

// The file's JSON (a .gltf's text, a .glb's JSON chunk), parsed once for what is checked and stood in
// before tinygltf reads it; discarded when it is not JSON, which tinygltf's parser then says.
static nlohmann::json file_json(const std::vector<unsigned char> &b, bool glb)
{
    size_t json_len = glb ? le32(&b[12]) : b.size(), json_at = glb ? 20 : 0;
    return nlohmann::json::parse(b.begin() + long(json_at), b.begin() + long(json_at + json_len), nullptr, false);
}

// Buffers as glTF requires them (byteLength at least 1; the GLB's own buffer within its BIN chunk),
// checked before tinygltf, which indexes an empty buffer unchecked ("vector::_M_range_check"). Malformed
// JSON (j discarded) is left to tinygltf's parser and its message.
lm_status Loader::check_buffers(const nlohmann::json &j, const std::vector<unsigned char> &b, bool glb)
{
    if (j.is_discarded() || !j.is_object() || !j.contains("buffers") || !j["buffers"].is_array())
        return LM_OK;
    size_t json_len = glb ? le32(&b[12]) : b.size();
    uint64_t bin_len = 0;
    uint64_t bin = 20 + ((uint64_t(json_len) + 3) & ~3ull);
    if (glb && bin + 8 <= le32(&b[8]))
        bin_len = le32(&b[bin]);
    const nlohmann::json &buffers = j["buffers"];
    for (size_t i = 0; i < buffers.size(); i++) {
        const nlohmann::json &buf = buffers[i];
        std::string name = buf.is_object() && buf.contains("name") && buf["name"].is_string() ? buf["name"] : "";
        const char *what = name.c_str();
        if (!buf.is_object() || !buf.contains("byteLength") || !buf["byteLength"].is_number())
            return fail(LM_ERR_FORMAT, "buffer %zu (\"%s\") has no byteLength", i, what);
        double len = buf["byteLength"].get<double>();
        if (!(len >= 1.0))
            return fail(LM_ERR_FORMAT, "buffer %zu (\"%s\"): byteLength %g; glTF requires at least 1", i, what, len);
        if (len > double(k_max_file_bytes)) /* tinygltf would size a vector to it */
            return fail(LM_ERR_FORMAT, "buffer %zu (\"%s\"): byteLength %g is more than the 4 GiB a file may have here",
                        i, what, len);
        if (glb && i == 0 && !buf.contains("uri") && len > double(bin_len))
            return fail(LM_ERR_FORMAT, "buffer 0 (\"%s\"): byteLength %g, but the .glb's BIN chunk holds %llu bytes",
                        what, len, (unsigned long long)bin_len);
    }
    return LM_OK;
}

// The GLB b again, with `json` as its JSON chunk and its BIN chunk as it was.
static std::vector<unsigned char> glb_with_json(const std::vector<unsigned char> &b, const std::string &json)
{
    size_t old_json = le32(&b[12]), rest = 20 + ((old_json + 3) & ~size_t(3)), padded = (json.size() + 3) & ~size_t(3);
    size_t tail = b.size() > rest ? std::min(b.size(), size_t(le32(&b[8]))) - rest : 0;
    std::vector<unsigned char> out(b.begin(), b.begin() + 20);
    auto put32 = [&out](size_t at, uint32_t v) { for (int i = 0; i < 4; i++) out[at + size_t(i)] = (unsigned char)(v >> (8 * i)); };
    put32(8, uint32_t(20 + padded + tail));
    put32(12, uint32_t(padded));
    out.insert(out.end(), json.begin(), json.end());
    out.insert(out.end(), padded - json.size(), ' ');
    out.insert(out.end(), b.begin() + long(rest), b.begin() + long(rest + tail));
    return out;
}

// The compressed glTF's parts that tinygltf would refuse given stand-ins in j (gltf_meshopt.h,
// gltf_draco.h), and the file's bytes rewritten with them; a file with none is left as it is.
lm_status Loader::stand_in_compressed(nlohmann::json &j, std::vector<unsigned char> &bytes, bool glb)
{
    if (j.is_discarded())
        return LM_OK; // tinygltf's parser says what is wrong
    std::string why = meshopt_stand_in(j, glb, fallbacks_);
    if (!why.empty())
        return fail(LM_ERR_FORMAT, "%s", why.c_str());
    if (!draco_stand_in(j) && fallbacks_.empty())
        return LM_OK;
    std::string json = j.dump();
    if (glb)
        bytes = glb_with_json(bytes, json);
    else
        bytes.assign(json.begin(), json.end());
    return LM_OK;
}

// The folder of the scene file, which the files it names are relative to.
std::string Loader::scene_dir() const
{
    std::string p(path_);
    size_t slash = p.find_last_of('/');
    return slash == std::string::npos ? "." : slash == 0 ? "/" : p.substr(0, slash);
}

// What a file that is not glTF is, by its first bytes, for the message that says so: a user who gives
// lmgi a picture, an OBJ or a .blend should hear what it is and what to give instead, not a JSON parser's
// complaint about its first byte. NULL: it may be glTF JSON (it starts with '{').
static const char *not_gltf(const std::vector<unsigned char> &b)
{
    static const struct {
        const char *magic, *what;
    } known[] = {{"\x89PNG", "a PNG image"},        {"\xff\xd8\xff", "a JPEG image"},     {"RIFF", "a RIFF file (WebP, WAV)"},
                 {"BLENDER", "a Blender file"},    {"Kaydara FBX", "an FBX file"},      {"PK\x03\x04", "a zip archive"},
                 {"#?RADIANCE", "a Radiance HDR image"}, {"v/1\x01", "an OpenEXR image"}, {"\x7f" "ELF", "a program"}};
    for (const auto &k : known)
        if (b.size() >= strlen(k.magic) && memcmp(b.data(), k.magic, strlen(k.magic)) == 0)
            return k.what;
    size_t i = 0;
    while (i < b.size() && (b[i] == ' ' || b[i] == '\t' || b[i] == '\r' || b[i] == '\n'))
        i++;
    if (i + 3 <= b.size() && b[i] == 0xef && b[i + 1] == 0xbb && b[i + 2] == 0xbf) // a UTF-8 byte order mark
        return nullptr;
    if (i < b.size() && b[i] == '{')
        return nullptr;
    if (i + 2 <= b.size() && (b[i] == 'v' || b[i] == 'o' || b[i] == 'g') && b[i + 1] == ' ')
        return "text, perhaps a Wavefront OBJ";
    return i < b.size() && b[i] >= 0x20 && b[i] < 0x7f ? "a text file" : "a file lmgi does not know";
}

lm_status Loader::parse(std::vector<unsigned char> &bytes)
{
    bool glb = bytes.size() >= 4 && memcmp(bytes.data(), "glTF", 4) == 0;
    if (const char *what = glb ? nullptr : not_gltf(bytes))
        return fail(LM_ERR_FORMAT, "this is %s, not a glTF scene; lmgi reads glTF 2.0: a .gltf (JSON, with its "
                    ".bin and images beside it) or a .glb (one binary file); export one from your modelling tool "
                    "(Blender: File > Export > glTF 2.0)", what);
    lm_status checked = glb ? check_glb(bytes) : LM_OK;
    if (checked)
        return checked;
    nlohmann::json j = file_json(bytes, glb);
    if ((checked = check_buffers(j, bytes, glb)) || (checked = stand_in_compressed(j, bytes, glb)))
        return checked;
    std::string dir = scene_dir();
    tinygltf::TinyGLTF gltf;
    gltf.SetImageLoader(keep_image_bytes, &model_);
    Confine confine = {dir, &escaped_, untrusted_, path_};
    tinygltf::FsCallbacks fs = {mem_ ? &any_file_exists : &file_exists, &tinygltf::ExpandFilePath,
                                mem_ ? &refuse_external_file : &read_whole_file, &tinygltf::WriteWholeFile,
                                mem_ ? nullptr : &confine};
    gltf.SetFsCallbacks(fs);
    std::string terr, twarn;
    bool ok = glb ? gltf.LoadBinaryFromMemory(&model_, &terr, &twarn, bytes.data(), unsigned(bytes.size()), dir)
                  : gltf.LoadASCIIFromString(&model_, &terr, &twarn, reinterpret_cast<const char *>(bytes.data()),
                                             unsigned(bytes.size()), dir);
    size_t start = 0;
    while (start < twarn.size()) {
        size_t e = twarn.find('\n', start);
        std::string line = twarn.substr(start, e == std::string::npos ? std::string::npos : e - start);
        if (!line.empty())
            lm_warn("%s: %s", path_, line.c_str());
        start = e == std::string::npos ? twarn.size() : e + 1;
    }
    if (!escaped_.empty()) // untrusted: one file outside the folder fails the whole load, image or buffer
        return fail(LM_ERR_IO, "%s", escaped_.c_str());
    if (!ok) {
        std::string why = first_line(terr.empty() ? twarn : terr);
        bool missing = why.find("not found") != std::string::npos || why.find("File open error") != std::string::npos;
        return fail(missing ? LM_ERR_IO : LM_ERR_FORMAT, "%s", why.empty() ? "malformed glTF" : why.c_str());
    }
    return LM_OK;
}

lm_status Loader::check_extensions()
{
    for (const std::string &e : model_.extensionsRequired) {
        bool known = false;
        for (const char *k : k_supported_required)
            known = known || e == k;
        if (!known)
            return fail(LM_ERR_UNSUPPORTED, "required extension %s is not supported", e.c_str());
    }
    std::string ignored;
    for (const std::string &e : model_.extensionsUsed) {
        quantized_ = quantized_ || e == "KHR_mesh_quantization";
        bool known = false;
        for (const char *k : k_supported_required)
            known = known || e == k;
        for (const char *k : k_known_unread)
            known = known || e == k;
        if (!known)
            ignored += (ignored.empty() ? "" : ", ") + e;
    }
    if (!ignored.empty())
        lm_warn("%s: ignoring optional extensions %s (lmgi does not read them)", path_, ignored.c_str());
    return LM_OK;
}

// Finds accessor `acc` and checks its whole element span lies inside its bufferView and buffer.
lm_status Loader::locate(int acc, int type, const char *what, const std::string &ctx, Span &sp)
{
    if (acc < 0 || size_t(acc) >= model_.accessors.size())
        return fail(LM_ERR_FORMAT, "%s: %s accessor %d out of range (%zu accessors)", ctx.c_str(), what, acc,
                    model_.accessors.size());
    const tinygltf::Accessor &a = model_.accessors[size_t(acc)];
    size_t cs = lm_component_size(a.componentType);
    if (a.type != type || cs == 0)
        return fail(LM_ERR_FORMAT, "%s: %s accessor %d has the wrong type or component type", ctx.c_str(), what, acc);
    sp.count = a.count, sp.comp_type = a.componentType, sp.normalized = a.normalized;
    sp.ncomp = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    size_t elem = cs * size_t(sp.ncomp);
    if (a.bufferView < 0) {
        if (a.count > k_max_unbacked_elems)
            return fail(LM_ERR_FORMAT, "%s: %s accessor %d has no bufferView and %zu elements", ctx.c_str(), what,
                        acc, a.count);
        sp.data = nullptr, sp.stride = elem;
        return LM_OK;
    }
    if (size_t(a.bufferView) >= model_.bufferViews.size())
        return fail(LM_ERR_FORMAT, "%s: %s accessor %d: bufferView %d out of range", ctx.c_str(), what, acc,
                    a.bufferView);
    const tinygltf::BufferView &bv = model_.bufferViews[size_t(a.bufferView)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size())
        return fail(LM_ERR_FORMAT, "%s: bufferView %d: buffer %d out of range", ctx.c_str(), a.bufferView, bv.buffer);
    const tinygltf::Buffer &buf = model_.buffers[size_t(bv.buffer)];
    if (!lm_span_fits(bv.byteOffset, 1, 0, bv.byteLength, buf.data.size()))
        return fail(LM_ERR_FORMAT, "%s: bufferView %d (offset %zu, length %zu) exceeds buffer %d of %zu bytes",
                    ctx.c_str(), a.bufferView, bv.byteOffset, bv.byteLength, bv.buffer, buf.data.size());
    sp.stride = bv.byteStride ? bv.byteStride : elem;
    if (sp.stride < elem)
        return fail(LM_ERR_FORMAT, "%s: %s accessor %d: byteStride %zu smaller than its element", ctx.c_str(), what,
                    acc, sp.stride);
    if (!lm_span_fits(a.byteOffset, a.count, sp.stride, elem, bv.byteLength))
        return fail(LM_ERR_FORMAT, "%s: %s accessor %d (offset %zu, %zu elements, stride %zu) exceeds bufferView %d of %zu bytes",
                    ctx.c_str(), what, acc, a.byteOffset, a.count, sp.stride, a.bufferView, bv.byteLength);
    sp.data = buf.data.data() + bv.byteOffset + a.byteOffset;
    return LM_OK;
}

lm_status Loader::read_floats(int acc, int type, bool force_norm, const char *what, const std::string &ctx,
                              std::vector<float> &out, size_t &count)
{
    Span sp;
    lm_status st = locate(acc, type, what, ctx, sp);
    if (st)
        return st;
    count = sp.count;
    out.assign(sp.count * size_t(sp.ncomp), 0.0f);
    // Integer texcoords are normalised whatever the flag says (glTF 2.0 allows no other kind), unless the
    // file uses KHR_mesh_quantization, which allows unnormalised ones (scaled by KHR_texture_transform).
    if (sp.data)
        lm_decode_floats(sp.data, sp.count, sp.stride, sp.comp_type, sp.ncomp,
                         sp.normalized || (force_norm && !quantized_ && sp.comp_type != LM_COMP_FLOAT), out.data());
    return LM_OK;
}

// The glTF image that texture `tex_index` shows: EXT_texture_webp's source where the texture has one (the
// extension's own image; `source` is then a fallback for readers without WebP), else `source`; -1 if
// none names an image.
int Loader::image_of(int tex_index) const
{
    if (tex_index < 0 || size_t(tex_index) >= model_.textures.size())
        return -1;
    const tinygltf::Texture &t = model_.textures[size_t(tex_index)];
    int img = int_prop(ext_obj(t.extensions, "EXT_texture_webp"), "source", t.source);
    return img >= 0 && size_t(img) < model_.images.size() ? img : -1;
}

// Decodes every image a material uses, in parallel (decoding is most of a textured level's load: 300
// JPEG or PNG textures of 1024 x 1024 took 8 s on one core), each as colour (sRGB) or data as its use
// says. An image used both ways is decoded as its first use in material order says. The warnings for
// undecodable images follow, in image order, so the log is the same on any number of threads.
// Each used image is decoded once however many glTF images name the same bytes (40 images of one file
// were decoded 40 times), and the decoding's memory is planned before any of it: the threads' largest
// decodes at once, plus every reduced texture kept (lm_memory_plan; above the machine's memory the load
// is refused naming the images, never a texture silently dropped).
lm_status Loader::decode_used_images()
{
    size_t n = model_.images.size();
    decoded_.assign(n, Decoded());
    std::vector<signed char> use(n, -1); // -1 unused, 1 colour, 0 data
    auto mark = [&](int tex, int srgb) {
        int img = image_of(tex);
        if (img >= 0 && use[size_t(img)] < 0)
            use[size_t(img)] = (signed char)srgb;
    };
    for (const tinygltf::Material &m : model_.materials) {
        mark(m.pbrMetallicRoughness.baseColorTexture.index, 1);
        mark(m.emissiveTexture.index, 1);
        mark(m.pbrMetallicRoughness.metallicRoughnessTexture.index, 0);
    }
    std::vector<long> same(n, -1); // an earlier image with the same bytes and use, decoded in its place
    std::unordered_map<uint64_t, long> first;
    std::vector<double> peak;
    double kept = 0.0;
    for (size_t i = 0; i < n; i++) {
        const std::vector<unsigned char> &b = model_.images[i].image;
        if (use[i] < 0 || b.empty())
            continue;
        uint64_t key = std::hash<std::string_view>{}(std::string_view(reinterpret_cast<const char *>(b.data()), b.size())) ^
                       uint64_t(use[i]);
        auto it = first.find(key);
        if (it != first.end() && model_.images[size_t(it->second)].image == b && use[size_t(it->second)] == use[i]) {
            same[i] = it->second;
            continue;
        }
        first[key] = long(i);
        double bytes = lm_image_decode_bytes(b.data(), b.size(), LM_TEXTURE_MAX_SIDE);
        peak.push_back(bytes);
        kept += std::fmin(bytes, 4.0 * LM_TEXTURE_MAX_SIDE * LM_TEXTURE_MAX_SIDE);
    }
    std::sort(peak.begin(), peak.end(), std::greater<double>());
    double at_once = kept;
    for (size_t k = 0; k < peak.size() && k < size_t(omp_get_max_threads()); k++)
        at_once += peak[k];
    char what[128];
    snprintf(what, sizeof what, "decoding %zu images", peak.size());
    lm_error e;
    if (lm_memory_plan(what, at_once, "smaller images (lmgi keeps at most 256 x 256 of each; decoding a huge one "
                       "is the cost)", &e) != LM_OK)
        return fail(e.status, "%s", e.msg);
    long count = long(n);
#pragma omp parallel for schedule(dynamic)
    for (long i = 0; i < count; i++) {
        const tinygltf::Image &im = model_.images[size_t(i)];
        Decoded &d = decoded_[size_t(i)];
        if (use[size_t(i)] < 0 || im.image.empty() || same[size_t(i)] >= 0) // unused, unreadable, or a repeat
            continue;
        uint8_t *px = nullptr;
        d.status = lm_image_decode(im.image.data(), im.image.size(), LM_TEXTURE_MAX_SIDE, use[size_t(i)], &px, &d.w,
                                   &d.h, &d.why);
        if (px) {
            try {
                d.rgba.assign(px, px + size_t(d.w) * size_t(d.h) * 4);
            } catch (const std::bad_alloc &) {
                d.status = LM_ERR_NOMEM;
            }
            free(px);
        }
    }
    for (size_t i = 0; i < n; i++)
        if (same[i] >= 0)
            decoded_[i] = decoded_[size_t(same[i])];
    for (size_t i = 0; i < n; i++) {
        const tinygltf::Image &im = model_.images[i];
        model_.images[i].image.clear(); // the encoded bytes are done with
        model_.images[i].image.shrink_to_fit();
        if (decoded_[i].status == LM_ERR_NOMEM)
            return fail(LM_ERR_NOMEM, "image %zu (\"%.200s\"): %s", i, (im.name.empty() ? im.uri : im.name).c_str(),
                        decoded_[i].why);
        if (decoded_[i].status)
            lm_warn("%s: image %zu (\"%.200s\"): %s; ignored", path_, i, (im.name.empty() ? im.uri : im.name).c_str(),
                    decoded_[i].why);
    }
    return LM_OK;
}

// lm texture index for glTF texture `tex_index` (-1 if none or undecodable); colour textures are sRGB.
int Loader::texture(int tex_index, const std::string &ctx)
{
    if (tex_index < 0)
        return -1;
    int img = image_of(tex_index);
    if (img < 0) {
        lm_warn("%s: %s: texture %d is missing; using the factor alone", path_, ctx.c_str(), tex_index);
        return -1;
    }
    if (image_tex_[size_t(img)] >= 0)
        return image_tex_[size_t(img)];
    const Decoded &d = decoded_[size_t(img)];
    if (d.rgba.empty()) // undecodable, already warned
        return -1;
    lm_texture t = {0, 0, nullptr};
    if (!lm_texture_from_rgba8(&t, d.rgba.data(), d.w, d.h, 1))
        throw std::bad_alloc();
    textures_.push_back(t);
    image_tex_[size_t(img)] = int(textures_.size() - 1);
    return image_tex_[size_t(img)];
}

// metallicRoughnessTexture (glTF: roughness in G, metalness in B, linear): the factors become factor x the
// texture's mean, so a material is metal as far as its texels are. UnityGLTF, for one, leaves
// metallicFactor at its default 1 and puts the metalness in this texture alone.
void Loader::metal_rough_from_texture(const tinygltf::PbrMetallicRoughness &pbr, lm_material &d)
{
    int img = image_of(pbr.metallicRoughnessTexture.index);
    if (img < 0 || decoded_[size_t(img)].rgba.empty())
        return;
    const uint8_t *px = decoded_[size_t(img)].rgba.data();
    double g = 0.0, b = 0.0;
    size_t n = size_t(decoded_[size_t(img)].w) * size_t(decoded_[size_t(img)].h);
    for (size_t i = 0; i < n; i++)
        g += px[4 * i + 1], b += px[4 * i + 2];
    d.roughness *= float(g / (255.0 * double(n)));
    d.metallic *= float(b / (255.0 * double(n)));
}

lm_status Loader::materials()
{
    size_t n = model_.materials.size();
    s_->materials = calloc_n<lm_material>(n + 1); // room for the default material
    image_tex_.assign(model_.images.size(), -1);
    lm_status decoded = decode_used_images();
    if (decoded)
        return decoded;
    static const float one4[4] = {1, 1, 1, 1}, zero3[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        const tinygltf::Material &m = model_.materials[i];
        lm_material &d = s_->materials[i];
        std::string ctx = "material " + std::to_string(i) + " (\"" + m.name + "\")";
        lm_copy_name(d.name, m.name.c_str());
        const tinygltf::PbrMetallicRoughness &pbr = m.pbrMetallicRoughness;
        vec_or(pbr.baseColorFactor, 4, one4, d.base_color);
        d.base_color_tex = texture(pbr.baseColorTexture.index, ctx);
        d.missing_textures = pbr.baseColorTexture.index >= 0 && d.base_color_tex < 0;
        d.base_color_uv = pbr.baseColorTexture.texCoord == 1 ? 1 : 0;
        d.uv_scale[0] = d.uv_scale[1] = 1.0f;
        if (const tinygltf::Value *tt = ext_obj(pbr.baseColorTexture.extensions, "KHR_texture_transform")) {
            for (int k = 0; k < 2; k++) {
                if (tt->Get("offset").ArrayLen() == 2 && tt->Get("offset").Get(k).IsNumber())
                    d.uv_offset[k] = float(tt->Get("offset").Get(k).GetNumberAsDouble());
                if (tt->Get("scale").ArrayLen() == 2 && tt->Get("scale").Get(k).IsNumber())
                    d.uv_scale[k] = float(tt->Get("scale").Get(k).GetNumberAsDouble());
            }
            d.uv_rotation = float(num(tt, "rotation", 0.0));
            int tc = int_prop(tt, "texCoord", -1);
            if (tc == 0 || tc == 1)
                d.base_color_uv = tc;
        }
        d.metallic = float(pbr.metallicFactor);
        d.roughness = float(pbr.roughnessFactor);
        if (pbr.metallicRoughnessTexture.index >= 0)
            metal_rough_from_texture(pbr, d);
        vec_or(m.emissiveFactor, 3, zero3, d.emissive);
        float strength = float(num(ext_obj(m.extensions, "KHR_materials_emissive_strength"), "emissiveStrength", 1.0));
        for (int k = 0; k < 3; k++)
            d.emissive[k] *= strength;
        d.emissive_tex = texture(m.emissiveTexture.index, ctx);
        d.missing_textures += m.emissiveTexture.index >= 0 && d.emissive_tex < 0;
        d.transmission = float(num(ext_obj(m.extensions, "KHR_materials_transmission"), "transmissionFactor", 0.0));
        d.ior = float(num(ext_obj(m.extensions, "KHR_materials_ior"), "ior", 1.5));
        d.double_sided = m.doubleSided;
        const float all[] = {d.base_color[0], d.base_color[1], d.base_color[2], d.base_color[3], d.uv_offset[0],
                             d.uv_offset[1], d.uv_scale[0], d.uv_scale[1], d.uv_rotation, d.metallic, d.roughness,
                             d.emissive[0], d.emissive[1], d.emissive[2], d.transmission, d.ior};
        if (!finite_all(all, sizeof all / sizeof all[0]))
            return fail(LM_ERR_INVALID, "%s has a non-finite parameter", ctx.c_str());
        const float uvt[] = {d.uv_offset[0], d.uv_offset[1], d.uv_scale[0], d.uv_scale[1], d.uv_rotation};
        for (float v : uvt)
            if (!(std::fabs(v) <= LM_MAX_UV_TRANSFORM))
                return fail(LM_ERR_INVALID, "%s: KHR_texture_transform offset, scale and rotation must be within "
                            "+-%g, not %g", ctx.c_str(), double(LM_MAX_UV_TRANSFORM), double(v));
        /* KHR_materials_ior: 1 or more, or 0 (a Fresnel term of 1 at every angle: all reflected) */
        if (!(d.ior >= 1.0f || d.ior == 0.0f))
            return fail(LM_ERR_INVALID, "%s: KHR_materials_ior ior %g must be at least 1 (or 0: all reflected)",
                        ctx.c_str(), double(d.ior));
        /* glTF keeps these factors in [0, 1]; an albedo above 1 makes light (a base colour of 1e38 gave an
         * infinite frame), a negative one takes it */
        const float unit[] = {d.base_color[0], d.base_color[1], d.base_color[2], d.base_color[3], d.metallic,
                              d.roughness, d.transmission};
        static const char *const unit_name[] = {"baseColorFactor", "baseColorFactor", "baseColorFactor",
                                                "baseColorFactor", "metallicFactor", "roughnessFactor",
                                                "transmissionFactor"};
        for (size_t k = 0; k < sizeof unit / sizeof unit[0]; k++)
            if (!(unit[k] >= 0.0f && unit[k] <= 1.0f))
                return fail(LM_ERR_INVALID, "%s: %s %g is outside [0, 1]", ctx.c_str(), unit_name[k], double(unit[k]));
        for (int k = 0; k < 3; k++)
            if (!(d.emissive[k] >= 0.0f))
                return fail(LM_ERR_INVALID, "%s: emission %g is negative", ctx.c_str(), double(d.emissive[k]));
        for (int k = 0; k < 3; k++)
            if (!(std::fabs(d.emissive[k]) <= LM_MAX_EMISSION))
                return fail(LM_ERR_INVALID, "%s: emission %g (emissiveFactor x emissiveStrength) exceeds %g: the "
                            "photon powers it makes would overflow to infinity", ctx.c_str(), double(d.emissive[k]),
                            LM_MAX_EMISSION);
        lm_material_classify(&d);
        d.lightmapped = !lm_material_is_specular(d.cls);
    }
    s_->material_count = int(n);
    s_->textures = copy_out(textures_);
    s_->texture_count = int(textures_.size());
    textures_.clear(); // owned by the scene now
    return LM_OK;
}

// extras.lmgi.reflection_box: [min x, y, z, max x, y, z] in world space, the proxy of what a reflector's
// environment map sees (gpu/frame/reflections.h); anything else is warned about and ignored.
static void read_reflection_box(const tinygltf::Value &v, lm_node_settings &st, const char *path,
                                const std::string &ctx)
{
    float b[6];
    bool ok = v.IsArray() && v.ArrayLen() == 6;
    for (int k = 0; ok && k < 6; k++) {
        ok = v.Get(k).IsNumber();
        b[k] = ok ? float(v.Get(k).GetNumberAsDouble()) : 0.0f;
        ok = ok && std::isfinite(b[k]);
    }
    for (int k = 0; ok && k < 3; k++)
        ok = b[k] < b[k + 3];
    if (!ok) {
        lm_warn("%s: %s: extras.lmgi.reflection_box is not [min x, y, z, max x, y, z] with min < max; ignored",
                path, ctx.c_str());
        return;
    }
    memcpy(st.reflection_box, b, sizeof b);
    st.has_reflection_box = 1;
}

// Reads the lmgi extras of a node: -1 unset, 0/1 set.
void read_settings(const tinygltf::Value &extras, lm_node_settings &st, const char *path, const std::string &ctx)
{
    st.dynamic = st.caustics = st.indirect = st.shadows = st.reflections = st.portal = -1;
    if (!extras.IsObject() || !extras.Has("lmgi"))
        return;
    const tinygltf::Value &l = extras.Get("lmgi");
    if (!l.IsObject()) {
        lm_warn("%s: %s: extras.lmgi is not an object; ignored", path, ctx.c_str());
        return;
    }
    struct { const char *key; int *dst; } keys[] = {
        {"dynamic", &st.dynamic}, {"caustics", &st.caustics}, {"indirect", &st.indirect}, {"shadows", &st.shadows},
        {"casts_shadows", &st.shadows}, {"reflections", &st.reflections}, {"portal", &st.portal}};
    for (const std::string &k : l.Keys()) {
        bool found = false;
        if (k == "reflection_box") {
            read_reflection_box(l.Get(k), st, path, ctx);
            continue;
        }
        for (auto &e : keys) {
            if (k != e.key)
                continue;
            found = true;
            const tinygltf::Value &v = l.Get(k);
            if (v.IsBool())
                *e.dst = v.Get<bool>() ? 1 : 0;
            else if (v.IsNumber())
                *e.dst = v.GetNumberAsDouble() != 0.0;
            else
                lm_warn("%s: %s: extras.lmgi.%s is not a boolean; ignored", path, ctx.c_str(), e.key);
        }
        if (!found)
            lm_warn("%s: %s: unknown lmgi setting \"%s\" ignored", path, ctx.c_str(), k.c_str());
    }
}

lm_status Loader::nodes()
{
    size_t n = model_.nodes.size();
    if (n > INT32_MAX / 2)
        return fail(LM_ERR_FORMAT, "too many nodes");
    s_->nodes = calloc_n<lm_node>(n);
    s_->node_count = int(n);
    static const float t0[3] = {0, 0, 0}, r0[4] = {0, 0, 0, 1}, s1[3] = {1, 1, 1};
    for (size_t i = 0; i < n; i++) {
        const tinygltf::Node &g = model_.nodes[i];
        lm_node &d = s_->nodes[i];
        std::string ctx = "node " + std::to_string(i) + " (\"" + g.name + "\")";
        lm_copy_name(d.name, g.name.c_str());
        d.parent = -1, d.camera = -1, d.light = -1;
        if ((!g.translation.empty() && g.translation.size() != 3) || (!g.rotation.empty() && g.rotation.size() != 4) ||
            (!g.scale.empty() && g.scale.size() != 3) || (!g.matrix.empty() && g.matrix.size() != 16))
            return fail(LM_ERR_FORMAT, "%s: transform arrays have the wrong length", ctx.c_str());
        vec_or(g.translation, 3, t0, d.translation);
        vec_or(g.rotation, 4, r0, d.rotation);
        vec_or(g.scale, 3, s1, d.scale);
        d.has_matrix = g.matrix.size() == 16;
        for (size_t k = 0; k < 16 && d.has_matrix; k++)
            d.matrix[k] = float(g.matrix[k]);
        if (!finite_all(d.translation, 3) || !finite_all(d.rotation, 4) || !finite_all(d.scale, 3))
            return fail(LM_ERR_INVALID, "%s has a non-finite transform", ctx.c_str());
        if (g.mesh >= 0 && size_t(g.mesh) >= model_.meshes.size())
            return fail(LM_ERR_FORMAT, "%s: mesh %d out of range", ctx.c_str(), g.mesh);
        d.mesh = g.mesh < 0 ? -1 : g.mesh;
        if (g.skin >= 0)
            lm_warn("%s: %s: skinning ignored; the mesh is placed by the node", path_, ctx.c_str());
        read_settings(g.extras, d.settings, path_, ctx);
    }
    for (size_t i = 0; i < n; i++) {
        for (int c : model_.nodes[i].children) {
            if (c < 0 || size_t(c) >= n)
                return fail(LM_ERR_FORMAT, "node %zu: child %d out of range", i, c);
            if (s_->nodes[c].parent >= 0 || size_t(c) == i)
                return fail(LM_ERR_FORMAT, "node %d has more than one parent or is its own child", c);
            s_->nodes[c].parent = int(i);
        }
    }
    return node_instances();
}

// What the glTF specification forbids in a camera, each a picture of nothing (a field of view of pi or
// more, a far plane before the near one); NULL when it is valid.
static const char *camera_problem(const lm_camera &d)
{
    const float all[] = {d.yfov, d.aspect, d.znear, d.zfar, d.xmag, d.ymag};
    for (float v : all)
        if (!std::isfinite(v))
            return "a parameter is not a finite number";
    if (d.perspective) {
        if (!(d.yfov > 0.0f && d.yfov < float(LM_PI)))
            return "perspective yfov must be in (0, pi)";
        if (!(d.znear > 0.0f))
            return "perspective znear must be > 0";
        if (!(d.zfar == 0.0f || d.zfar > d.znear))
            return "perspective zfar must be greater than znear (or absent: infinite)";
        if (!(d.aspect >= 0.0f))
            return "perspective aspectRatio must be > 0";
        return nullptr;
    }
    if (!(d.xmag != 0.0f && d.ymag != 0.0f))
        return "orthographic xmag and ymag must not be 0";
    if (!(d.znear >= 0.0f && d.zfar > d.znear))
        return "orthographic znear must be >= 0 and zfar greater than it";
    return nullptr;
}

// Lights and cameras are instanced per node that references them.
lm_status Loader::node_instances()
{
    std::vector<lm_light> lights;
    std::vector<lm_camera> cams;
    for (int i = 0; i < s_->node_count; i++) {
        const tinygltf::Node &g = model_.nodes[size_t(i)];
        if (g.camera >= 0) {
            if (size_t(g.camera) >= model_.cameras.size())
                return fail(LM_ERR_FORMAT, "node %d: camera %d out of range", i, g.camera);
            const tinygltf::Camera &c = model_.cameras[size_t(g.camera)];
            lm_camera d = {};
            lm_copy_name(d.name, c.name.c_str());
            d.node = i;
            d.perspective = c.type != "orthographic";
            d.yfov = float(c.perspective.yfov), d.aspect = float(c.perspective.aspectRatio);
            d.znear = float(d.perspective ? c.perspective.znear : c.orthographic.znear);
            d.zfar = float(d.perspective ? c.perspective.zfar : c.orthographic.zfar);
            d.xmag = float(c.orthographic.xmag), d.ymag = float(c.orthographic.ymag);
            if (const char *why = camera_problem(d))
                return fail(LM_ERR_INVALID, "camera %d (\"%s\"): %s (the glTF 2.0 specification)", g.camera, c.name.c_str(), why);
            s_->nodes[i].camera = int(cams.size());
            cams.push_back(d);
        }
        const tinygltf::Value *le = ext_obj(g.extensions, "KHR_lights_punctual");
        if (!le)
            continue;
        int li = int_prop(le, "light", -1);
        if (li < 0 || size_t(li) >= model_.lights.size())
            return fail(LM_ERR_FORMAT, "node %d: KHR_lights_punctual light %d out of range", i, li);
        const tinygltf::Light &l = model_.lights[size_t(li)];
        lm_light d = {};
        lm_copy_name(d.name, l.name.c_str());
        if (l.type == "point")
            d.type = LM_LIGHT_POINT;
        else if (l.type == "spot")
            d.type = LM_LIGHT_SPOT;
        else if (l.type == "directional")
            d.type = LM_LIGHT_DIRECTIONAL;
        else {
            lm_warn("%s: light %d (\"%s\"): unknown type \"%s\" ignored", path_, li, l.name.c_str(), l.type.c_str());
            continue;
        }
        static const float white[3] = {1, 1, 1};
        vec_or(l.color, 3, white, d.color);
        d.intensity = float(l.intensity), d.range = float(l.range);
        d.inner_cone = float(l.spot.innerConeAngle), d.outer_cone = float(l.spot.outerConeAngle);
        d.node = i;
        std::string what = "light " + std::to_string(li) + " (\"" + l.name + "\")";
        lm_error e;
        if (lm_light_check(what.c_str(), d.color, d.intensity, d.range, d.type == LM_LIGHT_SPOT, d.inner_cone,
                           d.outer_cone, &e) != LM_OK)
            return fail(LM_ERR_INVALID, "%s", e.msg);
        s_->nodes[i].light = int(lights.size());
        lights.push_back(d);
    }
    s_->lights = copy_out(lights), s_->light_count = int(lights.size());
    s_->cameras = copy_out(cams), s_->camera_count = int(cams.size());
    return LM_OK;
}

lm_status Loader::primitive(int node, int mesh, int prim)
{
    const tinygltf::Mesh &m = model_.meshes[size_t(mesh)];
    const tinygltf::Primitive &p = m.primitives[size_t(prim)];
    std::string ctx = "mesh " + std::to_string(mesh) + " (\"" + m.name + "\") primitive " + std::to_string(prim);
    int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        lm_warn("%s: %s: mode %d is not triangles; skipped", path_, ctx.c_str(), mode);
        return LM_OK;
    }
    auto attr = [&](const char *name) { auto it = p.attributes.find(name); return it == p.attributes.end() ? -1 : it->second; };
    if (attr("POSITION") < 0) {
        lm_warn("%s: %s: no POSITION attribute; skipped", path_, ctx.c_str());
        return LM_OK;
    }
    // An accessor without a bufferView is all zeros: positions that decode to one point. Said here, not
    // drawn as an invisible point. (A Draco primitive's accessors have views by now: decode_compressed.)
    int pa = attr("POSITION");
    if (size_t(pa) < model_.accessors.size() && model_.accessors[size_t(pa)].bufferView < 0 &&
        !model_.accessors[size_t(pa)].sparse.isSparse) {
        lm_warn("%s: %s: POSITION has no data (an accessor without a bufferView: every vertex at the origin); "
                "skipped", path_, ctx.c_str());
        return LM_OK;
    }
    std::vector<float> pos, nrm, uv[2];
    size_t vcount = 0, c = 0;
    lm_status st = read_floats(pa, TINYGLTF_TYPE_VEC3, false, "POSITION", ctx, pos, vcount);
    if (st)
        return st;
    long bad = lm_first_nonfinite(pos.data(), pos.size());
    if (bad >= 0)
        return fail(LM_ERR_INVALID, "%s: vertex %ld has a non-finite position", ctx.c_str(), bad / 3);
    if (pos_.size() / 3 + vcount > UINT32_MAX)
        return fail(LM_ERR_FORMAT, "more than 2^32 vertices");
    if (attr("NORMAL") >= 0) {
        if ((st = read_floats(attr("NORMAL"), TINYGLTF_TYPE_VEC3, false, "NORMAL", ctx, nrm, c)))
            return st;
        if (c != vcount)
            return fail(LM_ERR_FORMAT, "%s: NORMAL accessor has %zu elements, POSITION %zu", ctx.c_str(), c, vcount);
        if (!finite_all(nrm.data(), nrm.size())) {
            if (strict_)
                return fail(LM_ERR_INVALID, "%s: non-finite normals", ctx.c_str());
            lm_warn("%s: %s: non-finite normals; generating normals from faces", path_, ctx.c_str());
            nrm.clear();
        }
    }
    const char *uv_names[2] = {"TEXCOORD_0", "TEXCOORD_1"};
    for (int k = 0; k < 2; k++) {
        if (attr(uv_names[k]) < 0)
            continue;
        if ((st = read_floats(attr(uv_names[k]), TINYGLTF_TYPE_VEC2, true, uv_names[k], ctx, uv[k], c)))
            return st;
        if (c != vcount)
            return fail(LM_ERR_FORMAT, "%s: %s accessor has %zu elements, POSITION %zu", ctx.c_str(), uv_names[k], c, vcount);
        if (!finite_all(uv[k].data(), uv[k].size()))
            return fail(LM_ERR_INVALID, "%s: non-finite %s", ctx.c_str(), uv_names[k]);
        /* a texture repeats a million times at most: a coordinate of 3e38 (found by the fuzzer) overflows to
         * inf and NaN when it is interpolated across a triangle, and the frame had a NaN pixel */
        for (float v : uv[k])
            if (!(std::fabs(v) <= k_max_uv))
                return fail(LM_ERR_INVALID, "%s: %s value %g is beyond the %g a texture coordinate may reach",
                            ctx.c_str(), uv_names[k], double(v), double(k_max_uv));
    }
    std::vector<uint32_t> idx;
    if (p.indices >= 0) {
        Span sp;
        if ((st = locate(p.indices, TINYGLTF_TYPE_SCALAR, "index", ctx, sp)))
            return st;
        if (sp.count > UINT32_MAX)
            return fail(LM_ERR_FORMAT, "%s: too many indices", ctx.c_str());
        if (!sp.data) { // all zeros: every triangle a point, 2^24 of them took 3.7 GB and 43 s to drop
            lm_warn("%s: %s: its indices have no data (an accessor without a bufferView: every triangle "
                    "degenerate); skipped", path_, ctx.c_str());
            return LM_OK;
        }
        idx.assign(sp.count, 0);
        if (sp.data && !lm_decode_indices(sp.data, sp.count, sp.stride, sp.comp_type, idx.data()))
            return fail(LM_ERR_FORMAT, "%s: index accessor %d is not u8/u16/u32", ctx.c_str(), p.indices);
        for (size_t i = 0; i < idx.size(); i++)
            if (idx[i] >= vcount)
                return fail(LM_ERR_FORMAT, "%s: index %u (at %zu) out of range of the vertex count %zu", ctx.c_str(),
                            idx[i], i, vcount);
    } else {
        if (vcount > UINT32_MAX)
            return fail(LM_ERR_FORMAT, "%s: too many vertices", ctx.c_str());
        for (size_t i = 0; i < vcount; i++)
            idx.push_back(uint32_t(i));
    }
    if (p.material >= 0 && size_t(p.material) >= model_.materials.size())
        return fail(LM_ERR_FORMAT, "%s: material %d out of range", ctx.c_str(), p.material);
    int mat = p.material >= 0 ? p.material : int(model_.materials.size());
    need_default_material_ = need_default_material_ || p.material < 0;

    uint32_t base = uint32_t(pos_.size() / 3), first_tri = uint32_t(tris_.size() / 3);
    uint32_t ntri = lm_prim_tri_count(mode, uint32_t(idx.size()));
    if (size_t(first_tri) + ntri > UINT32_MAX / 3)
        return fail(LM_ERR_FORMAT, "too many triangles");
    tris_.resize(tris_.size() + size_t(ntri) * 3);
    lm_prim_triangles(mode, idx.data(), uint32_t(idx.size()), base, tris_.data() + size_t(first_tri) * 3);
    tmat_.insert(tmat_.end(), ntri, mat);
    tnode_.insert(tnode_.end(), ntri, uint32_t(node));
    pos_.insert(pos_.end(), pos.begin(), pos.end());
    vnode_.insert(vnode_.end(), vcount, uint32_t(node));
    for (int k = 0; k < 2; k++)
        uv[k].resize(vcount * 2, 0.0f);
    uv0_.insert(uv0_.end(), uv[0].begin(), uv[0].end());
    any_uv1_ = any_uv1_ || attr("TEXCOORD_1") >= 0;
    uv1_.insert(uv1_.end(), uv[1].begin(), uv[1].end());
    if (nrm.empty()) {
        nrm_.resize(pos_.size());
        lm_generate_normals(nrm_.data(), pos_.data(), tris_.data() + size_t(first_tri) * 3, ntri, base, uint32_t(vcount));
    } else {
        nrm_.insert(nrm_.end(), nrm.begin(), nrm.end());
    }
    return LM_OK;
}

// Each node gets its own copy of its mesh's triangles, contiguous, in node order.
lm_status Loader::geometry()
{
    s_->mesh_count = int(model_.meshes.size());
    for (int i = 0; i < s_->node_count; i++) {
        lm_node &n = s_->nodes[i];
        n.first_tri = uint32_t(tris_.size() / 3);
        if (n.settings.portal == 1 && n.mesh < 0)
            return fail(LM_ERR_INVALID, "node %d (\"%s\"): extras.lmgi.portal needs a mesh (the opening's shape)", i,
                        n.name);
        if (n.mesh >= 0) {
            for (size_t k = 0; k < model_.meshes[size_t(n.mesh)].primitives.size(); k++) {
                lm_status st = primitive(i, n.mesh, int(k));
                if (st)
                    return st;
            }
        }
        if (n.settings.portal == 1) { /* its triangles leave the geometry: placed in world space by finish() */
            for (size_t t = 3 * size_t(n.first_tri); t < tris_.size(); t++)
                for (int a = 0; a < 3; a++)
                    portal_local_.push_back(pos_[3 * size_t(tris_[t]) + a]);
            portal_node_.resize(portal_local_.size() / 9, i);
            tris_.resize(3 * size_t(n.first_tri)), tmat_.resize(n.first_tri), tnode_.resize(n.first_tri);
            if (portal_node_.size() > LM_MAX_PORTAL_TRIS)
                return fail(LM_ERR_INVALID, "node %d (\"%s\"): portals have more than %d triangles in all", i, n.name,
                            LM_MAX_PORTAL_TRIS);
        }
        n.tri_count = uint32_t(tris_.size() / 3) - n.first_tri;
    }
    if (need_default_material_) {
        lm_material &d = s_->materials[s_->material_count++];
        lm_copy_name(d.name, "lmgi_default");
        for (int k = 0; k < 3; k++)
            d.base_color[k] = 0.8f;
        d.base_color[3] = 1.0f;
        d.base_color_tex = d.emissive_tex = -1;
        d.uv_scale[0] = d.uv_scale[1] = 1.0f;
        d.roughness = 1.0f, d.ior = 1.5f;
        lm_material_classify(&d);
        d.lightmapped = !lm_material_is_specular(d.cls);
    }
    s_->vertex_count = uint32_t(pos_.size() / 3);
    s_->positions = copy_out(pos_), s_->normals = copy_out(nrm_), s_->uv0 = copy_out(uv0_);
    s_->uv1 = any_uv1_ ? copy_out(uv1_) : nullptr;
    s_->vertex_node = copy_out(vnode_);
    s_->tri_count = uint32_t(tris_.size() / 3);
    s_->tris = copy_out(tris_), s_->tri_material = copy_out(tmat_), s_->tri_node = copy_out(tnode_);
    return LM_OK;
}

lm_status Loader::animations()
{
    size_t na = model_.animations.size();
    animated_.assign(model_.nodes.size(), 0);
    s_->animations = calloc_n<lm_animation>(na);
    s_->animation_count = int(na);
    for (size_t a = 0; a < na; a++) {
        const tinygltf::Animation &g = model_.animations[a];
        lm_animation &d = s_->animations[a];
        std::string ctx = "animation " + std::to_string(a) + " (\"" + g.name + "\")";
        lm_copy_name(d.name, g.name.c_str());
        d.channels = calloc_n<lm_anim_channel>(g.channels.size());
        for (const tinygltf::AnimationChannel &ch : g.channels) {
            lm_anim_path path;
            if (ch.target_path == "translation")
                path = LM_PATH_TRANSLATION;
            else if (ch.target_path == "rotation")
                path = LM_PATH_ROTATION;
            else if (ch.target_path == "scale")
                path = LM_PATH_SCALE;
            else {
                lm_warn("%s: %s: \"%s\" channel ignored", path_, ctx.c_str(), ch.target_path.c_str());
                continue;
            }
            if (ch.target_node < 0)
                continue; // no target: nothing to animate (allowed by the spec)
            if (size_t(ch.target_node) >= model_.nodes.size() || ch.sampler < 0 || size_t(ch.sampler) >= g.samplers.size())
                return fail(LM_ERR_FORMAT, "%s: channel target node %d or sampler %d out of range", ctx.c_str(),
                            ch.target_node, ch.sampler);
            const tinygltf::AnimationSampler &sm = g.samplers[size_t(ch.sampler)];
            lm_interp in = sm.interpolation == "STEP" ? LM_INTERP_STEP
                         : sm.interpolation == "CUBICSPLINE" ? LM_INTERP_CUBIC : LM_INTERP_LINEAR;
            if (sm.interpolation != "LINEAR" && sm.interpolation != "STEP" && sm.interpolation != "CUBICSPLINE")
                return fail(LM_ERR_FORMAT, "%s: unknown interpolation \"%s\"", ctx.c_str(), sm.interpolation.c_str());
            std::vector<float> times, values;
            size_t nt = 0, nv = 0;
            int comps = path == LM_PATH_ROTATION ? 4 : 3;
            lm_status st = read_floats(sm.input, TINYGLTF_TYPE_SCALAR, false, "animation input", ctx, times, nt);
            if (st || (st = read_floats(sm.output, comps == 4 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3, false,
                                        "animation output", ctx, values, nv)))
                return st;
            size_t per_key = in == LM_INTERP_CUBIC ? 3 : 1;
            if (nt == 0 || nt > INT32_MAX || nv != nt * per_key)
                return fail(LM_ERR_FORMAT, "%s: sampler %d has %zu keys and %zu output values", ctx.c_str(), ch.sampler, nt, nv);
            for (size_t k = 0; k < nt; k++)
                if (!std::isfinite(times[k]) || (k > 0 && times[k] < times[k - 1]))
                    return fail(LM_ERR_FORMAT, "%s: sampler %d key times are not finite and increasing", ctx.c_str(), ch.sampler);
            if (!finite_all(values.data(), values.size()))
                return fail(LM_ERR_INVALID, "%s: sampler %d has non-finite values", ctx.c_str(), ch.sampler);
            float bound = path == LM_PATH_TRANSLATION ? LM_MAX_ANIM_TRANSLATION : LM_MAX_ANIM_SCALE;
            for (size_t k = 0; path != LM_PATH_ROTATION && k < values.size(); k++)
                if (!(std::fabs(values[k]) <= bound))
                    return fail(LM_ERR_INVALID, "%s: sampler %d moves node %d to %g, beyond the %g a %s key may "
                                "reach", ctx.c_str(), ch.sampler, ch.target_node, double(values[k]), double(bound),
                                path == LM_PATH_TRANSLATION ? "translation" : "scale");
            lm_anim_channel &c = d.channels[d.channel_count++];
            c.node = ch.target_node, c.path = path, c.interp = in, c.key_count = int(nt), c.comps = comps;
            c.times = copy_out(times), c.values = copy_out(values);
            d.duration = std::fmax(d.duration, times.back());
            animated_[size_t(ch.target_node)] = 1;
        }
    }
    return LM_OK;
}

lm_status Loader::finish()
{
    lm_status st = lm_scene_finish_nodes(s_.get(), animated_.data(), err_);
    if (st)
        return st;
    if (!portal_node_.empty()) { /* the portals in world space, where the photons are aimed */
        s_->portal_tris = calloc_n<float>(portal_local_.size());
        s_->portal_tri_count = uint32_t(portal_node_.size());
        for (size_t t = 0; t < portal_node_.size(); t++) {
            const lm_node &n = s_->nodes[portal_node_[t]];
            if (n.dynamic)
                return fail(LM_ERR_INVALID, "node %d (\"%s\"): a portal cannot move (dynamic or animated)",
                            portal_node_[t], n.name);
            for (int k = 0; k < 3; k++)
                lm_v3_store(&s_->portal_tris[9 * t + 3 * size_t(k)],
                            lm_mat4_point(n.world, lm_v3_load(&portal_local_[9 * t + 3 * size_t(k)])));
        }
    }
    for (int i = 0; i < s_->node_count; i++) {
        const lm_node &n = s_->nodes[i];
        uint32_t bad = n.tri_count ? lm_count_degenerate(s_.get(), n.first_tri, n.tri_count) : 0;
        if (!bad)
            continue;
        const char *mesh = model_.meshes[size_t(n.mesh)].name.c_str();
        if (strict_)
            return fail(LM_ERR_INVALID, "mesh \"%s\" (node %d) has %u degenerate triangles", mesh, i, bad);
        lm_warn("%s: mesh \"%s\" (node %d) has %u degenerate (zero-area) triangles", path_, mesh, i, bad);
    }
    return lm_scene_split_sides(s_.get(), err_);
}

// A radiance [r, g, b] of finite numbers in [0, LM_MAX_EMISSION] into out; false if v is not one.
static bool radiance(const tinygltf::Value &v, float out[3])
{
    bool ok = v.IsArray() && v.ArrayLen() == 3;
    for (int k = 0; ok && k < 3; k++) {
        ok = v.Get(k).IsNumber();
        double d = ok ? v.Get(k).GetNumberAsDouble() : -1.0;
        ok = ok && d >= 0.0 && d <= LM_MAX_EMISSION;
        out[k] = float(d);
    }
    return ok;
}

// The file's sky, in the root's extras (docs/levels.md, "Sky"): {"lmgi": {"sky": [r, g, b]}} a uniform
// radiance, {"sky": {"zenith": [r, g, b], "horizon": [r, g, b]}} a gradient, {"sky": {"image": URI,
// "scale": k}} an equirectangular HDR image beside the scene (.hdr, .exr). A malformed one is an error: it is
// light, and a scene lit wrongly is worse than one refused.
// A URI's %XX escapes decoded, as glTF's URIs are (RFC 3986; tinygltf decodes those of images and
// buffers itself, but keeps its decoder private). A malformed escape is kept as written.
static std::string percent_decoded(const std::string &uri)
{
    std::string out;
    for (size_t i = 0; i < uri.size(); i++) {
        unsigned v;
        if (uri[i] == '%' && i + 2 < uri.size() && isxdigit((unsigned char)uri[i + 1]) &&
            isxdigit((unsigned char)uri[i + 2]) && sscanf(uri.c_str() + i + 1, "%2x", &v) == 1) {
            out += char(v);
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

// The EXT_lights_image_based reference of the scene lmgi loads (the default scene, else the first), and
// that scene's index; NULL when it names no image-based light.
const tinygltf::Value *Loader::ibl_reference(int *scene) const
{
    if (model_.scenes.empty())
        return nullptr;
    *scene = model_.defaultScene >= 0 && size_t(model_.defaultScene) < model_.scenes.size() ? model_.defaultScene : 0;
    return ext_obj(model_.scenes[size_t(*scene)].extensions, "EXT_lights_image_based");
}

// The light's intensity (default 1: finite and >= 0) and rotation (default identity: a unit quaternion
// to 1e-3, made unit), as the extension defines them; the defaults stay where the light has none.
lm_status Loader::ibl_params(const tinygltf::Value &light, const std::string &what, float *intensity,
                             float rotation[4])
{
    const char *w = what.c_str();
    double k = num(&light, "intensity", 1.0);
    if (light.Has("intensity") && !light.Get("intensity").IsNumber())
        return fail(LM_ERR_INVALID, "%s: intensity must be a number", w);
    if (!(k >= 0.0 && k <= LM_MAX_EMISSION))
        return fail(LM_ERR_INVALID, "%s: intensity %g must be a number from 0 to %g", w, k, LM_MAX_EMISSION);
    *intensity = float(k);
    if (!light.Has("rotation"))
        return LM_OK;
    const tinygltf::Value &r = light.Get("rotation");
    bool ok = r.IsArray() && r.ArrayLen() == 4;
    double len2 = 0.0;
    for (int i = 0; ok && i < 4; i++) {
        ok = r.Get(i).IsNumber() && std::isfinite(r.Get(i).GetNumberAsDouble());
        rotation[i] = ok ? float(r.Get(i).GetNumberAsDouble()) : 0.0f;
        len2 += double(rotation[i]) * rotation[i];
    }
    if (!ok)
        return fail(LM_ERR_INVALID, "%s: rotation must be a quaternion [x, y, z, w] of 4 finite numbers", w);
    if (!(std::fabs(std::sqrt(len2) - 1.0) <= 1e-3))
        return fail(LM_ERR_INVALID, "%s: rotation [%g, %g, %g, %g] is not a unit quaternion (its length is %g)", w,
                    double(rotation[0]), double(rotation[1]), double(rotation[2]), double(rotation[3]),
                    std::sqrt(len2));
    lm_quat_normalize(rotation);
    return LM_OK;
}

// The light's mip 0 (specularImages[0]: the radiance itself, roughness 0), six glTF images decoded whole
// into 8-bit RGBA, square and of one size n. Their bytes came as every image's do (data: URIs,
// bufferViews, files under the folder rule: parse), and stay until decode_used_images.
lm_status Loader::ibl_faces(const tinygltf::Value &light, const std::string &what, std::vector<uint8_t> faces[6],
                            int *n)
{
    static const char *const k_face[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
    const char *w = what.c_str();
    const tinygltf::Value *mips = light.Has("specularImages") ? &light.Get("specularImages") : nullptr;
    if (!mips || !mips->IsArray() || mips->ArrayLen() < 1 || !mips->Get(0).IsArray())
        return fail(LM_ERR_FORMAT, "%s: specularImages must be an array of mips, each an array of 6 faces", w);
    const tinygltf::Value &mip0 = mips->Get(0);
    if (mip0.ArrayLen() != 6)
        return fail(LM_ERR_FORMAT, "%s: specularImages[0] has %zu faces; a cube has 6 (+X, -X, +Y, -Y, +Z, -Z)", w,
                    mip0.ArrayLen());
    int img[6];
    double plan = 12.0 * LM_SKY_CUBE_MAX_WIDTH * (LM_SKY_CUBE_MAX_WIDTH / 2); // the equirectangular image
    for (int f = 0; f < 6; f++) {
        double i = number_or_nan(mip0.Get(f));
        if (!(i >= 0.0 && i < double(model_.images.size()) && i == std::floor(i)))
            return fail(LM_ERR_FORMAT, "%s: face %s (specularImages[0][%d]): image %g out of range (%zu images)", w,
                        k_face[f], f, i, model_.images.size());
        img[f] = int(i);
        const std::vector<unsigned char> &b = model_.images[size_t(img[f])].image;
        plan += 2.5 * lm_image_decode_bytes(b.data(), b.size(), 0); // RGBA while decoding, then linear floats
    }
    lm_error e;
    if (lm_memory_plan("decoding the sky's six cube faces", plan, "smaller faces", &e) != LM_OK)
        return fail(e.status, "%s: %s", w, e.msg);
    for (int f = 0; f < 6; f++) {
        const tinygltf::Image &im = model_.images[size_t(img[f])];
        std::string label = "image " + std::to_string(img[f]); // and its name or file, where it has one
        if (!im.name.empty() || !im.uri.empty())
            label += " \"" + (im.name.empty() ? im.uri : im.name).substr(0, 200) + "\"";
        if (im.image.empty())
            return fail(LM_ERR_FORMAT, "%s: face %s (%s) has no bytes: its file is missing or unreadable", w,
                        k_face[f], label.c_str());
        uint8_t *px = nullptr;
        int fw = 0, fh = 0;
        const char *why = "";
        lm_status st = lm_image_decode(im.image.data(), im.image.size(), 0, 0, &px, &fw, &fh, &why);
        if (st)
            return fail(st, "%s: face %s (%s): %s", w, k_face[f], label.c_str(), why);
        faces[f].assign(px, px + size_t(fw) * size_t(fh) * 4);
        free(px);
        if (fw != fh)
            return fail(LM_ERR_FORMAT, "%s: face %s (image %d) is %d x %d pixels; cube faces are square", w,
                        k_face[f], img[f], fw, fh);
        if (f > 0 && fw != *n)
            return fail(LM_ERR_FORMAT, "%s: face %s (image %d) is %d x %d pixels, face +X %d x %d; the six faces "
                        "are one size", w, k_face[f], img[f], fw, fh, *n, *n);
        *n = fw;
    }
    return LM_OK;
}

// The scene's sky from the EXT_lights_image_based light it names (docs/levels.md, "Sky"): its mip 0's
// cube, rotation and intensity, resampled by lm_sky_set_cube. A malformed light is an error, as a
// malformed extras.lmgi.sky is.
lm_status Loader::ibl_sky(const tinygltf::Value &ref, int scene)
{
    const tinygltf::Value *root = ext_obj(model_.extensions, "EXT_lights_image_based");
    const tinygltf::Value *lights = root && root->Has("lights") && root->Get("lights").IsArray() ? &root->Get("lights")
                                                                                                 : nullptr;
    size_t count = lights ? lights->ArrayLen() : 0;
    double li = number_or_nan(ref.Get("light"));
    if (!(li >= 0.0 && li < double(count) && li == std::floor(li)))
        return fail(LM_ERR_FORMAT, "scene %d: EXT_lights_image_based light %g out of range (%zu lights)", scene, li,
                    count);
    const tinygltf::Value &light = lights->Get(int(li));
    std::string what = "EXT_lights_image_based light " + std::to_string(int(li));
    if (!light.IsObject())
        return fail(LM_ERR_FORMAT, "%s is not an object", what.c_str());
    float intensity = 1.0f, rotation[4] = {0, 0, 0, 1};
    std::vector<uint8_t> faces[6];
    int n = 0;
    lm_status st = ibl_params(light, what, &intensity, rotation);
    if (st || (st = ibl_faces(light, what, faces, &n)))
        return st;
    const uint8_t *rgbd[6];
    for (int f = 0; f < 6; f++)
        rgbd[f] = faces[f].data();
    lm_error e;
    if (lm_sky_set_cube(s_.get(), rgbd, n, rotation, intensity, what.c_str(), &e) != LM_OK)
        return fail(e.status, "%s", e.msg);
    return LM_OK;
}

lm_status Loader::sky()
{
    const tinygltf::Value &x = model_.extras;
    int scene = 0;
    const tinygltf::Value *ibl = ibl_reference(&scene);
    if (!x.IsObject() || !x.Has("lmgi") || !x.Get("lmgi").IsObject() || !x.Get("lmgi").Has("sky"))
        return ibl ? ibl_sky(*ibl, scene) : LM_OK;
    if (ibl) // lmgi's own word on its sky wins over another tool's
        lm_warn("%s: scene %d's EXT_lights_image_based light ignored: extras.lmgi.sky gives the sky", path_, scene);
    const tinygltf::Value &v = x.Get("lmgi").Get("sky");
    if (v.IsArray()) {
        if (!radiance(v, s_->sky))
            return fail(LM_ERR_INVALID, "extras.lmgi.sky must be [r, g, b], a radiance of finite numbers in [0, %g]",
                        LM_MAX_EMISSION);
        s_->sky_kind = LM_SKY_UNIFORM;
    } else if (v.IsObject() && v.Has("zenith")) {
        if (!radiance(v.Get("zenith"), s_->sky) || !v.Has("horizon") || !radiance(v.Get("horizon"), s_->sky_horizon))
            return fail(LM_ERR_INVALID, "extras.lmgi.sky: zenith and horizon must each be [r, g, b], finite numbers "
                        "in [0, %g]", LM_MAX_EMISSION);
        s_->sky_kind = LM_SKY_GRADIENT;
    } else if (v.IsObject() && v.Has("image") && v.Get("image").IsString()) {
        if (mem_)
            return fail(LM_ERR_INVALID, "extras.lmgi.sky.image: a scene from memory cannot name external files");
        double k = num(&v, "scale", 1.0);
        const float scale[3] = {float(k), float(k), float(k)};
        std::string uri = percent_decoded(v.Get("image").Get<std::string>());
        std::string file = uri.size() && uri[0] == '/' ? uri : scene_dir() + "/" + uri, why;
        Confine confine = {scene_dir(), &escaped_, untrusted_, path_};
        if (!confined(confine, file, &why))
            return fail(LM_ERR_IO, "extras.lmgi.sky.image: %s", escaped_.c_str());
        lm_error e;
        if (lm_sky_load_image(s_.get(), file.c_str(), scale, &e) != LM_OK)
            return fail(e.status, "extras.lmgi.sky.image: %s", e.msg);
        return LM_OK;
    } else {
        return fail(LM_ERR_INVALID, "extras.lmgi.sky must be [r, g, b], {\"zenith\": [r, g, b], \"horizon\": "
                    "[r, g, b]} or {\"image\": URI, \"scale\": k}");
    }
    s_->has_sky = 1;
    return LM_OK;
}

// Sparse accessors (glTF 2.0, 3.6.2.3: Blender writes them for shape keys and sparse animation) are made
// dense once, before anything reads them: the base (its bufferView, or zeros) copied tightly packed, each
// sparse index's value written over it, the result a buffer of its own that the accessor then names. So
// every reader (attributes, indices, keyframes) takes them as it takes any accessor, bounds checks and all.
lm_status Loader::densify(int acc)
{
    tinygltf::Accessor &a = model_.accessors[size_t(acc)];
    const auto &sp = a.sparse;
    std::string ctx = "accessor " + std::to_string(acc) + " (sparse)";
    size_t cs = lm_component_size(a.componentType), ncomp = size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)));
    if (cs == 0 || ncomp == 0 || ncomp > 16)
        return fail(LM_ERR_FORMAT, "%s: the wrong type or component type", ctx.c_str());
    size_t elem = cs * ncomp;
    if (sp.count < 1 || size_t(sp.count) > a.count)
        return fail(LM_ERR_FORMAT, "%s: %d sparse values for %zu elements", ctx.c_str(), sp.count, a.count);
    if (a.bufferView < 0 && a.count > k_max_unbacked_elems)
        return fail(LM_ERR_FORMAT, "%s: no bufferView and %zu elements", ctx.c_str(), a.count);
    // where a part lies: its bufferView's bytes from `offset`, `n` elements of `size` bytes, tightly packed
    auto part = [&](int view, size_t offset, size_t n, size_t size, const uint8_t **at) -> bool {
        if (view < 0 || size_t(view) >= model_.bufferViews.size())
            return false;
        const tinygltf::BufferView &bv = model_.bufferViews[size_t(view)];
        if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size())
            return false;
        const tinygltf::Buffer &b = model_.buffers[size_t(bv.buffer)];
        size_t stride = bv.byteStride ? bv.byteStride : size;
        if (!lm_span_fits(bv.byteOffset, 1, 0, bv.byteLength, b.data.size()) || stride < size ||
            !lm_span_fits(offset, n, stride, size, bv.byteLength))
            return false;
        *at = b.data.data() + bv.byteOffset + offset;
        return stride == size; // sparse parts are tightly packed; a base with a stride is copied below
    };
    std::vector<unsigned char> dense(a.count * elem, 0);
    if (a.bufferView >= 0) {
        const tinygltf::BufferView *bv = size_t(a.bufferView) < model_.bufferViews.size()
                                             ? &model_.bufferViews[size_t(a.bufferView)] : nullptr;
        size_t stride = bv && bv->byteStride ? bv->byteStride : elem;
        const uint8_t *base = nullptr;
        part(a.bufferView, a.byteOffset, a.count, elem, &base);
        if (!base)
            return fail(LM_ERR_FORMAT, "%s: its base bufferView %d does not hold its %zu elements", ctx.c_str(),
                        a.bufferView, a.count);
        for (size_t i = 0; i < a.count; i++)
            memcpy(dense.data() + i * elem, base + i * stride, elem);
    }
    size_t n = size_t(sp.count), isize = lm_component_size(sp.indices.componentType);
    const uint8_t *idx = nullptr, *val = nullptr;
    if (isize == 0 || sp.indices.componentType == LM_COMP_BYTE || sp.indices.componentType == LM_COMP_SHORT ||
        sp.indices.componentType == LM_COMP_FLOAT || !part(sp.indices.bufferView, size_t(sp.indices.byteOffset), n, isize, &idx) || sp.indices.byteOffset < 0)
        return fail(LM_ERR_FORMAT, "%s: its indices (bufferView %d, u8/u16/u32, tightly packed) do not hold %zu",
                    ctx.c_str(), sp.indices.bufferView, n);
    if (sp.values.byteOffset < 0 || !part(sp.values.bufferView, size_t(sp.values.byteOffset), n, elem, &val))
        return fail(LM_ERR_FORMAT, "%s: its values (bufferView %d, tightly packed) do not hold %zu", ctx.c_str(),
                    sp.values.bufferView, n);
    std::vector<uint32_t> where(n);
    if (!lm_decode_indices(idx, n, isize, sp.indices.componentType, where.data()))
        return fail(LM_ERR_FORMAT, "%s: indices are not u8/u16/u32", ctx.c_str());
    for (size_t i = 0; i < n; i++) {
        if (where[i] >= a.count || (i > 0 && where[i] <= where[i - 1]))
            return fail(LM_ERR_FORMAT, "%s: index %u (at %zu) is out of range of %zu or not increasing", ctx.c_str(),
                        where[i], i, a.count);
        memcpy(dense.data() + size_t(where[i]) * elem, val + i * elem, elem);
    }
    gltf_own_view(model_, size_t(acc), std::move(dense));
    return LM_OK;
}

// The compressed glTF that tools write (gltf_meshopt.h, gltf_draco.h), decoded into plain accessors.
lm_status Loader::decode_compressed()
{
    std::string why = meshopt_decode(model_, fallbacks_);
    if (why.empty())
        why = draco_decode(model_);
    return why.empty() ? LM_OK : fail(LM_ERR_FORMAT, "%s", why.c_str());
}

lm_status Loader::densify_sparse()
{
    for (size_t i = 0; i < model_.accessors.size(); i++)
        if (model_.accessors[i].sparse.isSparse) {
            lm_status st = densify(int(i));
            if (st)
                return st;
        }
    return LM_OK;
}

lm_status Loader::run(lm_scene **out)
{
    std::vector<unsigned char> bytes;
    lm_status st = read_file(bytes);
    if (st || (st = parse(bytes)) || (st = check_extensions()) || (st = decode_compressed()) || (st = densify_sparse()))
        return st;
    bytes = std::vector<unsigned char>(); // tinygltf has copied what it needs
    s_.reset(calloc_n<lm_scene>(1));
    snprintf(s_->path, sizeof s_->path, "%s", path_);
    // the sky first: an EXT_lights_image_based cube's images still have their bytes (decode_used_images
    // drops them)
    if ((st = sky()) || (st = materials()) || (st = nodes()) || (st = animations()) || (st = geometry()) ||
        (st = finish()))
        return st;
    *out = s_.release();
    return LM_OK;
}

} // namespace

extern "C" lm_status lm_scene_load_gltf(const char *path, const lm_load_options *opt, lm_scene **out, lm_error *err)
{
    if (out)
        *out = nullptr;
    lm_error_clear(err);
    if (!path || !out)
        return lm_fail(err, LM_ERR_INVALID, "lm_scene_load_gltf: NULL %s", path ? "output" : "path");
    try {
        Loader loader(path, opt, err);
        return loader.run(out);
    } catch (const std::bad_alloc &) {
        return lm_fail(err, LM_ERR_NOMEM, "%s: out of memory", path);
    } catch (const std::exception &e) {
        return lm_fail(err, LM_ERR_FORMAT, "%s: %s", path, e.what());
    } catch (...) {
        return lm_fail(err, LM_ERR_FORMAT, "%s: unexpected error while loading", path);
    }
}
