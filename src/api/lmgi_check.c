/* The public API's check: api/frame_check.h's comparison behind lmgi_check, on the caller's context. */
#include <lmgi_tools.h>

#include <stdlib.h>
#include <string.h>

#include "frame_check.h"
#include "lmgi_camera.h"
#include "lmgi_context.h"
#include "lmgi_reference.h"
#include "lmgi_scene.h"
#include "lmgi_updater.h"

#define CHECK_SIDE 128 /* the picture's side when the desc asks for none */

static void export_sum(const lm_check_sum *sum, uint32_t *pixels, double frame[3], double ref[3], double ratio[3])
{
    *pixels = sum->pixels;
    for (int k = 0; k < 3; k++) {
        frame[k] = sum->pixels ? sum->frame[k] / sum->pixels : 0.0;
        ref[k] = sum->pixels ? sum->ref[k] / sum->pixels : 0.0;
        ratio[k] = lm_check_ratio(sum, k);
    }
}

/* The internal check's figures and arrays moved into the public result. */
static lm_status export_check(lm_frame_check *c, const lmgi_scene *sc, float target, lmgi_check_result *out,
                              lm_error *err)
{
    out->width = c->width, out->height = c->height;
    out->frame = c->frame, out->reference = c->ref, out->compared = c->compared;
    out->caustic_frame = c->caustic, out->caustic_reference = c->ref_caustic;
    c->frame = c->ref = c->caustic = c->ref_caustic = NULL;
    c->compared = NULL;
    out->surface_count = c->surface_count;
    out->surfaces = calloc((size_t)(c->surface_count > 0 ? c->surface_count : 1), sizeof *out->surfaces);
    if (!out->surfaces)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for %d surfaces' figures", c->surface_count);
    for (int s = 0; s < c->surface_count; s++) {
        lmgi_check_surface *o = &out->surfaces[s];
        o->node = sc->surfaces.surfaces[s].node;
        o->material = sc->surfaces.surfaces[s].material;
        export_sum(&c->surface[s], &o->pixels, o->frame_mean, o->reference_mean, o->ratio);
    }
    export_sum(&c->lit, &out->pixels, out->frame_mean, out->reference_mean, out->ratio);
    out->rel_rmse = c->rel_rmse;
    uint32_t pixels;
    export_sum(&c->caustic_lit, &pixels, out->caustic_frame_mean, out->caustic_reference_mean, out->caustic_ratio);
    out->caustic_rel_rmse = c->caustic_rel_rmse;
    out->reference_target_error = target;
    out->reference_rel_se = c->ref_rel_se;
    out->reference_seconds = c->ref_seconds;
    return LM_OK;
}

static lmgi_status check_owned(lmgi_context *ctx, lmgi_scene *sc, const lmgi_updater_desc *desc,
                       const lmgi_reference_desc *ref, int frames, lmgi_check_result *out, lmgi_error *err)
{
    static const char fn[] = "lmgi_check";
    if (out)
        memset(out, 0, sizeof *out);
    if (!ctx || !sc || !out)
        return lm_api_refuse(err, "%s: %s is NULL", fn, !ctx ? "context" : !sc ? "scene" : "out");
    if (frames < 1)
        return lm_api_refuse(err, "%s: %d frames; at least 1", fn, frames);
    if (sc->updater)
        return lm_api_refuse(err, "%s: %s has an updater (the check runs its own, which moves the scene's nodes)",
                             fn, sc->scene->path);
    if (sc->scene->tri_count == 0)
        return lm_api_refuse(err, "%s: %s has no triangles to light", fn, sc->scene->path);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    if (desc)
        d = *desc;
    if (!d.frame.width && !d.frame.height)
        d.frame.width = d.frame.height = CHECK_SIDE;
    d.progress = NULL;
    lm_ref_settings rs;
    if (lm_api_ref_settings(ref, fn, &rs, err) != LMGI_OK)
        return LMGI_ERR_INVALID;
    lm_log_target saved = lm_api_enter(ctx);
    lm_error e;
    lm_frame_loop_settings ls;
    lm_frame_check c;
    memset(&c, 0, sizeof c);
    lm_status st = lm_updater_settings(sc->scene, &d, ctx->gl, &ls, &e);
    if (st == LM_OK)
        st = lm_frame_check_run(sc, &ls, &rs, frames, &c, &e);
    if (st == LM_OK)
        st = export_check(&c, sc, rs.target_error, out, &e);
    lm_frame_check_free(&c);
    lm_api_leave(saved);
    if (st == LM_OK)
        return LMGI_OK;
    lmgi_check_free(out);
    return lm_export_error(err, &e);
}

lmgi_status lmgi_check(lmgi_context *ctx, lmgi_scene *sc, const lmgi_updater_desc *desc,
                       const lmgi_reference_desc *ref, int frames, lmgi_check_result *out, lmgi_error *err)
{
    if (!ctx)
        return check_owned(ctx, sc, desc, ref, frames, out, err); /* refused there, naming it */
    lmgi_status st = lm_api_claim(ctx, "lmgi_check", err);
    if (st != LMGI_OK)
        return st;
    st = check_owned(ctx, sc, desc, ref, frames, out, err);
    lm_api_release(ctx);
    return st;
}

static lmgi_status check_updater_owned(lmgi_updater *u, const lmgi_camera *cam, int width, int height,
                               const lmgi_reference_desc *ref, lmgi_check_result *out, lmgi_error *err)
{
    static const char fn[] = "lmgi_check_updater";
    if (out)
        memset(out, 0, sizeof *out);
    if (!u || !cam || !out)
        return lm_api_refuse(err, "%s: %s is NULL", fn, !u ? "updater" : !cam ? "cam" : "out");
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        return lm_api_refuse(err, "%s: picture %d x %d must have sides in 1..16384", fn, width, height);
    const lmgi_scene *sc = lm_updater_scene(u);
    lm_view v;
    lm_ref_settings rs;
    if (lm_api_view(sc, cam, fn, &v, err) != LMGI_OK || lm_api_ref_settings(ref, fn, &rs, err) != LMGI_OK)
        return LMGI_ERR_INVALID;
    float *rgb = malloc((size_t)width * (size_t)height * 6 * sizeof *rgb), *caustic = rgb + (size_t)width * height * 3;
    if (!rgb)
        return lm_export_error(err, &(lm_error){LM_ERR_NOMEM, "lmgi_check_updater: no memory for the picture"});
    lmgi_context *ctx = lm_updater_context(u);
    lm_log_target saved = lm_api_enter(ctx);
    lm_error e;
    lm_frame_check c;
    memset(&c, 0, sizeof c);
    lm_status st = lm_updater_render(u, &v, width, height, rgb, &e); /* as lmgi_render draws it */
    if (st == LM_OK)
        st = lm_frame_loop_read_caustic_radiance(lm_updater_loop(u), caustic, &e);
    if (st == LM_OK)
        st = lm_gl_make_current(ctx->gl, &e); /* the surface index picture is drawn on it */
    if (st == LM_OK)
        st = lm_frame_check_picture(sc, &v, rgb, caustic, width, height, &rs, &c, &e);
    if (st == LM_OK)
        st = export_check(&c, sc, rs.target_error, out, &e);
    lm_frame_check_free(&c);
    free(rgb);
    lm_api_leave(saved);
    if (st == LM_OK)
        return LMGI_OK;
    lmgi_check_free(out);
    return lm_export_error(err, &e);
}

lmgi_status lmgi_check_updater(lmgi_updater *u, const lmgi_camera *cam, int width, int height,
                               const lmgi_reference_desc *ref, lmgi_check_result *out, lmgi_error *err)
{
    if (!u)
        return check_updater_owned(u, cam, width, height, ref, out, err); /* refused there, naming it */
    lmgi_status st = lm_api_claim(lm_updater_context(u), "lmgi_check_updater", err);
    if (st != LMGI_OK)
        return st;
    st = check_updater_owned(u, cam, width, height, ref, out, err);
    lm_api_release(lm_updater_context(u));
    return st;
}

void lmgi_check_free(lmgi_check_result *c)
{
    if (!c)
        return;
    free(c->frame);
    free(c->reference);
    free(c->caustic_frame);
    free(c->caustic_reference);
    free(c->compared);
    free(c->surfaces);
    memset(c, 0, sizeof *c);
}
