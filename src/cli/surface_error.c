/* The frame's error per visible surface (surface_error.h). */
#include "surface_error.h"

#include <math.h>

double lm_cli_surface_error(const lmgi_scene *sc, const lmgi_check_result *c, double *worst)
{
    double se = 0.0, w = 0.0;
    *worst = 0.0;
    for (int s = 0; s < c->surface_count; s++) {
        const lmgi_check_surface *f = &c->surfaces[s];
        lmgi_material mat;
        lmgi_error err;
        if (f->pixels < 20 || lmgi_get_material(sc, f->material, &mat, &err) != LMGI_OK ||
            mat.cls == LMGI_MATERIAL_EMITTER)
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
