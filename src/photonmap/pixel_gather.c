/* The brute-force photon gather at the visible pixels (pixel_gather.h). */
#include "pixel_gather.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"
#include "../trace/shading.h"
#include "photon_records.h"

#define KERNEL_C 0.2f /* the paper's cone clamped to a fifth of its height (eq. 2) */

lm_status lm_gbuffer_trace(lm_gbuffer *g, const lm_scene *s, const lm_rt *rt, const lm_view *cam, lm_error *err)
{
    size_t n = (size_t)cam->width * (size_t)cam->height;
    if (g->width != cam->width || g->height != cam->height) {
        float *pos = realloc(g->pos, 3 * n * sizeof *pos), *nrm = realloc(g->normal, 3 * n * sizeof *nrm);
        float *kd = realloc(g->kd, 3 * n * sizeof *kd);
        g->pos = pos ? pos : g->pos, g->normal = nrm ? nrm : g->normal, g->kd = kd ? kd : g->kd;
        if (!pos || !nrm || !kd)
            return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for a %d x %d picture's visible points", s->path,
                           cam->width, cam->height);
        g->width = cam->width, g->height = cam->height;
    }
    lm_vec3 fwd = lm_normalize(lm_v3_load(cam->forward)), right = lm_normalize(lm_cross(fwd, lm_v3_load(cam->up)));
    lm_vec3 up = lm_cross(right, fwd);
    float th = tanf(0.5f * cam->yfov), aspect = (float)cam->width / (float)cam->height;
#pragma omp parallel for schedule(dynamic, 64)
    for (long i = 0; i < (long)n; i++) {
        int x = (int)(i % cam->width), y = (int)(i / cam->width);
        float sx = (2.0f * ((float)x + 0.5f) / (float)cam->width - 1.0f) * th * aspect;
        float sy = (1.0f - 2.0f * ((float)y + 0.5f) / (float)cam->height) * th;
        float dir[3], *kd = g->kd + 3 * i, ks[3];
        lm_v3_store(dir, lm_normalize(lm_add(fwd, lm_add(lm_scale(right, sx), lm_scale(up, sy)))));
        memset(kd, 0, 3 * sizeof *kd);
        memset(g->pos + 3 * i, 0, 3 * sizeof(float));
        memset(g->normal + 3 * i, 0, 3 * sizeof(float));
        lm_rt_hit hit;
        float tnear = cam->znear / lm_dot(lm_v3_load(dir), fwd); /* the near plane, as the frame clips */
        if (!lm_rt_intersect(rt, cam->eye, dir, tnear, INFINITY, &hit))
            continue;
        lm_shading sh;
        lm_shading_from_hit(s, &hit, cam->eye, dir, &sh);
        int back = lm_dot(lm_v3_load(sh.ng), lm_v3_load(dir)) > 0.0f;
        memcpy(g->pos + 3 * i, sh.pos, sizeof sh.pos);
        lm_v3_store(g->normal + 3 * i, lm_scale(lm_v3_load(sh.ns), back ? -1.0f : 1.0f));
        if (!back || sh.material->double_sided) /* the back of a single-sided surface is black */
            lm_material_lobes(sh.material, sh.albedo, kd, ks);
    }
    return LM_OK;
}

void lm_gbuffer_free(lm_gbuffer *g)
{
    free(g->pos);
    free(g->normal);
    free(g->kd);
    memset(g, 0, sizeof *g);
}

/* The hits the gather takes: all but the punctual lights' first ones (their light is the direct pass's) and
 * the caustic ones (the caustic pass's; with it left out, nobody's). */
static int gathered(const lm_hit *h) { return lm_hit_in_iim(h); }

float lm_pixel_gather_radius(const lm_photon_store *ps, const lm_surfaces *su, int n)
{
    double area = 0.0, hits = 0.0;
    for (int k = 0; k < ps->surface_count && k < su->surface_count; k++) {
        area += su->surfaces[k].area;
        for (uint32_t j = 0; j < ps->surfaces[k].count; j++)
            hits += gathered(&ps->hits[ps->surfaces[k].slots[j]]);
    }
    return hits > 0.0 ? (float)sqrt((double)n * area / (LM_PI * hits)) : 0.0f;
}

/* The gathered hits packed for the inner loop: position, side normal (lm_hit_side_normal), flux. */
typedef struct {
    float *p, *side, *flux;
    uint32_t count;
} packed_hits;

static int pack(const lm_photon_store *ps, const lm_scene *s, packed_hits *out)
{
    uint32_t n = 0;
    for (int k = 0; k < ps->surface_count; k++)
        n += ps->surfaces[k].count;
    out->p = malloc(3 * (size_t)(n ? n : 1) * sizeof(float));
    out->side = malloc(3 * (size_t)(n ? n : 1) * sizeof(float));
    out->flux = malloc(3 * (size_t)(n ? n : 1) * sizeof(float));
    out->count = 0;
    if (!out->p || !out->side || !out->flux)
        return 0;
    for (int k = 0; k < ps->surface_count; k++)
        for (uint32_t j = 0; j < ps->surfaces[k].count; j++) {
            const lm_hit *x = &ps->hits[ps->surfaces[k].slots[j]];
            if (!gathered(x))
                continue;
            size_t at = 3 * (size_t)out->count++;
            memcpy(out->p + at, x->pos, 3 * sizeof(float));
            lm_hit_side_normal(s, x, out->side + at);
            memcpy(out->flux + at, x->flux, 3 * sizeof(float));
        }
    return 1;
}

/* Whether a photon at offset d from X (side normal np) lights X (normal nx): it lies on a surface that
 * continues X's smoothly, normals within 60 degrees and within r / 2 of X's tangent plane (a sphere of
 * radius r still counts). */
static int same_side(lm_vec3 d, lm_vec3 np, lm_vec3 nx, float radius)
{
    return lm_dot(np, nx) >= 0.5f && fabsf(lm_dot(d, nx)) <= 0.5f * radius;
}

void lm_pixel_gather_bruteforce(const lm_gbuffer *g, const lm_photon_store *ps, const lm_scene *s, float radius,
                                float *out)
{
    size_t n = (size_t)g->width * (size_t)g->height;
    memset(out, 0, 3 * n * sizeof *out);
    packed_hits h;
    if (!(radius > 0.0f) || !pack(ps, s, &h)) {
        if (radius > 0.0f)
            free(h.p), free(h.side), free(h.flux);
        return;
    }
    const float r2 = radius * radius, inv_r = 1.0f / radius;
    const double norm = LM_PI * KERNEL_C * (1.0 - KERNEL_C + KERNEL_C * KERNEL_C / 3.0) * (double)r2; /* eq. 3 */
#pragma omp parallel for schedule(dynamic, 16)
    for (long i = 0; i < (long)n; i++) {
        const float *kd = g->kd + 3 * i;
        if (kd[0] == 0.0f && kd[1] == 0.0f && kd[2] == 0.0f)
            continue;
        lm_vec3 x = lm_v3_load(g->pos + 3 * i), nx = lm_v3_load(g->normal + 3 * i);
        double sum[3] = {0.0, 0.0, 0.0};
        for (uint32_t k = 0; k < h.count; k++) {
            lm_vec3 d = lm_sub(lm_v3_load(h.p + 3 * (size_t)k), x);
            float d2 = lm_dot(d, d);
            if (d2 >= r2 || !same_side(d, lm_v3_load(h.side + 3 * (size_t)k), nx, radius))
                continue;
            float kappa = fminf(KERNEL_C, 1.0f - sqrtf(d2) * inv_r);
            for (int c = 0; c < 3; c++)
                sum[c] += (double)h.flux[3 * (size_t)k + c] * kappa;
        }
        for (int c = 0; c < 3; c++)
            out[3 * i + c] = (float)(kd[c] / LM_PI * sum[c] / norm);
    }
    free(h.p), free(h.side), free(h.flux);
}
