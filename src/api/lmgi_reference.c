/* The public API's reference: reference/reference.h's solver on a loaded scene, its results as images. */
#include <lmgi_tools.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../reference/reference.h"
#include "lmgi_camera.h"
#include "lmgi_reference.h"
#include "lmgi_scene.h"

lmgi_status lm_api_ref_settings(const lmgi_reference_desc *desc, const char *fn, lm_ref_settings *s, lmgi_error *err)
{
    lmgi_reference_desc d;
    memset(&d, 0, sizeof d);
    if (desc)
        d = *desc;
    lm_ref_settings_default(s);
    if (!(d.target_error >= 0.0f && d.target_error <= 1.0f))
        return lm_api_refuse(err, "%s: target_error %g must be in (0, 1] (0: the default)", fn, (double)d.target_error);
    if (d.samples < 0 || d.samples > 65536)
        return lm_api_refuse(err, "%s: samples %d must be in 1..65536 (0: the default)", fn, d.samples);
    if (d.caustic_photons < 0 || d.caustic_photons > (1 << 24))
        return lm_api_refuse(err, "%s: caustic_photons %d must be in 1..16777216 (0: the default)", fn,
                             d.caustic_photons);
    if (d.target_error > 0.0f)
        s->target_error = d.target_error;
    if (d.samples > 0) {
        s->samples = d.samples;
        s->min_samples = 2 * d.samples;
        if (s->max_samples < s->samples)
            s->max_samples = s->samples;
    }
    if (d.seed)
        s->seed = d.seed;
    if (d.caustic_photons > 0)
        s->caustic_photons = (uint32_t)d.caustic_photons;
    s->cache_dir = d.cache_dir;
    s->use_cache = !d.no_cache;
    return LMGI_OK;
}

/* Moves the internal result's arrays and figures into the public one (texel values spread into
 * atlas-sized images when atlas is given). */
static lm_status export_result(lm_ref_result *r, const lm_atlas *atlas, float target, lmgi_reference *out,
                               lm_error *err)
{
    out->target_error = target;
    out->width = r->width, out->height = r->height;
    out->entries = r->count, out->converged = r->converged;
    out->samples = r->total_samples, out->paths_cut = r->paths_cut;
    out->mean_rel_se = r->mean_rel_se, out->max_rel_se = r->max_rel_se;
    out->seconds = r->seconds, out->from_cache = r->from_cache;
    out->caustic_photons = r->caustic_photons, out->caustic_seconds = r->caustic_seconds;
    /* the same parts in the same order; NULL where the kind has none */
    float **src[] = {&r->full, &r->iim, &r->radiance, &r->direct, &r->caustic, &r->lost, &r->emission,
                     &r->indirect, &r->reflections};
    float **dst[] = {&out->full, &out->iim, &out->radiance, &out->direct, &out->caustic, &out->lost,
                     &out->emission, &out->indirect, &out->reflections};
    size_t bytes = atlas ? (size_t)atlas->width * (size_t)atlas->height * 3 * sizeof(float) : 0;
    for (size_t k = 0; k < sizeof src / sizeof *src; k++) {
        if (!*src[k])
            continue;
        if (!atlas) { /* pixels: the arrays are the images */
            *dst[k] = *src[k];
            *src[k] = NULL;
            continue;
        }
        if (!(*dst[k] = malloc(bytes)))
            return lm_fail(err, LM_ERR_NOMEM, "no memory for a %d x %d reference image", atlas->width, atlas->height);
        lm_ref_texels_to_image(atlas, *src[k], *dst[k]);
    }
    return LM_OK;
}

/* The solver on sc's world (photon work an updater left running finished first: it moves what is traced). */
static lmgi_status solve(const lmgi_scene *sc, const lm_ref_settings *set, const lm_view *cam,
                         lmgi_reference *out, lmgi_error *err)
{
    if (lm_scene_quiet(sc, "the reference", err) != LMGI_OK)
        return LMGI_ERR_INVALID;
    if (lm_scene_commit(sc, err) != LMGI_OK) /* the edits' placements in the BVH it traces */
        return err ? err->status : LMGI_ERR_BACKEND;
    lm_error e;
    lm_emitters em;
    lm_ref_result r;
    memset(&r, 0, sizeof r);
    lm_status st = lm_emitters_build(sc->scene, &em, &e);
    if (st == LM_OK) {
        st = cam ? lm_reference_pixels(sc->scene, sc->rt, &em, cam, set, &r, &e)
                 : lm_reference_texels(sc->scene, &sc->atlas, sc->rt, &em, set, &r, &e);
        lm_emitters_free(&em);
    }
    if (st == LM_OK)
        st = export_result(&r, cam ? NULL : &sc->atlas, set->target_error, out, &e);
    lm_ref_result_free(&r);
    if (st == LM_OK)
        return LMGI_OK;
    lmgi_reference_free(out);
    return lm_export_error(err, &e);
}

lmgi_status lmgi_reference_texels(const lmgi_scene *sc, const lmgi_reference_desc *desc, lmgi_reference *out,
                                  lmgi_error *err)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (!sc || !out)
        return lm_api_refuse(err, "lmgi_reference_texels: %s is NULL", sc ? "out" : "scene");
    lm_ref_settings set;
    if (lm_api_ref_settings(desc, "lmgi_reference_texels", &set, err) != LMGI_OK)
        return LMGI_ERR_INVALID;
    return solve(sc, &set, NULL, out, err);
}

lmgi_status lmgi_reference_pixels(const lmgi_scene *sc, const lmgi_reference_desc *desc, const lmgi_camera *cam,
                                  int width, int height, lmgi_reference *out, lmgi_error *err)
{
    static const char fn[] = "lmgi_reference_pixels";
    if (out)
        memset(out, 0, sizeof *out);
    if (!sc || !cam || !out)
        return lm_api_refuse(err, "%s: %s is NULL", fn, !sc ? "scene" : !cam ? "cam" : "out");
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        return lm_api_refuse(err, "%s: picture %d x %d must have sides in 1..16384", fn, width, height);
    lm_ref_settings set;
    lm_view v;
    if (lm_api_ref_settings(desc, fn, &set, err) != LMGI_OK || lm_api_view(sc, cam, fn, &v, err) != LMGI_OK)
        return LMGI_ERR_INVALID;
    lm_error e;
    if (lm_view_pinhole(&v, width, height, &e) != LM_OK)
        return lm_api_refuse(err, "%s: %s", fn, e.msg);
    return solve(sc, &set, &v, out, err);
}

void lmgi_reference_free(lmgi_reference *r)
{
    if (!r)
        return;
    float *images[9] = {r->full, r->iim, r->radiance, r->direct, r->caustic, r->lost, r->emission, r->indirect,
                        r->reflections};
    for (size_t k = 0; k < sizeof images / sizeof *images; k++)
        free(images[k]);
    memset(r, 0, sizeof *r);
}
