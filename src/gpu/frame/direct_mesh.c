#include "direct_mesh.h"

#include "../gl/gl_api.h"
#include <math.h>
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>

#include "../../core/vecmath.h"
#include "../../trace/bsdf.h"

#define FLOATS 18 /* pos, ns, base colour, (n or glass's ior, double-sided, metallic, class), emission, uv */

/* Group of triangle t: 0 without a base colour texture, else texture index + 1. */
static int group_of(const lm_scene *s, uint32_t t)
{
    const lm_material *m = &s->materials[s->tri_material[t]];
    int tex = m->base_color_tex;
    if (tex < 0 || tex >= s->texture_count || !s->textures[tex].rgba)
        return 0;
    return tex + 1;
}

/* KHR_texture_transform, as lm_material_albedo applies it (affine, so exact at the corners). */
static void transform_uv(const lm_material *m, const float in[2], float out[2])
{
    float su = in[0] * m->uv_scale[0], sv = in[1] * m->uv_scale[1];
    float c = cosf(m->uv_rotation), s = sinf(m->uv_rotation);
    out[0] = c * su + s * sv + m->uv_offset[0];
    out[1] = -s * su + c * sv + m->uv_offset[1];
}

/* The attributes of scene vertex vi drawn with material mi into v (FLOATS). The geometric normal is not
 * an attribute: the shaders take it from the position's screen derivatives, which is what lets corners
 * of different triangles share a vertex. */
static void vertex_attributes(const lm_scene *s, uint32_t vi, int mi, float *v)
{
    const lm_material *m = &s->materials[mi];
    lm_scene_vertex_world(s, vi, v);
    lm_scene_normal_world(s, vi, v + 3);
    memcpy(v + 6, m->base_color, 3 * sizeof(float));
    v[9] = m->cls == LM_MAT_GLOSSY ? lm_phong_exponent(m->roughness) : m->cls == LM_MAT_GLASS ? m->ior : 1.0f;
    v[10] = (float)m->double_sided;
    v[11] = fminf(fmaxf(m->metallic, 0.0f), 1.0f);
    v[12] = (float)m->cls;
    for (int c = 0; c < 3; c++)
        v[13 + c] = m->cls == LM_MAT_EMITTER ? m->emissive[c] : 0.0f;
    const float *uvs = m->base_color_uv == 1 && s->uv1 ? s->uv1 : s->uv0;
    transform_uv(m, uvs + 2 * (size_t)vi, v + 16);
}

static unsigned upload(const lm_texture *t)
{
    GLuint tex;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    /* row 0 (v = 0) first: GL's t = 0 is the first row, so uv addresses it as the CPU does */
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, t->width, t->height, 0, GL_RGBA, GL_FLOAT, t->rgba);
    /* mipmapped, for surfaces whose light is linear in the albedo (glsl/lobes.glsl's look_up_albedo) */
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    return tex;
}

/* What makes a corner's GPU vertex: scene vertex, material, lightmap uv (bits; 0 without an atlas). */
typedef struct {
    uint32_t vi;
    int32_t mat;
    float lm[2];
} corner_key;

/* Open-addressing map from corner keys to vertex slots, for one node at a time. */
typedef struct {
    corner_key *keys;
    int32_t *slot;
    size_t cap;
} corner_map;

static uint32_t hash_key(const corner_key *k)
{
    uint32_t w[4], h = 2166136261u;
    memcpy(w, k, sizeof w);
    for (int i = 0; i < 4; i++)
        h = (h ^ w[i]) * 16777619u;
    return h ^ (h >> 15);
}

static int map_reset(corner_map *m, size_t corners)
{
    size_t cap = 16;
    while (cap < 2 * corners)
        cap *= 2;
    if (cap > m->cap) {
        free(m->keys);
        free(m->slot);
        m->keys = malloc(sizeof *m->keys * cap);
        m->slot = malloc(sizeof *m->slot * cap);
        m->cap = m->keys && m->slot ? cap : 0;
        if (!m->cap)
            return 0;
    }
    memset(m->slot, 0xff, sizeof *m->slot * m->cap);
    return 1;
}

/* The slot of key k, given the next free slot *next when k is new. */
static int32_t map_slot(corner_map *m, const corner_key *k, int32_t *next)
{
    size_t h = hash_key(k) & (m->cap - 1);
    while (m->slot[h] >= 0 && memcmp(&m->keys[h], k, sizeof *k) != 0)
        h = (h + 1) & (m->cap - 1);
    if (m->slot[h] < 0) {
        m->keys[h] = *k;
        m->slot[h] = (*next)++;
    }
    return m->slot[h];
}

static corner_key key_of(const lm_scene *s, const lm_atlas *a, uint32_t t, int k)
{
    corner_key key;
    memset(&key, 0, sizeof key);
    key.vi = s->tris[3 * (size_t)t + k];
    key.mat = (int32_t)s->tri_material[t];
    if (a) { /* as lm_lightmapped_vertices; -2: the node's indirect light is switched off (the photon
              * gathers read it from the G-buffer, glsl/gbuffer_pack.glsl) */
        const float *c = a->corner_uv + 6 * (size_t)t + 2 * k;
        int none = a->tri_chart[t] < 0 || !isfinite(c[0]), off = !s->nodes[s->tri_node[t]].settings.indirect;
        key.lm[0] = off ? -2.0f : none ? -1.0f : c[0];
        key.lm[1] = off ? -2.0f : none ? -1.0f : c[1];
    }
    return key;
}

/* The built arrays before upload. */
typedef struct {
    float *vert, *lm_uv, *caster_pos;
    uint32_t *corner;        /* per triangle corner: its vertex */
    uint32_t *index, *caster_index; /* index: the full triangles, then the simplified ones */
    int verts, indices, casters, caster_indices;
} built;

static void built_free(built *b)
{
    free(b->vert);
    free(b->lm_uv);
    free(b->caster_pos);
    free(b->corner);
    free(b->index);
    free(b->caster_index);
}

/* Shading vertices, node by node (each node's vertices contiguous); returns 0 when out of memory. */
static int shading_vertices(lm_direct_mesh *d, const lm_scene *s, const lm_atlas *a, corner_map *map, built *b)
{
    int32_t next = 0;
    for (int n = 0; n < s->node_count; n++) {
        const lm_node *nd = &s->nodes[n];
        d->node_first[n] = next;
        if (!map_reset(map, 3 * (size_t)nd->tri_count))
            return 0;
        for (uint32_t t = nd->first_tri; t < nd->first_tri + nd->tri_count; t++)
            for (int k = 0; k < 3; k++) {
                corner_key key = key_of(s, a, t, k);
                int32_t before = next, v = map_slot(map, &key, &next);
                b->corner[3 * (size_t)t + k] = (uint32_t)v;
                if (v != before)
                    continue;
                d->vert_src[v] = key.vi;
                d->vert_mat[v] = key.mat;
                vertex_attributes(s, key.vi, key.mat, b->vert + (size_t)FLOATS * v);
                if (b->lm_uv)
                    memcpy(b->lm_uv + 2 * (size_t)v, key.lm, sizeof key.lm);
            }
        d->node_verts[n] = next - d->node_first[n];
    }
    b->verts = next;
    return 1;
}

typedef struct {
    float size; /* the diagonal of the node's world bounds, squared */
    int node;
} node_size;

static int smaller_first(const void *a, const void *b)
{
    const node_size *x = a, *y = b;
    return x->size < y->size ? -1 : x->size > y->size ? 1 : x->node - y->node;
}

/* The nodes in the order they are drawn: the smallest first, by their vertices' world bounds at the build
 * (ties by index). The walls, floors and terrain that enclose a scene are its largest nodes and lie behind
 * the props in most views, so drawn last their hidden pixels fail the early depth test instead of being
 * shaded and then covered (llvmpipe skips a block's shading when all of it fails). Where depths are equal
 * (a prop's foot on the floor) the prop is seen: GL_LESS keeps what was drawn first. NULL when out of memory. */
static int *draw_order(const lm_direct_mesh *d, const built *b)
{
    node_size *ns = malloc(sizeof *ns * (size_t)(d->node_count ? d->node_count : 1));
    int *order = malloc(sizeof(int) * (size_t)(d->node_count ? d->node_count : 1));
    if (!ns || !order) {
        free(ns);
        free(order);
        return NULL;
    }
    for (int n = 0; n < d->node_count; n++) {
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int v = d->node_first[n]; v < d->node_first[n] + d->node_verts[n]; v++)
            for (int k = 0; k < 3; k++) {
                lo[k] = fminf(lo[k], b->vert[(size_t)FLOATS * v + k]);
                hi[k] = fmaxf(hi[k], b->vert[(size_t)FLOATS * v + k]);
            }
        ns[n].node = n;
        ns[n].size = 0.0f;
        for (int k = 0; k < 3 && d->node_verts[n]; k++)
            ns[n].size += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    qsort(ns, (size_t)d->node_count, sizeof *ns, smaller_first);
    for (int n = 0; n < d->node_count; n++)
        order[n] = ns[n].node;
    free(ns);
    return order;
}

/* Indices grouped by texture (counting sort), the nodes in draw_order's order within a group, each group's
 * split sides last (lm_direct_mesh.paired); 0 when out of memory. */
static int shading_indices(lm_direct_mesh *d, const lm_scene *s, built *b)
{
    int *at = malloc(sizeof(int) * 2 * (size_t)d->groups), *at_paired = at + d->groups, *order = draw_order(d, b);
    if (!at || !order) {
        free(at);
        free(order);
        return 0;
    }
    for (uint32_t t = 0; t < s->tri_count; t++) {
        d->count[group_of(s, t)] += 3;
        d->paired[group_of(s, t)] += s->materials[s->tri_material[t]].split_sides ? 3 : 0;
    }
    for (int g = 1; g < d->groups; g++)
        d->first[g] = d->first[g - 1] + d->count[g - 1];
    for (int g = 0; g < d->groups; g++)
        at[g] = d->first[g], at_paired[g] = d->first[g] + d->count[g] - d->paired[g];
    for (int k = 0; k < s->node_count; k++) {
        const lm_node *nd = &s->nodes[order[k]];
        for (uint32_t t = nd->first_tri; t < nd->first_tri + nd->tri_count; t++) {
            int g = group_of(s, t), *o = s->materials[s->tri_material[t]].split_sides ? at_paired : at;
            memcpy(b->index + o[g], b->corner + 3 * (size_t)t, 3 * sizeof(uint32_t));
            o[g] += 3;
        }
    }
    free(at);
    free(order);
    b->indices = 3 * (int)s->tri_count;
    return 1;
}

/* The node whose vertex range holds mesh vertex v (node_first ascends with the node). */
static int node_of_vertex(const lm_direct_mesh *d, uint32_t v)
{
    int lo = 0, hi = d->node_count - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if ((uint32_t)d->node_first[mid] <= v)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo; /* the last node to start at or before v (one without vertices starts where the next does) */
}

/* Appends to b->index the simplified form of the n indices at `in`, whole triangles over node `node`'s
 * vertices; 0 when out of memory. */
static int simplify_run(const lm_direct_mesh *d, built *b, int node, size_t in, size_t n, float lod_error)
{
    unsigned *local = malloc(sizeof(unsigned) * 2 * n), *out = local + n;
    if (!local)
        return 0;
    uint32_t first = (uint32_t)d->node_first[node];
    for (size_t i = 0; i < n; i++)
        local[i] = b->index[in + i] - first;
    const float *pos = b->vert + (size_t)FLOATS * first;
    size_t verts = (size_t)d->node_verts[node], stride = sizeof(float) * FLOATS;
    float extent = meshopt_simplifyScale(pos, verts, stride); /* meshopt's error is relative to it */
    size_t m = n;
    if (extent > 0.0f)
        m = meshopt_simplify(out, local, n, pos, verts, stride, 0, lod_error / extent, 0, NULL);
    else
        memcpy(out, local, sizeof(unsigned) * n);
    for (size_t i = 0; i < m; i++)
        b->index[(size_t)b->indices + i] = out[i] + first;
    b->indices += (int)m;
    free(local);
    return 1;
}

/* The simplified triangles (lm_direct_mesh.lod_*) after the full ones: per group, its unpaired and then
 * its paired triangles, each node's run simplified on its own; 0 when out of memory. Without lod_error
 * the ranges are the full ones. */
static int lod_indices(lm_direct_mesh *d, built *b, float lod_error)
{
    if (!(lod_error > 0.0f)) {
        memcpy(d->lod_first, d->first, sizeof(int) * (size_t)d->groups);
        memcpy(d->lod_count, d->count, sizeof(int) * (size_t)d->groups);
        memcpy(d->lod_paired, d->paired, sizeof(int) * (size_t)d->groups);
        d->lod_tris = (uint32_t)b->indices / 3;
        return 1;
    }
    int full = b->indices;
    for (int g = 0; g < d->groups; g++) {
        d->lod_first[g] = b->indices;
        for (int side = 0; side < 2; side++) {
            int split = d->first[g] + d->count[g] - d->paired[g];
            int lo = side ? split : d->first[g], hi = side ? d->first[g] + d->count[g] : split, before = b->indices;
            for (int i = lo; i < hi;) {
                int node = node_of_vertex(d, b->index[i]), j = i;
                uint32_t v0 = (uint32_t)d->node_first[node], v1 = v0 + (uint32_t)d->node_verts[node];
                while (j < hi && b->index[j] >= v0 && b->index[j] < v1)
                    j += 3;
                if (!simplify_run(d, b, node, (size_t)i, (size_t)(j - i), lod_error))
                    return 0;
                i = j;
            }
            if (side)
                d->lod_paired[g] = b->indices - before;
        }
        d->lod_count[g] = b->indices - d->lod_first[g];
    }
    d->lod_tris = (uint32_t)(b->indices - full) / 3;
    return 1;
}

/* Caster positions and indices of one node (its own vertex range, one vertex per scene vertex). */
static int node_casters(lm_direct_mesh *d, const lm_scene *s, int n, corner_map *map, built *b)
{
    const lm_node *nd = &s->nodes[n];
    int32_t next = b->casters;
    d->caster_first[n] = next;
    if (!map_reset(map, 3 * (size_t)nd->tri_count))
        return 0;
    for (uint32_t t = nd->first_tri; t < nd->first_tri + nd->tri_count; t++)
        for (int k = 0; k < 3; k++) {
            corner_key key = {s->tris[3 * (size_t)t + k], 0, {0.0f, 0.0f}};
            int32_t before = next, v = map_slot(map, &key, &next);
            b->caster_index[b->caster_indices++] = (uint32_t)v;
            if (v != before)
                continue;
            d->caster_src[v] = key.vi;
            lm_scene_vertex_world(s, key.vi, b->caster_pos + 3 * (size_t)v);
        }
    d->caster_verts[n] = next - d->caster_first[n];
    b->casters = next;
    return 1;
}

/* The casters: static nodes' first, then the dynamic ones'. */
static int caster_geometry(lm_direct_mesh *d, const lm_scene *s, int shadows, corner_map *map, built *b)
{
    for (int pass = 0; pass < 2; pass++) {
        for (int n = 0; n < s->node_count; n++) {
            const lm_node *nd = &s->nodes[n];
            if (!shadows || !nd->settings.shadows || (nd->dynamic != 0) != (pass == 1))
                continue;
            if (!node_casters(d, s, n, map, b))
                return 0;
        }
        if (pass == 0)
            d->static_caster_indices = b->caster_indices;
    }
    return 1;
}

static int allocate(lm_direct_mesh *d, const lm_scene *s, const lm_atlas *a, built *b)
{
    size_t corners = 3 * (size_t)(s->tri_count ? s->tri_count : 1), nodes = s->node_count ? s->node_count : 1;
    uint32_t most = 1;
    for (int i = 0; i < s->node_count; i++)
        most = s->nodes[i].tri_count > most ? s->nodes[i].tri_count : most;
    d->first = calloc((size_t)d->groups, sizeof(int));
    d->count = calloc((size_t)d->groups, sizeof(int));
    d->paired = calloc((size_t)d->groups, sizeof(int));
    d->lod_first = calloc((size_t)d->groups, sizeof(int));
    d->lod_count = calloc((size_t)d->groups, sizeof(int));
    d->lod_paired = calloc((size_t)d->groups, sizeof(int));
    d->tex = calloc((size_t)d->groups, sizeof(unsigned));
    d->node_first = calloc(nodes, sizeof(int));
    d->node_verts = calloc(nodes, sizeof(int));
    d->caster_first = calloc(nodes, sizeof(int));
    d->caster_verts = calloc(nodes, sizeof(int));
    d->vert_src = malloc(sizeof(uint32_t) * corners);
    d->vert_mat = malloc(sizeof(int) * corners);
    d->caster_src = malloc(sizeof(uint32_t) * corners);
    d->node_world = malloc(sizeof(float) * 16 * nodes);
    d->scratch = malloc(sizeof(float) * FLOATS * 3 * most);
    b->vert = malloc(sizeof(float) * FLOATS * corners);
    b->lm_uv = a ? malloc(sizeof(float) * 2 * corners) : NULL;
    b->caster_pos = malloc(sizeof(float) * 3 * corners);
    b->corner = malloc(sizeof(uint32_t) * corners);
    b->index = malloc(sizeof(uint32_t) * 2 * corners); /* the simplified triangles after the full ones */
    b->caster_index = malloc(sizeof(uint32_t) * corners);
    return d->first && d->count && d->paired && d->lod_first && d->lod_count && d->lod_paired && d->tex &&
           d->node_first && d->node_verts && d->caster_first && d->caster_verts && d->vert_src && d->vert_mat &&
           d->caster_src && d->node_world && d->scratch &&
           b->vert && (b->lm_uv || !a) && b->caster_pos && b->corner && b->index && b->caster_index;
}

static void upload_meshes(lm_direct_mesh *d, const lm_scene *s, const built *b)
{
    const int sizes[6] = {3, 3, 3, 4, 3, 2}, pos_only[1] = {3};
    lm_gl_mesh_create_elements(&d->mesh, b->vert, b->verts, sizes, 6, b->index, b->indices);
    lm_gl_mesh_create_elements(&d->casters, b->caster_pos, b->casters, pos_only, 1, b->caster_index,
                               b->caster_indices);
    for (int g = 1; g < d->groups; g++)
        d->tex[g - 1] = d->count[g] ? upload(&s->textures[g - 1]) : 0;
    if (!b->lm_uv)
        return;
    glGenBuffers(1, &d->uv_vbo);
    glBindVertexArray(d->mesh.vao);
    glBindBuffer(GL_ARRAY_BUFFER, d->uv_vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 2 * (size_t)b->verts), b->lm_uv, GL_STATIC_DRAW);
    glVertexAttribPointer(7, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), (void *)0);
    glEnableVertexAttribArray(7);
}

/* The world bounds of the dynamic nodes' caster vertices under their current matrices (empty: lo > hi). */
static void dynamic_bounds(lm_direct_mesh *d, const lm_scene *s)
{
    for (int k = 0; k < 3; k++)
        d->dynamic_lo[k] = INFINITY, d->dynamic_hi[k] = -INFINITY;
    for (int n = 0; n < s->node_count && n < d->node_count; n++) {
        if (!s->nodes[n].dynamic)
            continue;
        for (int v = 0; v < d->caster_verts[n]; v++) {
            float p[3];
            lm_scene_vertex_world(s, d->caster_src[d->caster_first[n] + v], p);
            for (int k = 0; k < 3; k++)
                d->dynamic_lo[k] = fminf(d->dynamic_lo[k], p[k]), d->dynamic_hi[k] = fmaxf(d->dynamic_hi[k], p[k]);
        }
    }
}

lm_status lm_direct_mesh_build(lm_direct_mesh *d, const lm_scene *s, const lm_atlas *a, int shadows, float lod_error,
                               lm_error *err)
{
    memset(d, 0, sizeof *d);
    d->material_version = s->material_version;
    d->pass_version = s->pass_version;
    d->groups = s->texture_count + 1;
    d->node_count = s->node_count;
    built b;
    memset(&b, 0, sizeof b);
    corner_map map = {NULL, NULL, 0};
    int ok = allocate(d, s, a, &b) && shading_vertices(d, s, a, &map, &b) && shading_indices(d, s, &b) &&
             lod_indices(d, &b, lod_error) && caster_geometry(d, s, shadows, &map, &b);
    if (ok) {
        for (int i = 0; i < s->node_count; i++)
            memcpy(d->node_world + 16 * (size_t)i, s->nodes[i].world, sizeof s->nodes[i].world);
        upload_meshes(d, s, &b);
        dynamic_bounds(d, s);
    }
    built_free(&b);
    free(map.keys);
    free(map.slot);
    if (!ok) {
        lm_direct_mesh_free(d);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the direct-light meshes", s->path);
    }
    return LM_OK;
}

/* Node n's vertices (both meshes) recomputed from the scene and uploaded as one range each. */
static void upload_node(lm_direct_mesh *d, const lm_scene *s, int n)
{
    int first = d->node_first[n], count = d->node_verts[n];
    for (int v = 0; v < count; v++)
        vertex_attributes(s, d->vert_src[first + v], d->vert_mat[first + v], d->scratch + (size_t)FLOATS * v);
    glBindBuffer(GL_ARRAY_BUFFER, d->mesh.vbo);
    glBufferSubData(GL_ARRAY_BUFFER, (GLintptr)(sizeof(float) * FLOATS * (size_t)first),
                    (GLsizeiptr)(sizeof(float) * FLOATS * (size_t)count), d->scratch);
    first = d->caster_first[n];
    count = d->caster_verts[n];
    if (!count)
        return;
    for (int v = 0; v < count; v++) /* a node has no more caster vertices than shading vertices */
        lm_scene_vertex_world(s, d->caster_src[first + v], d->scratch + 3 * (size_t)v);
    glBindBuffer(GL_ARRAY_BUFFER, d->casters.vbo);
    glBufferSubData(GL_ARRAY_BUFFER, (GLintptr)(sizeof(float) * 3 * (size_t)first),
                    (GLsizeiptr)(sizeof(float) * 3 * (size_t)count), d->scratch);
}

int lm_direct_mesh_update(lm_direct_mesh *d, const lm_scene *s)
{
    int moved = 0, recolour = d->material_version != s->material_version;
    d->material_version = s->material_version;
    for (int i = 0; i < s->node_count && i < d->node_count; i++) {
        const lm_node *nd = &s->nodes[i];
        float *w = d->node_world + 16 * (size_t)i;
        if (recolour && nd->tri_count) /* the same places, new colours: no shadow is stale */
            upload_node(d, s, i);
        if (!memcmp(w, nd->world, sizeof nd->world))
            continue;
        memcpy(w, nd->world, sizeof nd->world);
        if (!nd->tri_count)
            continue;
        upload_node(d, s, i);
        moved |= LM_MESH_MOVED;
        if (nd->settings.shadows)
            moved |= nd->dynamic ? LM_MESH_DYNAMIC_CASTERS_MOVED : LM_MESH_STATIC_CASTERS_MOVED;
    }
    if (moved & LM_MESH_DYNAMIC_CASTERS_MOVED)
        dynamic_bounds(d, s);
    return moved;
}

static void draw_groups(const lm_direct_mesh *d, unsigned prog, const int *first, const int *count, const int *paired)
{
    GLint has_tex = prog ? glGetUniformLocation(prog, "has_tex") : -1;
    for (int g = 0; g < d->groups; g++) {
        if (!count[g])
            continue;
        if (has_tex >= 0)
            glUniform1i(has_tex, g > 0);
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D, g > 0 ? d->tex[g - 1] : 0);
        int unpaired = count[g] - paired[g];
        if (unpaired)
            lm_gl_mesh_draw_range(&d->mesh, first[g], unpaired);
        if (paired[g]) /* both sides lie in one plane: only the one facing the eye is drawn */
            lm_gl_mesh_draw_front_range(&d->mesh, first[g] + unpaired, paired[g]);
    }
}

void lm_direct_mesh_draw(const lm_direct_mesh *d, unsigned prog) { draw_groups(d, prog, d->first, d->count, d->paired); }

void lm_direct_mesh_draw_lod(const lm_direct_mesh *d, unsigned prog)
{
    draw_groups(d, prog, d->lod_first, d->lod_count, d->lod_paired);
}

void lm_direct_mesh_free(lm_direct_mesh *d)
{
    if (d->mesh.vao)
        lm_gl_mesh_destroy(&d->mesh);
    if (d->casters.vao)
        lm_gl_mesh_destroy(&d->casters);
    if (d->uv_vbo)
        glDeleteBuffers(1, &d->uv_vbo);
    for (int g = 0; d->tex && g + 1 < d->groups; g++)
        if (d->tex[g])
            glDeleteTextures(1, &d->tex[g]);
    free(d->first);
    free(d->count);
    free(d->paired);
    free(d->lod_first);
    free(d->lod_count);
    free(d->lod_paired);
    free(d->tex);
    free(d->node_first);
    free(d->node_verts);
    free(d->caster_first);
    free(d->caster_verts);
    free(d->vert_src);
    free(d->vert_mat);
    free(d->caster_src);
    free(d->node_world);
    free(d->scratch);
    memset(d, 0, sizeof *d);
}
