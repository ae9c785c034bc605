/* Closed-form emitter irradiance with sampled visibility (emitter_light.h). */
#include "emitter_light.h"

#include "../core/qmc.h"
#include "../core/vecmath.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


typedef struct {
    double x, y, z;
} dvec;

static dvec dv(double x, double y, double z) { return (dvec){x, y, z}; }
static dvec dload(const float *p) { return dv(p[0], p[1], p[2]); }
static dvec dsub(dvec a, dvec b) { return dv(a.x - b.x, a.y - b.y, a.z - b.z); }
static dvec dadd(dvec a, dvec b) { return dv(a.x + b.x, a.y + b.y, a.z + b.z); }
static dvec dscale(dvec a, double s) { return dv(a.x * s, a.y * s, a.z * s); }
static double ddot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dvec dcross(dvec a, dvec b) { return dv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
static double dlen(dvec a) { return sqrt(ddot(a, a)); }

static int is_emissive(const lm_material *m)
{
    return m->emissive[0] > 0.0f || m->emissive[1] > 0.0f || m->emissive[2] > 0.0f;
}

uint32_t lm_emissive_triangle_count(const lm_scene *s)
{
    uint32_t n = 0;
    for (uint32_t t = 0; t < s->tri_count; t++)
        n += is_emissive(&s->materials[s->tri_material[t]]);
    return n;
}

int lm_emitter_light_suits(const lm_scene *s)
{
    uint32_t n = lm_emissive_triangle_count(s);
    return n > 0 && n <= LM_EMITTER_LIGHT_MAX_TRIANGLES;
}

lm_status lm_emitter_light_init(lm_emitter_light *el, const lm_scene *s, const lm_rt *rt, int rays, lm_error *err)
{
    memset(el, 0, sizeof *el);
    if (rays < 1)
        return lm_fail(err, LM_ERR_INVALID, "emitter light: %d shadow rays per triangle (need at least 1)", rays);
    uint32_t n = lm_emissive_triangle_count(s);
    el->tris = malloc(sizeof(uint32_t) * (n ? n : 1));
    if (!el->tris)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for %u emissive triangles", s->path, n);
    for (uint32_t t = 0; t < s->tri_count; t++)
        if (is_emissive(&s->materials[s->tri_material[t]]))
            el->tris[el->count++] = t;
    el->scene = s;
    el->rt = rt;
    el->rays = rays;
    return LM_OK;
}

void lm_emitter_light_free(lm_emitter_light *el)
{
    free(el->tris);
    memset(el, 0, sizeof *el);
}

/* The part of polygon in[0, n) with n . q >= 0 (q relative to the point): Sutherland-Hodgman against
 * one plane; a triangle gives at most 4 corners. */
static int clip_to_horizon(const dvec *in, int n, dvec nrm, dvec *out)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        dvec a = in[i], b = in[(i + 1) % n];
        double da = ddot(nrm, a), db = ddot(nrm, b);
        if (da >= 0.0)
            out[m++] = a;
        if ((da >= 0.0) != (db >= 0.0))
            out[m++] = dadd(a, dscale(dsub(b, a), da / (da - db)));
    }
    return m;
}

/* Whether a corner of q[0, m) lies below the horizon of nrm by more than a float normal's rounding: where
 * the shading normal is the geometric one, the second clip leaves the polygon as it was. */
static int dips_below(const dvec *q, int m, dvec nrm)
{
    for (int i = 0; i < m; i++)
        if (ddot(nrm, q[i]) < -1e-5 * dlen(q[i]))
            return 1;
    return 0;
}

/* Lambert's formula: irradiance per unit radiance from polygon q[0, n) (relative to the point, above
 * its horizon) at a point with normal nrm. */
static double lambert(const dvec *q, int n, dvec nrm)
{
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        dvec a = q[i], b = q[(i + 1) % n];
        double la = dlen(a), lb = dlen(b);
        if (!(la > 0.0) || !(lb > 0.0))
            continue;
        dvec g = dcross(a, b);
        double lg = dlen(g);
        if (!(lg > 0.0))
            continue; /* an edge seen end-on subtends no angle */
        double c = ddot(a, b) / (la * lb), theta = acos(c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c);
        sum += theta * ddot(nrm, g) / lg;
    }
    return 0.5 * fabs(sum);
}

/* Triangle tri's world corners, relative to p, clipped to p's horizon; the corner count (0 when p is
 * behind a single-sided emitter or the triangle is below the horizon). */
static int visible_polygon(const float v[3][3], int double_sided, dvec p, dvec nrm, dvec out[4])
{
    dvec q[3];
    for (int k = 0; k < 3; k++)
        q[k] = dsub(dload(v[k]), p);
    dvec face = dcross(dsub(q[1], q[0]), dsub(q[2], q[0]));
    if (!double_sided && !(ddot(face, q[0]) < 0.0)) /* p must be on the front: face . (p - v0) > 0 */
        return 0;
    return clip_to_horizon(q, 3, nrm, out);
}

double lm_triangle_irradiance_factor(const float v[3][3], int double_sided, const float p[3], const float n[3])
{
    dvec q[4], nrm = dload(n);
    int m = visible_polygon(v, double_sided, dload(p), nrm, q);
    return m >= 3 ? lambert(q, m, nrm) : 0.0;
}

/* Van der Corput radical inverse in base 2. */
static double radical_inverse2(uint32_t i)
{
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
    i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
    i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
    i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
    return (double)i * (1.0 / 4294967296.0);
}


typedef struct {
    double f, fv; /* sums of the unoccluded integrand and of the visible part */
} vis_sum;

/* k stratified points on triangle (a, b, c) (relative to p), each weighed by cos cos' / r^2 and tested
 * with a shadow ray, 8 rays to an Embree packet. face: the emitter's unit normal. */
static void sample_triangle(const lm_emitter_light *el, dvec p, dvec nrm, dvec face, const dvec t[3], int k,
                            const double shift[2], vis_sum *vs)
{
    const float org[3] = {(float)p.x, (float)p.y, (float)p.z};
    float dir[24], tfar[8];
    double f[8];
    int n = 0, blocked[8];
    for (int i = 0; i < k; i++) {
        double u = fmod((i + 0.5) / k + shift[0], 1.0), w = fmod(radical_inverse2((uint32_t)i) + shift[1], 1.0);
        double su = sqrt(u);
        dvec q = dadd(dscale(t[0], 1.0 - su), dadd(dscale(t[1], su * (1.0 - w)), dscale(t[2], su * w)));
        double r = dlen(q);
        if (!(r > 0.0))
            continue;
        dvec d = dscale(q, 1.0 / r);
        double fi = ddot(nrm, d) * fabs(ddot(face, d)) / (r * r);
        if (!(fi > 0.0))
            continue;
        vs->f += fi;
        f[n] = fi;
        dir[3 * n] = (float)d.x, dir[3 * n + 1] = (float)d.y, dir[3 * n + 2] = (float)d.z;
        tfar[n++] = (float)(r * (1.0 - 1e-4));
        if (n == 8 || i == k - 1) {
            lm_rt_occluded8(el->rt, org, dir, tfar, n, blocked);
            for (int j = 0; j < n; j++)
                vs->fv += blocked[j] ? 0.0 : f[j];
            n = 0;
        }
    }
    if (n > 0) { /* the last points were skipped after these */
        lm_rt_occluded8(el->rt, org, dir, tfar, n, blocked);
        for (int j = 0; j < n; j++)
            vs->fv += blocked[j] ? 0.0 : f[j];
    }
}

/* Fraction of polygon q[0, m) (3 to 5 corners, relative to p) that p sees, weighted by the integrand: its
 * fan of triangles from q[0], the rays shared by area (the first at least one). */
static double visibility(const lm_emitter_light *el, dvec p, dvec nrm, const dvec *q, int m, uint32_t seed)
{
    dvec face = dcross(dsub(q[1], q[0]), dsub(q[2], q[0]));
    double lf = dlen(face);
    if (!(lf > 0.0))
        return 1.0;
    face = dscale(face, 1.0 / lf);
    double area[3], total = 0.0;
    for (int i = 0; i < m - 2; i++)
        total += area[i] = 0.5 * dlen(dcross(dsub(q[i + 1], q[0]), dsub(q[i + 2], q[0])));
    double shift[2];
    lm_seed_shift(seed, shift);
    vis_sum vs = {0.0, 0.0};
    int given = 0;
    double before = 0.0;
    for (int i = 0; i < m - 2; i++) {
        before += area[i];
        int k = i == m - 3 ? el->rays - given : (int)lround(el->rays * before / total) - given;
        if (i == 0)
            k = k < 1 ? 1 : k;
        if (k <= 0)
            continue;
        const dvec t[3] = {q[0], q[i + 1], q[i + 2]};
        sample_triangle(el, p, nrm, face, t, k, shift, &vs);
        given += k;
    }
    return vs.f > 0.0 ? vs.fv / vs.f : 1.0;
}

void lm_emitter_irradiance(const lm_emitter_light *el, const float p[3], const float n[3], const float ng[3],
                           uint32_t seed, float out[3])
{
    double e[3] = {0.0, 0.0, 0.0};
    dvec pd = dload(p), nrm = dload(n), geo = ng ? dload(ng) : nrm;
    for (int j = 0; j < el->count; j++) {
        uint32_t t = el->tris[j];
        const lm_material *m = &el->scene->materials[el->scene->tri_material[t]];
        float v[3][3];
        for (int k = 0; k < 3; k++)
            lm_scene_vertex_world(el->scene, el->scene->tris[3 * (size_t)t + k], v[k]);
        dvec q[5]; /* a triangle clipped to two horizons has at most 5 corners */
        int corners = visible_polygon(v, m->double_sided, pd, nrm, q);
        if (ng && corners >= 3 && dips_below(q, corners, geo)) { /* and above the geometric horizon */
            dvec both[5];
            corners = clip_to_horizon(q, corners, geo, both);
            memcpy(q, both, sizeof *q * (size_t)corners);
        }
        double factor = corners >= 3 ? lambert(q, corners, nrm) : 0.0;
        if (!(factor > 0.0))
            continue;
        factor *= visibility(el, pd, nrm, q, corners, seed * 2654435761u + (uint32_t)j);
        for (int c = 0; c < 3; c++)
            e[c] += m->emissive[c] * factor;
    }
    for (int c = 0; c < 3; c++)
        out[c] = (float)e[c];
}
