/* Portals: sampling through openings, and the density of a ray crossing them (portals.h). */
#include "portals.h"

#include <math.h>

#include "../core/vecmath.h"

static void corners(const lm_scene *s, uint32_t i, lm_vec3 c[3])
{
    for (int k = 0; k < 3; k++)
        c[k] = lm_v3_load(s->portal_tris + 9 * (size_t)i + 3 * (size_t)k);
}

/* Triangle i's area across direction d: 0 unless d enters by its front. */
static double weight(const lm_scene *s, uint32_t i, const float *d)
{
    lm_vec3 c[3];
    corners(s, i, c);
    lm_vec3 front = lm_cross(lm_sub(c[1], c[0]), lm_sub(c[2], c[0]));
    return fmax(-0.5 * lm_dot(front, lm_v3_load(d)), 0.0); /* half |front| times the cosine */
}

int lm_portal_crossings(const lm_scene *s, const float o[3], const float d[3])
{
    lm_vec3 O = lm_v3_load(o), D = lm_v3_load(d);
    int k = 0;
    for (uint32_t i = 0; i < s->portal_tri_count; i++) { /* Moller-Trumbore, the line's side t > 0 */
        lm_vec3 c[3];
        corners(s, i, c);
        lm_vec3 e1 = lm_sub(c[1], c[0]), e2 = lm_sub(c[2], c[0]), q = lm_cross(D, e2);
        float det = lm_dot(e1, q);
        if (!(lm_dot(lm_cross(e1, e2), D) < 0.0f) || fabsf(det) < 1e-30f)
            continue; /* not entering by its front */
        lm_vec3 tv = lm_sub(O, c[0]), r = lm_cross(tv, e1);
        float a = lm_dot(tv, q) / det, b = lm_dot(D, r) / det, t = lm_dot(e2, r) / det;
        k += a >= 0.0f && b >= 0.0f && a + b <= 1.0f && t > 0.0f;
    }
    return k;
}

double lm_portal_area(const lm_scene *s, const float d[3])
{
    double sum = 0.0;
    for (uint32_t i = 0; i < s->portal_tri_count; i++)
        sum += weight(s, i, d);
    return sum;
}

int lm_portal_point(const lm_scene *s, const float d[3], double total, float u0, float u1, float p[3])
{
    double at = (double)u0 * total, w = 0.0;
    if (!(total > 0.0))
        return 0;
    uint32_t i = 0;
    for (; i < s->portal_tri_count; i++) { /* the triangle whose share holds u0, and u0 within it */
        w = weight(s, i, d);
        if (w > 0.0 && (at < w || i + 1 == s->portal_tri_count))
            break;
        at -= w;
    }
    if (!(w > 0.0)) /* u0 rounded past the last facing triangle: the last one that faces */
        for (i = s->portal_tri_count; i-- > 0 && !((w = weight(s, i, d)) > 0.0);)
            ;
    float a = (float)fmin(fmax(at / w, 0.0), 1.0), r = sqrtf(a); /* uniform on the triangle */
    lm_vec3 c[3];
    corners(s, i, c);
    lm_vec3 x = lm_add(lm_scale(c[0], 1.0f - r), lm_add(lm_scale(c[1], r * (1.0f - u1)), lm_scale(c[2], r * u1)));
    lm_v3_store(p, x);
    return 1;
}
