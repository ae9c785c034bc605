/* Hit point attributes for light transport (shading.h). */
#include "shading.h"

#include <math.h>
#include <string.h>

#include "../core/vecmath.h"

/* Barycentric weights of Embree's (u, v): p = (1-u-v) v0 + u v1 + v v2. */
static void hit_weights(const lm_rt_hit *hit, float w[3])
{
    w[1] = hit->u;
    w[2] = hit->v;
    w[0] = 1.0f - hit->u - hit->v;
}

static inline __attribute__((always_inline)) lm_vec3 interp3(const float *attr, const uint32_t *idx, const float w[3])
{
    lm_vec3 r = lm_v3(0, 0, 0);
    for (int k = 0; k < 3; k++)
        r = lm_add(r, lm_scale(lm_v3_load(attr + 3 * (size_t)idx[k]), w[k]));
    return r;
}

static inline __attribute__((always_inline)) void interp2(const float *attr, const uint32_t *idx, const float w[3], float out[2])
{
    out[0] = out[1] = 0.0f;
    for (int k = 0; k < 3; k++) {
        out[0] += w[k] * attr[2 * (size_t)idx[k]];
        out[1] += w[k] * attr[2 * (size_t)idx[k] + 1];
    }
}

/* Shading normal: interpolated vertex normals in world space, flipped to ng's side; ng where the
 * interpolation degenerates. The normal transform is linear, so the local normals are interpolated
 * first and transformed once, by the node's normal matrix that the BVH keeps (no cofactors per hit).
 * A flat static triangle's comes with the hit, made once by the BVH. */
static lm_vec3 shading_normal(const lm_scene *s, const lm_rt_hit *hit, const uint32_t *idx, const float w[3],
                              lm_vec3 ng)
{
    if (hit->ns)
        return lm_v3_load(hit->ns);
    return lm_shading_normal_of(hit->nmat, interp3(s->normals, idx, w), ng);
}

static void fill_albedo(const lm_scene *s, const uint32_t *idx, const float w[3], lm_shading *sh)
{
    const lm_material *m = sh->material;
    if (m->base_color_tex < 0) { /* untextured (most hits): lm_material_albedo's factor, no call */
        for (int c = 0; c < 3; c++)
            sh->albedo[c] = m->base_color[c];
        return;
    }
    float uv[2]; /* texture coordinates only for a textured hit */
    interp2(m->base_color_uv == 1 && s->uv1 ? s->uv1 : s->uv0, idx, w, uv);
    lm_material_albedo(s, m, uv[0], uv[1], sh->albedo);
}

void lm_shading_from_hit(const lm_scene *s, const lm_rt_hit *hit, const float org[3], const float dir[3],
                         lm_shading *sh)
{
    /* Every field is written below (no memset: this runs once per photon hit). */
    const uint32_t *idx = s->tris + 3 * (size_t)hit->tri;
    float w[3];
    hit_weights(hit, w);
    const lm_node *node = &s->nodes[hit->node];
    lm_vec3 local = interp3(s->positions, idx, w);
    lm_vec3 pos = lm_mat4_point(node->world, local);
    if (!lm_v3_finite(pos)) /* fall back to the ray's own parameter */
        pos = lm_add(lm_v3_load(org), lm_scale(lm_v3_load(dir), hit->t));
    lm_v3_store(sh->pos, pos);
    lm_v3_store(sh->local, local);
    lm_vec3 ng = lm_v3_load(hit->ng);
    lm_v3_store(sh->ng, ng);
    lm_v3_store(sh->ns, shading_normal(s, hit, idx, w, ng));
    sh->material_id = s->tri_material[hit->tri];
    sh->material = &s->materials[sh->material_id];
    fill_albedo(s, idx, w, sh);
    sh->node = hit->node;
    sh->surface = hit->surface;
    sh->tri = hit->tri;
}

int lm_shading_normals_lean(const lm_shading *sh)
{
    return lm_dot(lm_v3_load(sh->ns), lm_v3_load(sh->ng)) < LM_NORMALS_AGREE;
}

float lm_shading_arrival_weight(const lm_shading *sh, const float dir[3])
{
    if (lm_material_is_specular(sh->material->cls) || !lm_shading_normals_lean(sh))
        return 1.0f;
    lm_vec3 d = lm_v3_load(dir);
    float cg = lm_dot(d, lm_v3_load(sh->ng)), cs = lm_dot(d, lm_v3_load(sh->ns));
    if (!(fabsf(cg) > 0.0f))
        return 0.0f; /* along the face: no density to weigh */
    float w = cs / cg; /* ns lies on ng's side: the same sign unless dir comes from behind ns */
    return w > 0.0f ? w : 0.0f;
}

const lm_shading *lm_shading_for_bounce(const lm_shading *sh, lm_shading *flat)
{
    lm_material_class c = sh->material->cls;
    if ((c != LM_MAT_DIFFUSE && c != LM_MAT_EMITTER) || !lm_shading_normals_lean(sh))
        return sh;
    *flat = *sh;
    memcpy(flat->ns, flat->ng, sizeof flat->ns);
    return flat;
}
