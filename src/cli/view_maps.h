/* The viewer's views of the lighting besides the picture (lmgi view, docs/viewer.md, "Views"): the IIM
 * (the irradiance the gather made), the AIM (the photon estimate it gathered from) and the error
 * estimate (what is still to come), each seen on the scene from the window's camera; the caustics alone;
 * and the atlas itself, flat, with the texels still to move and the surfaces the last update changed
 * highlighted.
 *
 * Built on the public API alone: a ray a pixel (lmgi_intersect) gives the triangle and its barycentrics,
 * lmgi_triangle_lightmap_uv the atlas texel under them, lmgi_get_lightmap the values. The rays are cast
 * again only when the camera, the picture's size or the scene (an edit: lm_view_maps_edited) changed:
 * about 0.1 s for 640 x 480 on one core of this project's machine; the map is read back every frame.
 * The error atlas read here also tells the panel how stale the lighting is (lm_view_maps_staleness).
 * Memory: an int a pixel, 32 bytes and an int an atlas texel, 4 bytes a surface. Not thread-safe. */
#ifndef LM_CLI_VIEW_MAPS_H
#define LM_CLI_VIEW_MAPS_H

#include <lmgi.h>
#include <stddef.h>

typedef enum {
    LM_VIEW_PICTURE = 0, /* the composited frame (lmgi_render) */
    LM_VIEW_IIM,         /* irradiance E of the lightmap as displayed */
    LM_VIEW_AIM,         /* the photon estimate's radiance */
    LM_VIEW_ERROR,       /* the error estimate, false colours: LM_VIEW_ERROR_FULL and above red */
    LM_VIEW_CAUSTICS,    /* the caustic pass's irradiance alone */
    LM_VIEW_ATLAS,       /* the IIM atlas, flat; texels still to move red, surfaces changed by the last
                          * update yellow */
    LM_VIEW_MAP_COUNT
} lm_view_map;

#define LM_VIEW_ERROR_FULL 0.1f  /* the error view's colour ramp ends (red) at 10% */
#define LM_VIEW_STALE 1e-3f      /* a texel whose error estimate is above this (0.1%) is still to move: the
                                  * blend leaves rounding-sized remainders (1e-7) it never clears */

typedef struct {
    int *texel;          /* per pixel, top row first: the atlas index (y * width + x) seen, -1: none */
    int w, h;            /* the picture the rays were cast for */
    lmgi_camera cam;     /* and their camera */
    int cast;            /* 1: texel is current for (w, h, cam) and the scene as it is */
    float *atlas;        /* the map read back, 4 floats a texel */
    float *error;        /* the error atlas read back (lm_view_maps_staleness), 4 floats a texel */
    int *surface;        /* per atlas texel: its surface, -1 where none */
    size_t n;            /* atlas texels */
    uint32_t *version;   /* per surface: lmgi_surface_version at the last frame */
    int surfaces;
} lm_view_maps;

/* "picture", "IIM", "AIM", "error", "caustics", "atlas". */
const char *lm_view_map_name(int map);
/* The atlas index of the texel each pixel of a w x h picture from cam sees (-1: nothing hit, a mirror or
 * glass, a triangle without texels), top row first; texel holds w * h ints. */
void lm_view_map_texels(const lmgi_scene *sc, const lmgi_camera *cam, int w, int h, int *texel);
/* Reads the error atlas (LMGI_LIGHTMAP_ERROR) into m->error: *texels gets the valid texels still to move
 * (above LM_VIEW_STALE), *largest the largest change still to come. 0 (both 0) with err set when the
 * read failed or memory ran out. */
int lm_view_maps_staleness(lm_view_maps *m, lmgi_updater *u, const lmgi_scene *sc, uint32_t *texels, float *largest,
                           lmgi_error *err);
/* The scene changed (a node moved): the rays are cast again at the next draw. */
void lm_view_maps_edited(lm_view_maps *m);
/* rgb (w x h x 3 linear floats, top row first) made map `map` (not LM_VIEW_PICTURE) as seen from cam; for
 * LM_VIEW_CAUSTICS, rgb must hold the last lmgi_render of u at w x h (its caustics are read back). The
 * error and atlas views are false colours in [0, 1], to be shown as they are (the clamp tone map at
 * exposure 1). 0 with err set when a read-back failed or memory ran out. */
int lm_view_maps_draw(lm_view_maps *m, lmgi_updater *u, const lmgi_scene *sc, int map, const lmgi_camera *cam, int w,
                      int h, float *rgb, lmgi_error *err);
void lm_view_maps_free(lm_view_maps *m);

#endif
