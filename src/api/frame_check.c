#include "frame_check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../gpu/frame/surface_view.h"

double lm_check_ratio(const lm_check_sum *c, int channel)
{
    if (c->ref[channel] == 0.0)
        return c->frame[channel] == 0.0 ? 1.0 : INFINITY;
    return c->frame[channel] / c->ref[channel];
}

void lm_frame_check_free(lm_frame_check *c)
{
    free(c->frame);
    free(c->ref);
    free(c->ref_indirect);
    free(c->caustic);
    free(c->ref_caustic);
    free(c->surface_at);
    free(c->compared);
    free(c->surface);
    memset(c, 0, sizeof *c);
}

static int emissive_surface(const lmgi_scene *sc, int surface)
{
    const float *e = sc->scene->materials[sc->surfaces.surfaces[surface].material].emissive;
    return e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f;
}

static void add(lm_check_sum *c, const float *frame, const float *ref)
{
    c->pixels++;
    for (int k = 0; k < 3; k++) {
        c->frame[k] += frame[k];
        c->ref[k] += ref[k];
    }
}

/* A pixel whose four neighbours show its surface too: the reference's pixel is an average over its
 * area, the frame's a sample at its centre, so along an edge they see different things (aliasing, not
 * lighting error). */
static int interior(const lm_frame_check *c, size_t i)
{
    int w = c->width, h = c->height, x = (int)(i % (size_t)w), y = (int)(i / (size_t)w), s = c->surface_at[i];
    if (x == 0 || y == 0 || x == w - 1 || y == h - 1)
        return 0;
    return c->surface_at[i - 1] == s && c->surface_at[i + 1] == s && c->surface_at[i - (size_t)w] == s &&
           c->surface_at[i + (size_t)w] == s;
}

/* Sums per surface and over the lit pixels, and the relative RMSE over those. */
static lm_status compare(const lmgi_scene *sc, lm_frame_check *c, lm_error *err)
{
    size_t n = (size_t)c->width * (size_t)c->height;
    uint8_t *mask = calloc(n, 1);
    if (!mask)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the frame check's mask");
    for (size_t i = 0; i < n; i++) {
        int s = c->surface_at[i];
        if (s < 0 || s >= c->surface_count || !interior(c, i))
            continue;
        c->compared[i] = 1;
        add(&c->surface[s], c->frame + 3 * i, c->ref + 3 * i);
        if (!emissive_surface(sc, s)) {
            add(&c->lit, c->frame + 3 * i, c->ref + 3 * i);
            add(&c->caustic_lit, c->caustic + 3 * i, c->ref_caustic + 3 * i);
            mask[i] = 1;
        }
    }
    c->rel_rmse = lm_ref_relative_rmse(c->frame, c->ref, mask, n, 3);
    c->caustic_rel_rmse = lm_ref_relative_rmse(c->caustic, c->ref_caustic, mask, n, 3);
    free(mask);
    return LM_OK;
}

/* The frame loop's picture after `frames` frames into rgb, and (each not NULL) what its caustics added and
 * the surface index of each of its pixels. */
static lm_status run_frames(lmgi_scene *sc, const lm_frame_loop_settings *set, int frames, float *rgb,
                            float *caustic, int32_t *surface_at, lm_view *view, lm_error *err)
{
    lm_frame_loop *fl = NULL;
    lm_status st = lm_frame_loop_create(&sc->world, set, &fl, NULL, NULL, err);
    for (int f = 0; st == LM_OK && f < (frames > 0 ? frames : 1); f++) {
        lm_frame_stats fs;
        st = lm_frame_loop_step(fl, (float)f / 30.0f, &fs, err);
    }
    if (st == LM_OK) {
        memcpy(rgb, lm_frame_loop_image(fl), (size_t)set->width * (size_t)set->height * 3 * sizeof(float));
        *view = *lm_frame_loop_view(fl);
    }
    if (st == LM_OK && caustic)
        st = lm_frame_loop_read_caustic_radiance(fl, caustic, err);
    if (st == LM_OK && surface_at) /* drawn with the loop's context still current (it has no other) */
        st = lm_render_surface_index(sc->scene, &sc->surfaces, view, set->width, set->height, surface_at, err);
    lm_frame_loop_free(fl);
    return st;
}

static lm_status reference_pixels(const lmgi_scene *sc, const lm_view *view, const lm_ref_settings *set,
                                  lm_frame_check *c, lm_error *err)
{
    lm_view cam = *view;
    lm_status st = lm_view_pinhole(&cam, c->width, c->height, err);
    if (st == LM_OK && lm_edits_pending(&sc->edits) && lm_scene_quiet(sc, "the frame check", NULL) != LMGI_OK)
        st = lm_fail(err, LM_ERR_INVALID, "%s: the context is in use by another thread", sc->scene->path);
    if (st == LM_OK) /* the edits in the scene and the BVH it traces */
        st = lm_edits_commit(&sc->world, err);
    if (st != LM_OK)
        return st;
    lm_emitters em;
    if ((st = lm_emitters_build(sc->scene, &em, err)) != LM_OK)
        return st;
    lm_ref_result r;
    st = lm_reference_pixels(sc->scene, sc->rt, &em, &cam, set, &r, err);
    lm_emitters_free(&em);
    if (st != LM_OK)
        return st;
    memcpy(c->ref, r.full, (size_t)r.count * 3 * sizeof(float));
    memcpy(c->ref_indirect, r.indirect, (size_t)r.count * 3 * sizeof(float));
    memcpy(c->ref_caustic, r.caustic, (size_t)r.count * 3 * sizeof(float));
    c->ref_rel_se = r.mean_rel_se;
    c->ref_seconds = r.seconds;
    lm_ref_result_free(&r);
    return LM_OK;
}

lm_status lm_frame_check_frame(lmgi_scene *sc, const lm_frame_loop_settings *loop, int frames, float *rgb,
                               lm_error *err)
{
    lm_view view;
    return run_frames(sc, loop, frames, rgb, NULL, NULL, &view, err);
}

/* out's arrays for a width x height picture. */
static lm_status alloc_check(const lmgi_scene *sc, int width, int height, lm_frame_check *out, lm_error *err)
{
    memset(out, 0, sizeof *out);
    out->width = width, out->height = height;
    size_t n = (size_t)out->width * (size_t)out->height;
    out->surface_count = sc->surfaces.surface_count;
    out->frame = malloc(n * 3 * sizeof(float));
    out->ref = malloc(n * 3 * sizeof(float));
    out->ref_indirect = malloc(n * 3 * sizeof(float));
    out->caustic = calloc(n * 3, sizeof(float));
    out->ref_caustic = malloc(n * 3 * sizeof(float));
    out->surface_at = malloc(n * sizeof(int32_t));
    out->compared = calloc(n, 1);
    out->surface = calloc((size_t)(out->surface_count ? out->surface_count : 1), sizeof *out->surface);
    return out->frame && out->ref && out->ref_indirect && out->caustic && out->ref_caustic && out->surface_at &&
                   out->compared && out->surface
               ? LM_OK
               : lm_fail(err, LM_ERR_NOMEM, "no memory to check a %dx%d frame", out->width, out->height);
}

lm_status lm_frame_check_run(lmgi_scene *sc, const lm_frame_loop_settings *loop, const lm_ref_settings *ref,
                             int frames, lm_frame_check *out, lm_error *err)
{
    lm_status st = alloc_check(sc, loop->width, loop->height, out, err);
    lm_view view;
    if (st == LM_OK)
        st = run_frames(sc, loop, frames, out->frame, out->caustic, out->surface_at, &view, err);
    if (st == LM_OK)
        st = reference_pixels(sc, &view, ref, out, err);
    if (st == LM_OK)
        st = compare(sc, out, err);
    if (st != LM_OK)
        lm_frame_check_free(out);
    return st;
}

lm_status lm_frame_check_picture(const lmgi_scene *sc, const lm_view *view, const float *rgb, const float *caustic,
                                 int width, int height, const lm_ref_settings *ref, lm_frame_check *out,
                                 lm_error *err)
{
    lm_status st = alloc_check(sc, width, height, out, err);
    if (st == LM_OK) {
        memcpy(out->frame, rgb, (size_t)width * (size_t)height * 3 * sizeof(float));
        if (caustic)
            memcpy(out->caustic, caustic, (size_t)width * (size_t)height * 3 * sizeof(float));
        st = lm_render_surface_index(sc->scene, &sc->surfaces, view, width, height, out->surface_at, err);
    }
    if (st == LM_OK)
        st = reference_pixels(sc, view, ref, out, err);
    if (st == LM_OK)
        st = compare(sc, out, err);
    if (st != LM_OK)
        lm_frame_check_free(out);
    return st;
}
