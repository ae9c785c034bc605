/* File-format-independent parts of scene loading: decoding accessor data, triangulating primitives,
 * generating normals, checking geometry, converting textures, and resolving the node graph. */
#include "scene_build.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/log.h"
#include "../core/vecmath.h"

/* A triangle is degenerate when twice its area is below this fraction of its longest edge squared:
 * such slivers have no usable normal or lightmap area in float precision. */
#define LM_DEGENERATE_REL 1e-7f

size_t lm_component_size(int comp_type)
{
    switch (comp_type) {
    case LM_COMP_BYTE:
    case LM_COMP_UNSIGNED_BYTE: return 1;
    case LM_COMP_SHORT:
    case LM_COMP_UNSIGNED_SHORT: return 2;
    case LM_COMP_UNSIGNED_INT:
    case LM_COMP_FLOAT: return 4;
    }
    return 0;
}

int lm_span_fits(uint64_t offset, uint64_t count, uint64_t stride, uint64_t elem, uint64_t avail)
{
    if (offset > avail)
        return 0;
    if (count == 0)
        return 1;
    uint64_t room = avail - offset;
    if (elem > room)
        return 0;
    /* (count - 1) * stride + elem <= room, without overflow */
    return stride == 0 || count - 1 <= (room - elem) / stride;
}

static float decode_one(const uint8_t *p, int comp_type, int normalized)
{
    switch (comp_type) {
    case LM_COMP_BYTE: {
        int8_t v = (int8_t)p[0];
        return normalized ? fmaxf((float)v / 127.0f, -1.0f) : (float)v;
    }
    case LM_COMP_UNSIGNED_BYTE: return normalized ? (float)p[0] / 255.0f : (float)p[0];
    case LM_COMP_SHORT: {
        int16_t v;
        memcpy(&v, p, 2);
        return normalized ? fmaxf((float)v / 32767.0f, -1.0f) : (float)v;
    }
    case LM_COMP_UNSIGNED_SHORT: {
        uint16_t v;
        memcpy(&v, p, 2);
        return normalized ? (float)v / 65535.0f : (float)v;
    }
    case LM_COMP_UNSIGNED_INT: {
        uint32_t v;
        memcpy(&v, p, 4);
        return normalized ? (float)((double)v / 4294967295.0) : (float)v;
    }
    case LM_COMP_FLOAT: {
        float v;
        memcpy(&v, p, 4);
        return v;
    }
    }
    return 0.0f;
}

void lm_decode_floats(const uint8_t *src, size_t count, size_t stride, int comp_type, int ncomp,
                      int normalized, float *out)
{
    size_t cs = lm_component_size(comp_type);
    for (size_t i = 0; i < count; i++)
        for (int c = 0; c < ncomp; c++)
            out[i * (size_t)ncomp + (size_t)c] = decode_one(src + i * stride + (size_t)c * cs, comp_type, normalized);
}

int lm_decode_indices(const uint8_t *src, size_t count, size_t stride, int comp_type, uint32_t *out)
{
    if (comp_type != LM_COMP_UNSIGNED_BYTE && comp_type != LM_COMP_UNSIGNED_SHORT &&
        comp_type != LM_COMP_UNSIGNED_INT)
        return 0;
    for (size_t i = 0; i < count; i++)
        out[i] = (uint32_t)decode_one(src + i * stride, comp_type, 0);
    return 1;
}

uint32_t lm_prim_tri_count(int mode, uint32_t n)
{
    if (mode == 4)
        return n / 3;
    if (mode == 5 || mode == 6)
        return n >= 3 ? n - 2 : 0;
    return 0;
}

void lm_prim_triangles(int mode, const uint32_t *idx, uint32_t n, uint32_t base, uint32_t *out)
{
    uint32_t t = lm_prim_tri_count(mode, n);
    for (uint32_t i = 0; i < t; i++) {
        uint32_t a, b, c;
        if (mode == 4) {
            a = idx[3 * i], b = idx[3 * i + 1], c = idx[3 * i + 2];
        } else if (mode == 5) { /* strip: every other triangle swaps to keep the winding */
            a = idx[i], b = idx[i + 1 + (i & 1)], c = idx[i + 2 - (i & 1)];
        } else { /* fan around the first index */
            a = idx[0], b = idx[i + 1], c = idx[i + 2];
        }
        out[3 * i] = a + base, out[3 * i + 1] = b + base, out[3 * i + 2] = c + base;
    }
}

void lm_generate_normals(float *normals, const float *positions, const uint32_t *tris, uint32_t tri_count,
                         uint32_t first_vertex, uint32_t vcount)
{
    float *n0 = normals + (size_t)first_vertex * 3;
    memset(n0, 0, (size_t)vcount * 3 * sizeof(float));
    for (uint32_t t = 0; t < tri_count; t++) {
        const uint32_t *v = tris + 3 * (size_t)t;
        lm_vec3 a = lm_v3_load(positions + 3 * (size_t)v[0]), b = lm_v3_load(positions + 3 * (size_t)v[1]);
        lm_vec3 c = lm_v3_load(positions + 3 * (size_t)v[2]);
        lm_vec3 fn = lm_cross(lm_sub(b, a), lm_sub(c, a)); /* length = 2 * area: area weighting */
        for (int k = 0; k < 3; k++) {
            float *n = normals + 3 * (size_t)v[k];
            lm_v3_store(n, lm_add(lm_v3_load(n), fn));
        }
    }
    for (uint32_t i = 0; i < vcount; i++) {
        lm_vec3 n = lm_normalize(lm_v3_load(n0 + 3 * (size_t)i));
        lm_v3_store(n0 + 3 * (size_t)i, lm_dot(n, n) > 0.0f ? n : lm_v3(0.0f, 0.0f, 1.0f));
    }
}

uint32_t lm_count_degenerate(const lm_scene *s, uint32_t first, uint32_t count)
{
    uint32_t bad = 0;
    for (uint32_t t = first; t < first + count; t++) {
        const uint32_t *v = s->tris + 3 * (size_t)t;
        lm_vec3 a = lm_v3_load(s->positions + 3 * (size_t)v[0]);
        lm_vec3 b = lm_v3_load(s->positions + 3 * (size_t)v[1]);
        lm_vec3 c = lm_v3_load(s->positions + 3 * (size_t)v[2]);
        lm_vec3 e0 = lm_sub(b, a), e1 = lm_sub(c, a), e2 = lm_sub(c, b);
        float longest = fmaxf(lm_dot(e0, e0), fmaxf(lm_dot(e1, e1), lm_dot(e2, e2)));
        float twice_area = lm_length(lm_cross(e0, e1));
        if (!(twice_area > LM_DEGENERATE_REL * longest))
            bad++;
    }
    return bad;
}

long lm_first_nonfinite(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return (long)i;
    return -1;
}

static float srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

int lm_texture_from_rgba8(lm_texture *t, const uint8_t *px, int w, int h, int srgb)
{
    float lut[256];
    for (int i = 0; i < 256; i++)
        lut[i] = srgb ? srgb_to_linear((float)i / 255.0f) : (float)i / 255.0f;
    size_t n = (size_t)w * (size_t)h;
    t->rgba = malloc(n * 4 * sizeof(float));
    if (!t->rgba)
        return 0;
    t->width = w, t->height = h;
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++)
            t->rgba[4 * i + (size_t)c] = lut[px[4 * i + (size_t)c]];
        t->rgba[4 * i + 3] = (float)px[4 * i + 3] / 255.0f; /* alpha is always linear */
    }
    return 1;
}

void lm_copy_name(char *dst, const char *src)
{
    size_t n = src ? strlen(src) : 0;
    if (n >= LM_NAME_MAX)
        n = LM_NAME_MAX - 1;
    if (n)
        memcpy(dst, src, n);
    dst[n] = '\0';
}

/* Walking up from any node must reach a root within node_count steps. */
/* Splits a local matrix into T, R, S (exact for matrices without shear). */
static void decompose(lm_node *n)
{
    const float *m = n->matrix;
    lm_vec3 c[3];
    for (int k = 0; k < 3; k++) {
        c[k] = lm_v3(m[4 * k], m[4 * k + 1], m[4 * k + 2]);
        n->scale[k] = lm_length(c[k]);
        n->translation[k] = m[12 + k];
    }
    if (lm_dot(lm_cross(c[0], c[1]), c[2]) < 0.0f) { /* mirrored: put the sign in the x scale */
        n->scale[0] = -n->scale[0];
        c[0] = lm_scale(c[0], -1.0f);
    }
    for (int k = 0; k < 3; k++)
        c[k] = n->scale[k] != 0.0f ? lm_normalize(c[k]) : lm_v3(k == 0, k == 1, k == 2);
    /* rotation matrix r[row][col] = c[col] component row; quaternion from its trace */
    float r00 = c[0].x, r11 = c[1].y, r22 = c[2].z, tr = r00 + r11 + r22;
    float *q = n->rotation;
    if (tr > 0.0f) {
        float s = sqrtf(tr + 1.0f) * 2.0f;
        q[3] = 0.25f * s, q[0] = (c[1].z - c[2].y) / s, q[1] = (c[2].x - c[0].z) / s, q[2] = (c[0].y - c[1].x) / s;
    } else if (r00 > r11 && r00 > r22) {
        float s = sqrtf(1.0f + r00 - r11 - r22) * 2.0f;
        q[3] = (c[1].z - c[2].y) / s, q[0] = 0.25f * s, q[1] = (c[1].x + c[0].y) / s, q[2] = (c[2].x + c[0].z) / s;
    } else if (r11 > r22) {
        float s = sqrtf(1.0f + r11 - r00 - r22) * 2.0f;
        q[3] = (c[2].x - c[0].z) / s, q[0] = (c[1].x + c[0].y) / s, q[1] = 0.25f * s, q[2] = (c[2].y + c[1].z) / s;
    } else {
        float s = sqrtf(1.0f + r22 - r00 - r11) * 2.0f;
        q[3] = (c[0].y - c[1].x) / s, q[0] = (c[2].x + c[0].z) / s, q[1] = (c[2].y + c[1].z) / s, q[2] = 0.25f * s;
    }
    lm_quat_normalize(q);
}

static int resolve_switch(int own, int parent_value) { return own >= 0 ? own : parent_value; }

/* Resolves node i, whose parent is resolved already. */
static void resolve_node(lm_scene *s, int i, const unsigned char *animated)
{
    lm_node *n = &s->nodes[i];
    const lm_node *p = n->parent >= 0 ? &s->nodes[n->parent] : NULL;
    /* A child of a moving node moves with it, whatever it says; otherwise its own flag or animation. */
    n->dynamic = (animated && animated[i]) || n->settings.dynamic == 1 || (p && p->dynamic);
    n->settings.dynamic = n->dynamic;
    n->settings.caustics = resolve_switch(n->settings.caustics, p ? p->settings.caustics : 1);
    n->settings.indirect = resolve_switch(n->settings.indirect, p ? p->settings.indirect : 1);
    n->settings.shadows = resolve_switch(n->settings.shadows, p ? p->settings.shadows : 1);
    n->settings.reflections = resolve_switch(n->settings.reflections, p ? p->settings.reflections : 1);
    n->settings.portal = n->settings.portal == 1;
}

/* glTF: a node whose world matrix has a negative determinant shows its triangles' other side as the
 * front. Reversing their winding once here makes the world winding say where the front is, for every
 * stage that decides a side (surfaces, photon hits, hemicube, shadows, the frame's gl_FrontFacing). */
static void reverse_mirrored(lm_scene *s)
{
    for (int i = 0; i < s->node_count; i++) {
        lm_node *n = &s->nodes[i];
        n->mirrored = lm_mat4_mirrors(n->world);
        for (uint32_t t = n->first_tri; n->mirrored && t < n->first_tri + n->tri_count; t++) {
            uint32_t *tri = s->tris + 3 * (size_t)t, v = tri[1];
            tri[1] = tri[2], tri[2] = v;
        }
    }
}

/* An animation that scales a node through zero to a negative product turns it over while it plays:
 * the winding stays as it was at load, so the node is then lit from behind. Said once per node. */
static void warn_mirroring_animations(const lm_scene *s)
{
    for (int a = 0; a < s->animation_count; a++)
        for (int c = 0; c < s->animations[a].channel_count; c++) {
            const lm_anim_channel *ch = &s->animations[a].channels[c];
            if (ch->path != LM_PATH_SCALE)
                continue;
            const lm_node *n = &s->nodes[ch->node];
            float own = n->scale[0] * n->scale[1] * n->scale[2];
            for (int k = 0; k < ch->key_count; k++) {
                const float *v = lm_anim_key_value(ch, k);
                if ((v[0] * v[1] * v[2] < 0.0f) != (own < 0.0f)) {
                    lm_warn("%s: animation \"%s\" mirrors node \"%s\" (scale key %d); its sides stay those of "
                            "its pose at load, so while mirrored it is lit from behind", s->path,
                            s->animations[a].name, n->name, k);
                    break;
                }
            }
        }
}

/* Float keeps 24 bits: a scene 1e6 units from the origin kept about 0.06 units of its positions (its
 * frame came out at a ninth of its brightness, black at 1e7, from rays' offsets and depth buffers that
 * lost their digits). A scene farther from the origin than LM_REBASE_RATIO times its own size (8 of its
 * bits spent on the offset) is moved to the origin by its root nodes, and their animated translations
 * with them; the file's coordinates are origin + lmgi's. Nearer, nothing changes. */
#define LM_REBASE_RATIO 256.0f

static void rebase(lm_scene *s)
{
    float size = lm_scene_size(s);
    lm_vec3 c = lm_scale(lm_add(lm_v3_load(s->bounds_min), lm_v3_load(s->bounds_max)), 0.5f);
    if (!(size > 0.0f) || fmaxf(fabsf(c.x), fmaxf(fabsf(c.y), fabsf(c.z))) <= LM_REBASE_RATIO * size)
        return;
    lm_v3_store(s->origin, c);
    for (int i = 0; i < s->node_count; i++) {
        lm_node *n = &s->nodes[i];
        for (int k = 0; k < 6 && n->settings.has_reflection_box; k++) /* world space, as the file gave it */
            n->settings.reflection_box[k] -= s->origin[k % 3];
        if (n->parent >= 0)
            continue;
        for (int k = 0; k < 3; k++)
            n->translation[k] -= s->origin[k], n->matrix[12 + k] -= s->origin[k];
    }
    for (int a = 0; a < s->animation_count; a++)
        for (int ci = 0; ci < s->animations[a].channel_count; ci++) {
            lm_anim_channel *ch = &s->animations[a].channels[ci];
            if (ch->path != LM_PATH_TRANSLATION || s->nodes[ch->node].parent >= 0)
                continue;
            for (int k = 0; k < ch->key_count; k++)
                for (int j = 0; j < 3; j++)
                    lm_anim_key_value(ch, k)[j] -= s->origin[j];
        }
    lm_scene_update_world(s);
    lm_scene_update_bounds(s);
    lm_info("%s: the scene lies %g units from the origin; lmgi works relative to (%g %g %g)", s->path,
            (double)lm_length(c), (double)c.x, (double)c.y, (double)c.z);
}

lm_status lm_scene_finish_nodes(lm_scene *s, const unsigned char *animated, lm_error *err)
{
    int c;
    int *order = lm_scene_parents_first(s, &c); /* iterative: a chain of any depth is fine */
    if (!order)
        return lm_fail(err, LM_ERR_NOMEM, "%s: out of memory resolving nodes", s->path);
    if (c >= 0) {
        free(order);
        return lm_fail(err, LM_ERR_FORMAT, "%s: node %d (\"%s\") is part of a cycle in the node hierarchy",
                       s->path, c, s->nodes[c].name);
    }
    for (int i = 0; i < s->node_count; i++) {
        lm_node *n = &s->nodes[i];
        if (n->has_matrix)
            decompose(n);
        else
            lm_mat4_from_trs(n->matrix, n->translation, n->rotation, n->scale);
        if (!lm_mat4_finite(n->matrix)) {
            free(order);
            return lm_fail(err, LM_ERR_INVALID, "%s: node %d (\"%s\") has a non-finite transform", s->path, i,
                           n->name);
        }
    }
    for (int i = 0; i < s->node_count; i++)
        resolve_node(s, order[i], animated);
    free(order);
    lm_scene_update_world(s);
    lm_scene_keep_bounds(s);
    lm_scene_update_bounds(s);
    reverse_mirrored(s);
    warn_mirroring_animations(s);
    lm_status st = lm_scene_check_extent(s, -1, err);
    if (st == LM_OK)
        rebase(s);
    return st;
}
