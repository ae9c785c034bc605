/* The scene model: freeing, world transforms, animation evaluation and geometric queries. */
#include "scene.h"

#include "../core/hash.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"

void lm_scene_free(lm_scene *s)
{
    if (!s)
        return;
    for (int i = 0; i < s->texture_count; i++)
        free(s->textures[i].rgba);
    for (int a = 0; a < s->animation_count; a++) {
        for (int c = 0; c < s->animations[a].channel_count; c++) {
            free(s->animations[a].channels[c].times);
            free(s->animations[a].channels[c].values);
        }
        free(s->animations[a].channels);
    }
    free(s->sky_image);
    free(s->portal_tris);
    free(s->nodes);
    free(s->materials);
    free(s->textures);
    free(s->lights);
    free(s->cameras);
    free(s->animations);
    free(s->positions);
    free(s->normals);
    free(s->uv0);
    free(s->uv1);
    free(s->vertex_node);
    free(s->tris);
    free(s->tri_material);
    free(s->tri_node);
    free(s->tri_twin);
    free(s->node_bounds);
    free(s);
}

static void local_matrix(lm_node *n)
{
    if (!n->has_matrix)
        lm_mat4_from_trs(n->matrix, n->translation, n->rotation, n->scale);
}

int *lm_scene_parents_first(const lm_scene *s, int *cycle)
{
    size_t n = (size_t)(s->node_count > 0 ? s->node_count : 0);
    int *order = malloc(sizeof(int) * (n + 1)), *stack = malloc(sizeof(int) * (n + 1));
    unsigned char *state = calloc(n + 1, 1); /* 0 unseen, 1 on the walk under way, 2 placed */
    *cycle = -1;
    if (!order || !stack || !state) {
        free(order), free(stack), free(state);
        return NULL;
    }
    int placed = 0;
    for (int i = 0; i < (int)n && *cycle < 0; i++) {
        /* walk up to a placed ancestor (or the root), then place the walked nodes top down */
        int top = 0, p = i;
        while (p >= 0 && p < (int)n && state[p] == 0) {
            state[p] = 1;
            stack[top++] = p;
            p = s->nodes[p].parent;
        }
        if (p >= 0 && p < (int)n && state[p] == 1)
            *cycle = p;
        while (top > 0) {
            int k = stack[--top];
            state[k] = 2;
            order[placed++] = k;
        }
    }
    free(stack);
    free(state);
    return order;
}

/* world = parent's world x local, parents first: O(nodes) whatever the depth. Without memory for the
 * order (or on a cycle, which loading refuses), each node's chain is walked up instead, bounded. */
void lm_scene_update_world(lm_scene *s)
{
    for (int i = 0; i < s->node_count; i++)
        local_matrix(&s->nodes[i]);
    int cycle;
    int *order = lm_scene_parents_first(s, &cycle);
    if (order && cycle < 0) {
        for (int i = 0; i < s->node_count; i++) {
            lm_node *n = &s->nodes[order[i]];
            if (n->parent >= 0)
                lm_mat4_mul(n->world, s->nodes[n->parent].world, n->matrix);
            else
                memcpy(n->world, n->matrix, sizeof n->matrix);
        }
        free(order);
        return;
    }
    free(order);
    for (int i = 0; i < s->node_count; i++) {
        float *w = s->nodes[i].world;
        memcpy(w, s->nodes[i].matrix, sizeof s->nodes[i].matrix);
        int p = s->nodes[i].parent;
        for (int steps = 0; p >= 0 && steps < s->node_count; steps++) {
            lm_mat4_mul(w, s->nodes[p].matrix, w);
            p = s->nodes[p].parent;
        }
    }
}

/* Index k of the last key with times[k] <= t (0 when t precedes every key). */
static int find_key(const lm_anim_channel *c, float t)
{
    int lo = 0, hi = c->key_count - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (c->times[mid] <= t)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

float *lm_anim_key_value(const lm_anim_channel *c, int k)
{
    int per_key = c->interp == LM_INTERP_CUBIC ? 3 : 1;
    return c->values + ((size_t)k * (size_t)per_key + (per_key == 3)) * (size_t)c->comps;
}

/* glTF cubic Hermite spline between keys k and k+1 at fraction u, tangents scaled by the interval. */
static void cubic(const lm_anim_channel *c, int k, float u, float dt, float *out)
{
    const float *p0 = lm_anim_key_value(c, k), *p1 = lm_anim_key_value(c, k + 1);
    const float *b0 = p0 + c->comps;     /* out-tangent of k */
    const float *a1 = p1 - c->comps;     /* in-tangent of k+1 */
    float u2 = u * u, u3 = u2 * u;
    float h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
    for (int i = 0; i < c->comps; i++)
        out[i] = h00 * p0[i] + h10 * dt * b0[i] + h01 * p1[i] + h11 * dt * a1[i];
}

static void eval_channel(const lm_anim_channel *c, float t, float *out)
{
    int n = c->key_count, k = find_key(c, t);
    if (t <= c->times[0] || k >= n - 1 || c->interp == LM_INTERP_STEP) {
        memcpy(out, lm_anim_key_value(c, t <= c->times[0] ? 0 : k), (size_t)c->comps * sizeof(float));
    } else {
        float dt = c->times[k + 1] - c->times[k];
        float u = dt > 0.0f ? (t - c->times[k]) / dt : 0.0f;
        const float *a = lm_anim_key_value(c, k), *b = lm_anim_key_value(c, k + 1);
        if (c->interp == LM_INTERP_CUBIC)
            cubic(c, k, u, dt, out);
        else if (c->path == LM_PATH_ROTATION)
            lm_quat_slerp(out, a, b, u);
        else
            for (int i = 0; i < c->comps; i++)
                out[i] = a[i] + (b[i] - a[i]) * u;
    }
    if (c->path == LM_PATH_ROTATION)
        lm_quat_normalize(out);
}

static void apply_channel(lm_scene *s, const lm_anim_channel *c, float t)
{
    if (c->node < 0 || c->node >= s->node_count || c->key_count < 1)
        return;
    lm_node *n = &s->nodes[c->node];
    if (n->edited)
        return;
    float v[4];
    eval_channel(c, t, v);
    float *dst = c->path == LM_PATH_TRANSLATION ? n->translation : c->path == LM_PATH_ROTATION ? n->rotation : n->scale;
    memcpy(dst, v, (size_t)(c->path == LM_PATH_ROTATION ? 4 : 3) * sizeof(float));
    n->has_matrix = 0; /* an animated node is driven by its TRS (decomposed from any matrix at load) */
}

void lm_scene_eval_animation(lm_scene *s, int anim, float t)
{
    if (!isfinite(t))
        t = 0.0f;
    for (int a = 0; a < s->animation_count; a++) {
        if (anim >= 0 && a != anim)
            continue;
        /* Clamping per channel to its key range is the same as clamping to the animation's range. */
        for (int c = 0; c < s->animations[a].channel_count; c++)
            apply_channel(s, &s->animations[a].channels[c], t);
    }
    lm_scene_update_world(s);
}

int lm_scene_set_node_world(lm_scene *s, int node, const float world[16])
{
    lm_node *n = &s->nodes[node];
    float local[16];
    if (n->parent >= 0) {
        float inv[16];
        if (!lm_mat4_invert_affine(inv, s->nodes[n->parent].world))
            return 0;
        lm_mat4_mul(local, inv, world);
    } else {
        memcpy(local, world, sizeof local);
    }
    memcpy(n->matrix, local, sizeof local);
    n->has_matrix = 1;
    n->edited = 1;
    lm_scene_update_world(s);
    return 1;
}

void lm_scene_release_node(lm_scene *s, int node) { s->nodes[node].edited = 0; }

float lm_scene_animation_duration(const lm_scene *s)
{
    float d = 0.0f;
    for (int a = 0; a < s->animation_count; a++)
        d = fmaxf(d, s->animations[a].duration);
    return d;
}

void lm_scene_vertex_world(const lm_scene *s, uint32_t v, float out[3])
{
    const float *m = s->nodes[s->vertex_node[v]].world;
    lm_v3_store(out, lm_mat4_point(m, lm_v3_load(s->positions + 3 * (size_t)v)));
}

void lm_scene_normal_world(const lm_scene *s, uint32_t v, float out[3])
{
    const float *m = s->nodes[s->vertex_node[v]].world;
    lm_v3_store(out, lm_mat4_normal(m, lm_v3_load(s->normals + 3 * (size_t)v)));
}

lm_vec3 lm_scene_tri_normal_world(const lm_scene *s, uint32_t t)
{
    float p[3][3];
    for (int k = 0; k < 3; k++)
        lm_scene_vertex_world(s, s->tris[3 * (size_t)t + (size_t)k], p[k]);
    lm_vec3 a = lm_v3_load(p[0]);
    return lm_normalize(lm_cross(lm_sub(lm_v3_load(p[1]), a), lm_sub(lm_v3_load(p[2]), a)));
}

float lm_scene_tri_area_world(const lm_scene *s, uint32_t t)
{
    float p[3][3];
    for (int k = 0; k < 3; k++)
        lm_scene_vertex_world(s, s->tris[3 * (size_t)t + (size_t)k], p[k]);
    lm_vec3 a = lm_v3_load(p[0]);
    return 0.5f * lm_length(lm_cross(lm_sub(lm_v3_load(p[1]), a), lm_sub(lm_v3_load(p[2]), a)));
}

float lm_scene_size(const lm_scene *s)
{
    lm_vec3 d = lm_sub(lm_v3_load(s->bounds_max), lm_v3_load(s->bounds_min));
    return d.x >= 0.0f ? lm_length(d) : 0.0f;
}

float lm_scene_ray_lift(const lm_scene *s)
{
    float size = lm_scene_size(s);
    return 1e-5f * (size > 0.0f && isfinite(size) ? size : 1.0f);
}

/* The world bounds of the corners of triangles [first, first + count), widened into *lo and *hi. */
static void widen_by_tris(const lm_scene *s, uint32_t first, uint32_t count, lm_vec3 *lo, lm_vec3 *hi)
{
    for (uint32_t t = first; t < first + count; t++) {
        for (int k = 0; k < 3; k++) {
            float p[3];
            lm_scene_vertex_world(s, s->tris[3 * (size_t)t + (size_t)k], p);
            *lo = lm_vmin(*lo, lm_v3_load(p));
            *hi = lm_vmax(*hi, lm_v3_load(p));
        }
    }
}

void lm_scene_keep_bounds(lm_scene *s)
{
    free(s->node_bounds);
    s->node_bounds = s->node_count > 0 ? malloc(sizeof *s->node_bounds * LM_NODE_BOUNDS * (size_t)s->node_count) : NULL;
    s->bounds_tris = NULL;
}

void lm_scene_node_local_boxes(const lm_scene *s, float *out)
{
    for (int n = 0; n < s->node_count; n++) {
        const lm_node *node = &s->nodes[n];
        float *b = out + 6 * (size_t)n;
        b[0] = b[1] = b[2] = INFINITY, b[3] = b[4] = b[5] = -INFINITY;
        for (uint32_t t = node->first_tri; t < node->first_tri + node->tri_count; t++)
            for (int k = 0; k < 3; k++) {
                const float *p = s->positions + 3 * (size_t)s->tris[3 * (size_t)t + (size_t)k];
                for (int a = 0; a < 3; a++)
                    b[a] = fminf(b[a], p[a]), b[3 + a] = fmaxf(b[3 + a], p[a]);
            }
    }
}

/* Bounds of the vertices that triangles use (unreferenced vertices don't count). An empty scene gets
 * min > max (size 0). */
void lm_scene_update_bounds(lm_scene *s)
{
    lm_vec3 lo = lm_v3(FLT_MAX, FLT_MAX, FLT_MAX), hi = lm_v3(-FLT_MAX, -FLT_MAX, -FLT_MAX);
    if (!s->node_bounds) { /* no cache (lm_scene_keep_bounds): every corner */
        widen_by_tris(s, 0, s->tri_count, &lo, &hi);
    } else {
        int fresh = s->bounds_tris != s->tris; /* none made yet, or the triangles split into sides since */
        s->bounds_tris = s->tris;
        for (int n = 0; n < s->node_count; n++) {
            const lm_node *nd = &s->nodes[n];
            float *c = s->node_bounds + LM_NODE_BOUNDS * (size_t)n, *m = c + 6;
            if (fresh || memcmp(m, nd->world, sizeof nd->world)) {
                lm_vec3 nlo = lm_v3(FLT_MAX, FLT_MAX, FLT_MAX), nhi = lm_v3(-FLT_MAX, -FLT_MAX, -FLT_MAX);
                widen_by_tris(s, nd->first_tri, nd->tri_count, &nlo, &nhi);
                lm_v3_store(c, nlo);
                lm_v3_store(c + 3, nhi);
                memcpy(m, nd->world, sizeof nd->world);
            }
            lo = lm_vmin(lo, lm_v3_load(c));
            hi = lm_vmax(hi, lm_v3_load(c + 3));
        }
    }
    lm_v3_store(s->bounds_min, lo);
    lm_v3_store(s->bounds_max, hi);
}

const char *lm_light_type_name(lm_light_type t)
{
    switch (t) {
    case LM_LIGHT_POINT: return "point";
    case LM_LIGHT_SPOT: return "spot";
    case LM_LIGHT_DIRECTIONAL: return "directional";
    }
    return "unknown";
}

int lm_node_under(const lm_scene *s, int node, int ancestor)
{
    for (int steps = 0; node >= 0 && node < s->node_count && steps <= s->node_count; steps++) {
        if (node == ancestor)
            return 1;
        node = s->nodes[node].parent; /* steps bound a cycle, which the loader refuses anyway */
    }
    return 0;
}

int lm_node_animated_under(const lm_scene *s, int node)
{
    for (int a = 0; a < s->animation_count; a++)
        for (int c = 0; c < s->animations[a].channel_count; c++)
            if (lm_node_under(s, s->animations[a].channels[c].node, node))
                return 1;
    return 0;
}

void lm_scene_set_dynamic(lm_scene *s, int node, int dynamic)
{
    for (int n = 0; n < s->node_count; n++)
        if (lm_node_under(s, n, node))
            s->nodes[n].dynamic = s->nodes[n].settings.dynamic = dynamic;
    s->pass_version++;
}

static int in_range(float v, float lo, float hi) { return v >= lo && v <= hi; } /* false for NaN */

/* Embree takes no ray whose numbers exceed about 1.8e18, and a scene near that would put rays and texel
 * sizes there (a vertex at 1e20 gave "texel inf units" and an abort inside Embree; a node moved to 1e30
 * a black frame). */
lm_status lm_scene_check_extent(const lm_scene *s, int node, lm_error *err)
{
    /* the nodes it covers, decided once: asking lm_node_under per vertex walked the parents a million
     * times for each edit of a large level */
    unsigned char *covered = malloc(s->node_count > 0 ? (size_t)s->node_count : 1);
    if (!covered)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory to check a node's extent", s->path);
    lm_status st = LM_OK;
    for (int n = 0; n < s->node_count; n++) { /* a light's or camera's place is its node's */
        const float *w = s->nodes[n].world;
        covered[n] = node < 0 || lm_node_under(s, n, node);
        for (int k = 0; k < 3 && covered[n] && st == LM_OK; k++)
            if (!(fabsf(w[12 + k]) <= LM_MAX_COORDINATE))
                st = lm_fail(err, LM_ERR_INVALID, "%s: node \"%s\" lies at %g, beyond the %g a coordinate may "
                             "reach", s->path, s->nodes[n].name, (double)w[12 + k], (double)LM_MAX_COORDINATE);
    }
    for (uint32_t v = 0; v < s->vertex_count && st == LM_OK; v++) {
        if (!covered[s->vertex_node[v]])
            continue;
        float p[3];
        lm_scene_vertex_world(s, v, p);
        for (int k = 0; k < 3 && st == LM_OK; k++)
            if (!(fabsf(p[k]) <= LM_MAX_COORDINATE))
                st = lm_fail(err, LM_ERR_INVALID, "%s: vertex %u (node \"%s\") lies at %g, beyond the %g a "
                             "coordinate may reach", s->path, v, s->nodes[s->vertex_node[v]].name, (double)p[k],
                             (double)LM_MAX_COORDINATE);
    }
    free(covered);
    return st;
}

lm_status lm_light_check(const char *what, const float color[3], float intensity, float range, int spot,
                         float inner_cone, float outer_cone, lm_error *err)
{
    for (int c = 0; c < 3; c++)
        if (!in_range(color[c], 0.0f, 1000.0f))
            return lm_fail(err, LM_ERR_INVALID, "%s: colour %g must be in [0, 1000] (glTF: [0, 1])", what,
                           (double)color[c]);
    if (!in_range(intensity, 0.0f, 1e15f) || !in_range(range, 0.0f, 1e15f))
        return lm_fail(err, LM_ERR_INVALID, "%s: intensity %g and range %g must each be in [0, 1e15]", what,
                       (double)intensity, (double)range);
    for (int c = 0; c < 3; c++)
        if (!((double)color[c] * intensity <= LM_MAX_EMISSION))
            return lm_fail(err, LM_ERR_INVALID, "%s: colour x intensity %g exceeds %g: its photon powers would "
                           "overflow to infinity", what, (double)color[c] * intensity, LM_MAX_EMISSION);
    if (spot && !(in_range(inner_cone, 0.0f, (float)(LM_PI / 2)) && in_range(outer_cone, 0.0f, (float)(LM_PI / 2)) &&
                  inner_cone <= outer_cone && outer_cone > 0.0f))
        return lm_fail(err, LM_ERR_INVALID, "%s: spot cones %g and %g must satisfy 0 <= inner <= outer <= pi/2, "
                       "outer > 0", what, (double)inner_cone, (double)outer_cone);
    return LM_OK;
}

void lm_light_place(const lm_scene *s, const lm_light *l, float pos[3], float dir[3])
{
    if (l->node < 0) {
        memcpy(pos, l->pos, 3 * sizeof *pos);
        lm_v3_store(dir, lm_normalize(lm_v3_load(l->dir)));
        return;
    }
    const float *w = s->nodes[l->node].world;
    lm_v3_store(pos, lm_v3(w[12], w[13], w[14]));
    lm_v3_store(dir, lm_normalize(lm_mat4_dir(w, lm_v3(0, 0, -1))));
}

uint64_t lm_scene_world_hash(const lm_scene *s)
{
    uint64_t h = LM_HASH_SEED;
    for (int n = 0; n < s->node_count; n++)
        h = lm_hash_bytes(h, s->nodes[n].world, sizeof s->nodes[n].world);
    return h;
}
