/* lmgi_load_desc: an application's own level (vertex and index arrays, materials, lights) handed over
 * without a file. The arrays are written into a .glb in memory and loaded by the glTF loader, so a scene
 * from arrays is checked, classified and split into sides exactly as a file is, with the same messages. */
#include <lmgi.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lmgi_scene.h"

typedef struct {
    char *s;
    size_t len, cap;
    int failed;
} text;

static void put(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(text *t, const char *fmt, ...)
{
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        size_t room = t->cap - t->len;
        int n = t->s ? vsnprintf(t->s + t->len, room, fmt, ap) : -1;
        va_end(ap);
        if (n >= 0 && (size_t)n < room) {
            t->len += (size_t)n;
            return;
        }
        size_t cap = t->cap ? 2 * t->cap : 4096;
        while (n >= 0 && cap - t->len <= (size_t)n)
            cap *= 2;
        char *grown = realloc(t->s, cap);
        if (!grown) {
            t->failed = 1;
            return;
        }
        t->s = grown, t->cap = cap;
    }
}

/* The binary chunk: each array appended 4-byte aligned; returns its offset. */
typedef struct {
    unsigned char *b;
    size_t len, cap;
    int failed;
} blob;

static size_t append(blob *b, const void *data, size_t n)
{
    size_t at = (b->len + 3) & ~(size_t)3;
    if (at + n > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < at + n)
            cap *= 2;
        unsigned char *grown = realloc(b->b, cap);
        if (!grown) {
            b->failed = 1;
            return 0;
        }
        b->b = grown, b->cap = cap;
    }
    memset(b->b + b->len, 0, at - b->len);
    memcpy(b->b + at, data, n);
    b->len = at + n;
    return at;
}

static int finite_all(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* What glTF and the loader cannot say as clearly: counts, indices and references. */
static lmgi_status check(const lmgi_scene_desc *d, lmgi_error *err)
{
    if (d->mesh_count < 1 || !d->meshes)
        return lm_api_refuse(err, "lmgi_load_desc: no meshes");
    if (d->material_count < 0 || (d->material_count > 0 && !d->materials) || d->light_count < 0 ||
        (d->light_count > 0 && !d->lights))
        return lm_api_refuse(err, "lmgi_load_desc: material or light count without the array");
    for (int i = 0; i < d->mesh_count; i++) {
        const lmgi_mesh_desc *m = &d->meshes[i];
        if (!m->positions || !m->indices || m->vertex_count == 0 || m->triangle_count == 0)
            return lm_api_refuse(err, "mesh %d: needs positions, indices and at least one triangle", i);
        for (size_t k = 0; k < 3 * (size_t)m->triangle_count; k++)
            if (m->indices[k] >= m->vertex_count)
                return lm_api_refuse(err, "mesh %d: index %zu is %u, but the mesh has %u vertices", i, k,
                                     m->indices[k], m->vertex_count);
        if (m->material < 0 || m->material >= d->material_count)
            return lm_api_refuse(err, "mesh %d: material %d, but the scene has %d", i, m->material,
                                 d->material_count);
        if (!finite_all(m->transform, 16))
            return lm_api_refuse(err, "mesh %d: its transform has NaN or infinite entries", i);
    }
    for (int i = 0; i < d->light_count; i++) {
        const lmgi_light_desc *l = &d->lights[i];
        if (!finite_all(l->position, 3) || !finite_all(l->direction, 3) || !finite_all(l->color, 3) ||
            !(l->intensity >= 0.0f) || !isfinite(l->intensity))
            return lm_api_refuse(err, "light %d: position, direction, colour and intensity must be finite (intensity "
                                 ">= 0)", i);
        if (l->type < LMGI_LIGHT_POINT || l->type > LMGI_LIGHT_DIRECTIONAL)
            return lm_api_refuse(err, "light %d: type %d is not a light type", i, (int)l->type);
    }
    return LMGI_OK;
}

static int is_zero(const float *v, int n)
{
    for (int i = 0; i < n; i++)
        if (v[i] != 0.0f)
            return 0;
    return 1;
}

static void put_floats(text *t, const float *v, int n)
{
    put(t, "[");
    for (int i = 0; i < n; i++)
        put(t, "%s%.9g", i ? "," : "", (double)v[i]);
    put(t, "]");
}

/* The rotation taking glTF's light direction (-Z) to d. */
static void light_rotation(const float d_in[3], float q[4])
{
    float len = sqrtf(d_in[0] * d_in[0] + d_in[1] * d_in[1] + d_in[2] * d_in[2]);
    float d[3] = {0, 0, -1};
    if (len > 0.0f)
        d[0] = d_in[0] / len, d[1] = d_in[1] / len, d[2] = d_in[2] / len;
    float dot = -d[2]; /* (0, 0, -1) . d */
    if (dot < -0.999999f) { /* straight up +Z: half a turn about x */
        q[0] = 1, q[1] = 0, q[2] = 0, q[3] = 0;
        return;
    }
    /* axis (0, 0, -1) x d, angle from w = 1 + dot, normalised */
    float x = d[1], y = -d[0], z = 0.0f, w = 1.0f + dot;
    float n = sqrtf(x * x + y * y + z * z + w * w);
    q[0] = x / n, q[1] = y / n, q[2] = z / n, q[3] = w / n;
}

/* One accessor over a view of the binary chunk. */
static void accessor(text *t, int *count, int comp, uint32_t n, const char *type, const float *min,
                     const float *max)
{
    put(t, "%s{\"bufferView\":%d,\"componentType\":%d,\"count\":%u,\"type\":\"%s\"", *count ? "," : "", *count, comp,
        n, type);
    if (min)
        put(t, ",\"min\":"), put_floats(t, min, 3), put(t, ",\"max\":"), put_floats(t, max, 3);
    put(t, "}");
    (*count)++;
}

static void write_meshes(const lmgi_scene_desc *d, text *json, text *views, text *acc, blob *bin, int *n_acc)
{
    put(json, "\"meshes\":[");
    for (int i = 0; i < d->mesh_count; i++) {
        const lmgi_mesh_desc *m = &d->meshes[i];
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (uint32_t v = 0; v < m->vertex_count; v++)
            for (int c = 0; c < 3; c++)
                lo[c] = fminf(lo[c], m->positions[3 * v + c]), hi[c] = fmaxf(hi[c], m->positions[3 * v + c]);
        struct {
            const void *data;
            size_t bytes;
            int comp;
            uint32_t n;
            const char *type, *attr;
        } arrays[4] = {
            {m->positions, 12 * (size_t)m->vertex_count, 5126, m->vertex_count, "VEC3", "POSITION"},
            {m->normals, 12 * (size_t)m->vertex_count, 5126, m->vertex_count, "VEC3", "NORMAL"},
            {m->uvs, 8 * (size_t)m->vertex_count, 5126, m->vertex_count, "VEC2", "TEXCOORD_0"},
            {m->indices, 12 * (size_t)m->triangle_count, 5125, 3 * m->triangle_count, "SCALAR", NULL},
        };
        put(json, "%s{\"name\":\"mesh %d\",\"primitives\":[{\"attributes\":{", i ? "," : "", i);
        int first = 1, index_acc = -1;
        for (int k = 0; k < 4; k++) {
            if (!arrays[k].data)
                continue;
            size_t at = append(bin, arrays[k].data, arrays[k].bytes);
            put(views, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", *n_acc ? "," : "", at, arrays[k].bytes);
            if (arrays[k].attr)
                put(json, "%s\"%s\":%d", first ? "" : ",", arrays[k].attr, *n_acc), first = 0;
            else
                index_acc = *n_acc;
            accessor(acc, n_acc, arrays[k].comp, arrays[k].n, arrays[k].type, k ? NULL : lo, k ? NULL : hi);
        }
        put(json, "},\"indices\":%d,\"material\":%d,\"mode\":4}]}", index_acc, m->material);
    }
    put(json, "],");
}

static void write_materials(const lmgi_scene_desc *d, text *json, int *uses_lights_ext, int *uses_mat_ext)
{
    put(json, "\"materials\":[");
    for (int i = 0; i < d->material_count; i++) {
        const lmgi_material_desc *m = &d->materials[i];
        float base[4] = {1, 1, 1, 1};
        if (!is_zero(m->base_color, 4))
            memcpy(base, m->base_color, sizeof base);
        float peak = fmaxf(m->emissive[0], fmaxf(m->emissive[1], m->emissive[2]));
        float emissive[3] = {0, 0, 0};
        for (int c = 0; peak > 0.0f && c < 3; c++) /* emissiveFactor is at most 1: the rest is strength */
            emissive[c] = m->emissive[c] / fmaxf(peak, 1.0f);
        put(json, "%s{\"name\":\"%s\",\"pbrMetallicRoughness\":{\"baseColorFactor\":", i ? "," : "",
            m->name ? m->name : "material");
        put_floats(json, base, 4);
        put(json, ",\"metallicFactor\":%.9g,\"roughnessFactor\":%.9g},\"emissiveFactor\":", (double)m->metallic,
            (double)(m->roughness > 0.0f ? m->roughness : 1.0f));
        put_floats(json, emissive, 3);
        put(json, ",\"doubleSided\":%s", m->double_sided ? "true" : "false");
        int ext = peak > 1.0f || m->transmission > 0.0f || m->ior > 0.0f;
        if (ext) {
            *uses_mat_ext = 1;
            put(json, ",\"extensions\":{");
            const char *sep = "";
            if (peak > 1.0f)
                put(json, "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":%.9g}", (double)peak), sep = ",";
            if (m->transmission > 0.0f)
                put(json, "%s\"KHR_materials_transmission\":{\"transmissionFactor\":%.9g}", sep,
                    (double)m->transmission), sep = ",";
            if (m->ior > 0.0f)
                put(json, "%s\"KHR_materials_ior\":{\"ior\":%.9g}", sep, (double)m->ior);
            put(json, "}");
        }
        put(json, "}");
    }
    put(json, "],");
    *uses_lights_ext = d->light_count > 0;
}

static void write_nodes(const lmgi_scene_desc *d, text *json)
{
    static const char *types[3] = {"point", "spot", "directional"};
    put(json, "\"scene\":0,\"scenes\":[{\"nodes\":[");
    for (int i = 0; i < d->mesh_count + d->light_count; i++)
        put(json, "%s%d", i ? "," : "", i);
    put(json, "]}],\"nodes\":[");
    for (int i = 0; i < d->mesh_count; i++) {
        const lmgi_mesh_desc *m = &d->meshes[i];
        put(json, "%s{\"name\":\"%s\",\"mesh\":%d", i ? "," : "", m->name ? m->name : "mesh", i);
        if (!is_zero(m->transform, 16))
            put(json, ",\"matrix\":"), put_floats(json, m->transform, 16);
        if (m->dynamic)
            put(json, ",\"extras\":{\"lmgi\":{\"dynamic\":true}}");
        put(json, "}");
    }
    for (int i = 0; i < d->light_count; i++) {
        const lmgi_light_desc *l = &d->lights[i];
        float q[4];
        light_rotation(l->direction, q);
        put(json, ",{\"name\":\"%s\",\"translation\":", l->name ? l->name : "light");
        put_floats(json, l->position, 3);
        put(json, ",\"rotation\":");
        put_floats(json, q, 4);
        put(json, ",\"extensions\":{\"KHR_lights_punctual\":{\"light\":%d}}}", i);
    }
    put(json, "],");
    if (d->light_count > 0) {
        put(json, "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[");
        for (int i = 0; i < d->light_count; i++) {
            const lmgi_light_desc *l = &d->lights[i];
            float color[3] = {1, 1, 1};
            if (!is_zero(l->color, 3))
                memcpy(color, l->color, sizeof color);
            put(json, "%s{\"type\":\"%s\",\"color\":", i ? "," : "", types[l->type]);
            put_floats(json, color, 3);
            put(json, ",\"intensity\":%.9g", (double)l->intensity);
            if (l->range > 0.0f)
                put(json, ",\"range\":%.9g", (double)l->range);
            if (l->type == LMGI_LIGHT_SPOT)
                put(json, ",\"spot\":{\"innerConeAngle\":%.9g,\"outerConeAngle\":%.9g}", (double)l->inner_cone,
                    (double)(l->outer_cone > 0.0f ? l->outer_cone : 0.785398163f));
            put(json, "}");
        }
        put(json, "]}},");
    }
}

/* The .glb: 12-byte header, the JSON chunk padded with spaces, the BIN chunk padded with zeros. */
static unsigned char *glb(const text *json, const blob *bin, size_t *size)
{
    size_t jlen = (json->len + 3) & ~(size_t)3, blen = (bin->len + 3) & ~(size_t)3;
    *size = 12 + 8 + jlen + 8 + blen;
    unsigned char *out = calloc(1, *size);
    if (!out)
        return NULL;
    uint32_t head[5] = {0x46546C67u, 2, (uint32_t)*size, (uint32_t)jlen, 0x4E4F534Au};
    memcpy(out, head, sizeof head);
    memcpy(out + 20, json->s, json->len);
    memset(out + 20 + json->len, ' ', jlen - json->len);
    uint32_t bhead[2] = {(uint32_t)blen, 0x004E4942u};
    memcpy(out + 20 + jlen, bhead, sizeof bhead);
    memcpy(out + 28 + jlen, bin->b, bin->len);
    return out;
}

lmgi_status lmgi_load_desc(const lmgi_scene_desc *d, const lmgi_options *o, lmgi_scene **out, lmgi_error *err)
{
    if (out)
        *out = NULL;
    if (!d || !out)
        return lm_api_refuse(err, "lmgi_load_desc: %s is NULL", d ? "out" : "the desc");
    lmgi_status st = check(d, err);
    if (st != LMGI_OK)
        return st;
    text json = {0}, views = {0}, acc = {0};
    blob bin = {0};
    int n_acc = 0, lights_ext = 0, mat_ext = 0;
    put(&json, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"lmgi_load_desc\"},");
    write_meshes(d, &json, &views, &acc, &bin, &n_acc);
    write_materials(d, &json, &lights_ext, &mat_ext);
    write_nodes(d, &json);
    if (lights_ext || mat_ext)
        put(&json, "\"extensionsUsed\":[%s%s%s],", lights_ext ? "\"KHR_lights_punctual\"" : "",
            lights_ext && mat_ext ? "," : "",
            mat_ext ? "\"KHR_materials_emissive_strength\",\"KHR_materials_transmission\",\"KHR_materials_ior\"" : "");
    put(&json, "\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[%s],\"accessors\":[%s]}", bin.len,
        views.s ? views.s : "", acc.s ? acc.s : "");
    size_t size = 0;
    unsigned char *file = json.failed || views.failed || acc.failed || bin.failed ? NULL : glb(&json, &bin, &size);
    st = file ? lmgi_load_memory(file, size, d->name ? d->name : "(scene desc)", o, out, err)
              : lm_export_error(err, &(lm_error){LM_ERR_NOMEM, "lmgi_load_desc: no memory for the scene"});
    free(file);
    free(json.s), free(views.s), free(acc.s), free(bin.b);
    return st;
}
