/* The viewer's views of the lighting (view_maps.h). */
#include "view_maps.h"

#include "view_edit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *lm_view_map_name(int map)
{
    static const char *const names[LM_VIEW_MAP_COUNT] = {"picture", "IIM", "AIM", "error", "caustics", "atlas"};
    return map >= 0 && map < LM_VIEW_MAP_COUNT ? names[map] : "?";
}

void lm_view_map_texels(const lmgi_scene *sc, const lmgi_camera *cam, int w, int h, int *texel)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float org[3], dir[3], uv[6];
            lm_view_ray(cam, x + 0.5, y + 0.5, w, h, org, dir); /* through the pixel's centre */
            lmgi_hit hit;
            lmgi_intersect(sc, org, dir, INFINITY, &hit);
            int *out = &texel[(size_t)y * (size_t)w + (size_t)x];
            *out = -1;
            if (!hit.hit || hit.surface < 0 || !lmgi_triangle_lightmap_uv(sc, hit.triangle, uv))
                continue;
            float b0 = 1.0f - hit.uv[0] - hit.uv[1];
            int tx = (int)floorf((b0 * uv[0] + hit.uv[0] * uv[2] + hit.uv[1] * uv[4]) * (float)in.atlas_width);
            int ty = (int)floorf((b0 * uv[1] + hit.uv[0] * uv[3] + hit.uv[1] * uv[5]) * (float)in.atlas_height);
            if (tx >= 0 && ty >= 0 && tx < in.atlas_width && ty < in.atlas_height)
                *out = ty * in.atlas_width + tx;
        }
}

void lm_view_maps_edited(lm_view_maps *m) { m->cast = 0; }

/* The buffers for the scene's atlas (made again for a scene loaded again); 0: no memory. */
static int ensure_atlas(lm_view_maps *m, const lmgi_scene *sc)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = (size_t)in.atlas_width * (size_t)in.atlas_height;
    int surfaces = lmgi_surface_count(sc);
    if (n != m->n || surfaces != m->surfaces || !m->atlas) {
        free(m->atlas);
        free(m->error);
        free(m->surface);
        free(m->version);
        m->atlas = malloc(4 * n * sizeof *m->atlas);
        m->error = malloc(4 * n * sizeof *m->error);
        m->surface = malloc(n * sizeof *m->surface);
        m->version = calloc((size_t)(surfaces > 0 ? surfaces : 1), sizeof *m->version);
        m->n = n, m->surfaces = surfaces, m->cast = 0;
        if (m->surface) {
            for (size_t i = 0; i < n; i++)
                m->surface[i] = -1;
            for (uint32_t i = 0; i < lmgi_texel_count(sc); i++) {
                lmgi_texel t;
                lmgi_get_texel(sc, i, &t);
                m->surface[(size_t)t.y * (size_t)in.atlas_width + (size_t)t.x] = t.surface;
            }
        }
    }
    return m->atlas && m->error && m->surface && m->version;
}

/* The buffers for a w x h picture and the scene's atlas; 0: no memory. */
static int ensure(lm_view_maps *m, const lmgi_scene *sc, int w, int h)
{
    if (m->w != w || m->h != h || !m->texel) {
        free(m->texel);
        m->texel = malloc((size_t)w * (size_t)h * sizeof *m->texel);
        m->w = w, m->h = h, m->cast = 0;
    }
    return ensure_atlas(m, sc) && m->texel;
}

/* Whether error texel i (m->error, read back) is a valid texel still to move. */
static int still_to_move(const lm_view_maps *m, size_t i)
{
    return m->error[4 * i + 3] > 0.0f && m->error[4 * i] > LM_VIEW_STALE;
}

int lm_view_maps_staleness(lm_view_maps *m, lmgi_updater *u, const lmgi_scene *sc, uint32_t *texels, float *largest,
                           lmgi_error *err)
{
    *texels = 0;
    *largest = 0.0f;
    if (!ensure_atlas(m, sc)) {
        snprintf(err->message, sizeof err->message, "view: no memory for the error atlas");
        return 0;
    }
    if (lmgi_get_lightmap(u, LMGI_LIGHTMAP_ERROR, m->error, 4 * m->n, err) != LMGI_OK)
        return 0;
    for (size_t i = 0; i < m->n; i++)
        if (still_to_move(m, i)) {
            ++*texels;
            *largest = fmaxf(*largest, m->error[4 * i]);
        }
    return 1;
}

/* The error view's ramp: dark blue at 0 (and up to LM_VIEW_STALE), through green and yellow, red at
 * LM_VIEW_ERROR_FULL and above; a texel still to move never looks like none. */
static void ramp(float e, float *rgb)
{
    if (!(e > LM_VIEW_STALE)) /* nothing (left) to move: rounding remainders show as none */
        e = 0.0f;
    float x = fminf(fmaxf(e / LM_VIEW_ERROR_FULL, 0.0f), 1.0f);
    rgb[0] = x < 0.5f ? 0.0f : 2.0f * x - 1.0f;
    rgb[1] = x < 0.5f ? 2.0f * x : 2.0f - 2.0f * x;
    rgb[2] = x < 0.5f ? 0.08f * (1.0f - 2.0f * x) : 0.0f;
    if (e > LM_VIEW_STALE && x < 0.25f) /* any texel still to move shows */
        rgb[0] = rgb[1] = fmaxf(rgb[1], 0.15f);
}

/* The atlas fitted into the picture (nearest texel), the IIM's irradiance made grey and scaled so its
 * mean sits at a quarter, texels still to move red, those of surfaces the last update changed yellow. */
static void draw_atlas(lm_view_maps *m, lmgi_updater *u, const lmgi_scene *sc, int w, int h, float *rgb)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    double sum = 0.0;
    size_t valid = 0;
    for (size_t i = 0; i < m->n; i++)
        if (m->atlas[4 * i + 3] > 0.0f)
            sum += m->atlas[4 * i] + m->atlas[4 * i + 1] + m->atlas[4 * i + 2], valid++;
    float scale = sum > 0.0 ? (float)(0.25 * 3.0 * (double)valid / sum) : 1.0f;
    unsigned char *changed = calloc((size_t)(m->surfaces > 0 ? m->surfaces : 1), 1);
    for (int s = 0; changed && s < m->surfaces; s++) {
        uint32_t now = lmgi_surface_version(u, s);
        changed[s] = now != m->version[s];
        m->version[s] = now;
    }
    float fit = fminf((float)w / (float)in.atlas_width, (float)h / (float)in.atlas_height);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float *px = rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
            int ax = (int)((float)x / fit), ay = in.atlas_height - 1 - (int)((float)y / fit); /* v = 0 at the bottom */
            px[0] = px[1] = px[2] = 0.0f;
            if (ax >= in.atlas_width || ay < 0)
                continue;
            size_t i = (size_t)ay * (size_t)in.atlas_width + (size_t)ax;
            const float *t = m->atlas + 4 * i;
            float grey = fminf(1.0f, scale * (t[0] + t[1] + t[2]) / 3.0f);
            px[0] = px[1] = px[2] = t[3] > 0.0f ? grey : 0.03f;
            int s = m->surface[i];
            if (still_to_move(m, i))
                px[0] = fmaxf(px[0], 0.9f), px[1] *= 0.3f, px[2] *= 0.3f;
            else if (changed && s >= 0 && changed[s])
                px[0] = fmaxf(px[0], 0.9f), px[1] = fmaxf(px[1], 0.8f), px[2] *= 0.3f;
        }
    free(changed);
}

int lm_view_maps_draw(lm_view_maps *m, lmgi_updater *u, const lmgi_scene *sc, int map, const lmgi_camera *cam, int w,
                      int h, float *rgb, lmgi_error *err)
{
    if (!ensure(m, sc, w, h)) {
        snprintf(err->message, sizeof err->message, "view: no memory for the %s view", lm_view_map_name(map));
        return 0;
    }
    size_t pixels = (size_t)w * (size_t)h;
    if (map == LM_VIEW_CAUSTICS)
        return lmgi_get_caustics(u, rgb, 3 * pixels, NULL, NULL, err) == LMGI_OK;
    if (map == LM_VIEW_ATLAS) {
        uint32_t texels;
        float largest;
        if (lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, m->atlas, 4 * m->n, err) != LMGI_OK ||
            !lm_view_maps_staleness(m, u, sc, &texels, &largest, err))
            return 0;
        draw_atlas(m, u, sc, w, h, rgb);
        return 1;
    }
    lmgi_lightmap kind = map == LM_VIEW_AIM ? LMGI_LIGHTMAP_AIM : map == LM_VIEW_ERROR ? LMGI_LIGHTMAP_ERROR : LMGI_LIGHTMAP_IIM;
    if (lmgi_get_lightmap(u, kind, m->atlas, 4 * m->n, err) != LMGI_OK)
        return 0;
    if (!m->cast || memcmp(&m->cam, cam, sizeof *cam)) {
        lm_view_map_texels(sc, cam, w, h, m->texel);
        m->cam = *cam;
        m->cast = 1;
    }
    for (size_t p = 0; p < pixels; p++) {
        float *px = rgb + 3 * p;
        int i = m->texel[p];
        if (i < 0) {
            px[0] = px[1] = px[2] = 0.0f;
        } else if (map == LM_VIEW_ERROR) {
            ramp(m->atlas[4 * (size_t)i], px);
        } else {
            memcpy(px, m->atlas + 4 * (size_t)i, 3 * sizeof *px);
        }
    }
    return 1;
}

void lm_view_maps_free(lm_view_maps *m)
{
    free(m->texel);
    free(m->atlas);
    free(m->error);
    free(m->surface);
    free(m->version);
    memset(m, 0, sizeof *m);
}
