/* The gather's estimate of its own error from the AIM's noise (gather_error.h). */
#include "gather_error.h"

#include <math.h>
#include <string.h>

#include "../../charts/atlas_dilate.h"
#include "../../core/qmc.h"
#include "../../core/vecmath.h"
#include "../../photonmap/hemicube_rim.h"

void lm_gather_error_source(const lm_atlas *a, const float *aim_rgb, const float *aim_error, float *out)
{
    size_t n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n; i++) {
        float y = lm_luminance(aim_rgb + 3 * i);
        out[4 * i] = aim_error[2 * i] * y, out[4 * i + 1] = aim_error[2 * i + 1], out[4 * i + 2] = y;
        out[4 * i + 3] = 0.0f;
    }
    lm_atlas_dilate_gutters(a, out, 4);
}

/* Var(E) and the fully correlated sum for one texel (gather_error.h), luminance, with side^2 rays. */
static void texel_variance(const lm_hemicube_settings *set, const lm_scene *s, const lm_atlas *a, const lm_rt *rt,
                           const float *source, double corr_area, int side, uint32_t texel, double *var,
                           double *bound)
{
    float eye[3], n[3], ng[3];
    lm_gather_texel_frame(set, s, a, texel, eye, n, ng);
    lm_vec3 N = lm_v3_load(n), G = lm_v3_load(ng), T, B;
    lm_tangents(N, &T, &B);
    double shift[2], v = 0.0, sum = 0.0;
    lm_seed_shift(texel, shift);
    for (int i = 0; i < side; i++)
        for (int j = 0; j < side; j++) {
            double u1 = fmod((i + shift[0]) / side, 1.0), u2 = fmod((j + shift[1]) / side, 1.0);
            float sn, cs, rr = (float)sqrt(u1), cos_t = (float)sqrt(1.0 - u1);
            lm_sincos_turn((float)u2, &sn, &cs);
            lm_vec3 d = lm_add(lm_add(lm_scale(B, rr * cs), lm_scale(T, rr * sn)), lm_scale(N, cos_t));
            if (lm_dot(d, G) <= 0.0f)
                continue; /* into the texel's own surface */
            float dir[3], uv[2], src[3];
            lm_v3_store(dir, d);
            lm_rt_hit h;
            if (!lm_rt_intersect(rt, eye, dir, 0.0f, INFINITY, &h) || !lm_atlas_hit_uv(a, &h, uv))
                continue; /* the sky, a mirror or glass: no photon estimate, no noise */
            const lm_material *m = &s->materials[s->tri_material[h.tri]];
            double cos_h = -lm_dot(lm_v3_load(h.ng), d);
            if (!m->double_sided && cos_h < 0.0)
                continue; /* the back of a single-sided surface: black */
            lm_atlas_sample_rgb(a, source, uv[0], uv[1], src);
            double sy = src[0], r = src[1], d2 = (double)h.t * h.t;
            if (!(sy > 0.0) || !(d2 > 0.0))
                continue;
            v += sy * sy * corr_area * r * r * cos_t * fabs(cos_h) / d2;
            sum += sy;
        }
    int K = side * side;
    *var = LM_PI / K * v;
    *bound = LM_PI / K * sum;
}

void lm_gather_error(const lm_hemicube_settings *set, const lm_scene *s, const lm_atlas *a, const lm_rt *rt,
                     const float *source, const float *aim_error, int kernel, const float *iim_rgba, int samples,
                     float *out)
{
    memset(out, 0, sizeof *out * 4 * (size_t)a->width * a->height);
    int side = (int)sqrt((double)(samples > 1 ? samples : 1));
    double corr_area = LM_PI * (kernel ? 0.75 : 1.0); /* A_c / r^2 */
#pragma omp parallel for schedule(dynamic, 64)
    for (int64_t i = 0; i < (int64_t)a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        size_t at = (size_t)t->y * a->width + t->x;
        double var, bound, y = lm_luminance(iim_rgba + 4 * at);
        texel_variance(set, s, a, rt, source, corr_area, side, (uint32_t)i, &var, &bound);
        float *o = out + 4 * at;
        o[0] = y > 0.0 ? (float)(fmin(sqrt(var), bound) / y) : 0.0f;
        o[1] = aim_error[2 * at];
        o[2] = iim_rgba[4 * at + 3];
    }
}
