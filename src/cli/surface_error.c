/* The frame's error per visible surface (surface_error.h). */
#include "surface_error.h"

#include <math.h>

/* Whether surface s counts: seen, and not an emitter. */
static int judged(const lmgi_scene *sc, const lmgi_check_surface *f, uint32_t min_pixels)
{
    lmgi_material mat;
    lmgi_error err;
    return f->pixels >= min_pixels && lmgi_get_material(sc, f->material, &mat, &err) == LMGI_OK &&
           mat.cls != LMGI_MATERIAL_EMITTER;
}

double lm_cli_surface_error(const lmgi_scene *sc, const lmgi_check_result *c, double *worst)
{
    double se = 0.0, w = 0.0;
    *worst = 0.0;
    for (int s = 0; s < c->surface_count; s++) {
        const lmgi_check_surface *f = &c->surfaces[s];
        if (!judged(sc, f, 20))
            continue;
        double fr = f->frame_mean[0] + f->frame_mean[1] + f->frame_mean[2];
        double rf = f->reference_mean[0] + f->reference_mean[1] + f->reference_mean[2];
        if (!(rf > 0.0))
            continue;
        double d = fabs(fr / rf - 1.0);
        se += f->pixels * d * d, w += f->pixels;
        if (f->pixels >= 100)
            *worst = fmax(*worst, d);
    }
    return w > 0.0 ? sqrt(se / w) : NAN;
}

double lm_cli_channel_off(const double frame[3], const double ref[3], int *channel)
{
    double floor = 0.05 * fmax(ref[0], fmax(ref[1], ref[2])), far = -1.0;
    int at = -1;
    for (int k = 0; floor > 0.0 && k < 3; k++) {
        double d = fabs(frame[k] - ref[k]) / fmax(ref[k], floor);
        if (d > far)
            far = d, at = k;
    }
    if (channel)
        *channel = at;
    return far;
}

void lm_cli_surface_channels(const lmgi_scene *sc, const lmgi_check_result *c, double tol, lm_cli_channel_check *out)
{
    *out = (lm_cli_channel_check){0, 0, -1, 0, 0.0, 0.0};
    for (int s = 0; s < c->surface_count; s++) {
        const lmgi_check_surface *f = &c->surfaces[s];
        int k;
        double far = judged(sc, f, 100) ? lm_cli_channel_off(f->frame_mean, f->reference_mean, &k) : -1.0;
        if (far < 0.0)
            continue;
        out->surfaces++;
        out->within += far <= tol;
        if (far > out->worst) {
            const double *r = f->reference_mean, *m = f->frame_mean;
            out->worst = far, out->worst_surface = s, out->worst_channel = k;
            out->worst_ratio = r[k] > 0.0 ? m[k] / r[k] - 1.0 : INFINITY;
        }
    }
}
