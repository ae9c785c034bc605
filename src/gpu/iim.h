/* Indirect illumination maps (IIMs): scheduling of texel refreshes and double-buffered blending
 * (Larsen & Christensen section 4; DESIGN.md step 4).
 *
 * Scheduling: each frame at most texels_per_frame texels (the paper's 20) are handed to the gather.
 * Surfaces are taken in order of their delta_i (photon store: energy of hits added or removed since
 * the surface's IIM was refreshed, first hits of punctual lights left out), largest first, then by
 * age (frames since the surface's last completed refresh, oldest first), then by id. Only surfaces
 * with delta_i > delta_threshold, or with a refresh under way, are candidates: nothing changed means no
 * IIM work. A surface's texels are refreshed in atlas order from a cursor that survives across frames;
 * when the last one is handed out the surface's refresh is complete: its delta_i is reset
 * (lm_photon_store_reset_delta_i) and it is committed at the next lm_iim_blend.
 *
 * Double buffering (GPU, no read-back): the gather writes into `fresh`. Committing a surface copies,
 * for its texels, the currently displayed value into `old` and `fresh` into `new`; from then on
 * display = mix(old, new, t) with t = min(1, frames since the commit / blend_frames). A texel thus
 * never leaves [old, new], and a surface committed again mid-blend starts from what was on screen (no
 * popping). The alpha channel (back-face fraction) blends alike.
 *
 * Invalid texels (back-face fraction above the limit: the texel sees the inside of geometry) are
 * filled on the CPU copy used for output (lm_iim_fill_invalid), then gutters are dilated. */
#ifndef LM_IIM_H
#define LM_IIM_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../trace/photon_store.h"

#define LM_IIM_DEFAULT_TEXELS_PER_FRAME 20 /* the paper's */

typedef struct {
    int texels_per_frame;  /* gather budget per frame (default LM_IIM_DEFAULT_TEXELS_PER_FRAME) */
    int blend_frames;      /* frames an updated surface takes to blend from old to new (default 8; 0 = pop) */
    double delta_threshold; /* a surface is refreshed when its delta_i exceeds this (default 0) */
} lm_iim_settings;

typedef struct {
    lm_iim_settings set;
    int width, height, surface_count;
    uint32_t *surf_first;  /* surface_count + 1 offsets into surf_texels */
    uint32_t *surf_texels; /* texel indices (into lm_atlas.texels) grouped by surface, atlas order */
    uint32_t *cursor;      /* per surface: next texel of a refresh under way (0: none under way) */
    int *last_done;        /* per surface: frame its last refresh completed (-1: never) */
    int *blend_start;      /* per surface: frame of its last commit (very negative: fully blended) */
    uint8_t *commit;       /* per surface: completed, to commit at the next lm_iim_blend */
    uint32_t *version;     /* per surface: blends that changed its displayed texels (a commit, or a blend
                            * still under way) */
    int frame;
    int settled;           /* display already holds every surface's new map: lm_iim_blend has nothing to do */
    /* GPU side (0 when created without GL) */
    unsigned fresh_tex, old_tex, new_tex, display_tex;
    unsigned blend_prog, surface_buf, params_buf;
} lm_iim;

void lm_iim_settings_default(lm_iim_settings *s);
/* with_gl: also make the four atlas-sized RGBA32F textures and the blend program (current context). */
lm_status lm_iim_init(lm_iim *iim, const lm_atlas *a, const lm_iim_settings *set, int with_gl, lm_error *err);
void lm_iim_free(lm_iim *iim);

/* Picks this frame's texels (at most texels_per_frame, written to out) and resets delta_i of surfaces
 * whose refresh completes. Returns how many. */
uint32_t lm_iim_schedule(lm_iim *iim, lm_photon_store *ps, uint32_t *out);
/* Every texel of every surface, for the first full gather; marks every surface completed. Returns the
 * count (out must hold a->texel_count). */
uint32_t lm_iim_schedule_all(lm_iim *iim, lm_photon_store *ps, uint32_t *out);
/* Blend weight of a surface this frame. */
float lm_iim_blend_weight(const lm_iim *iim, int surface);
/* Ends the frame on the GPU: commits completed surfaces, writes display = mix(old, new, t), then
 * advances the frame counter. instant: committed surfaces show new at once (after the first gather). */
lm_status lm_iim_blend(lm_iim *iim, int instant, lm_error *err);

/* CPU: texels (rgba, atlas-sized, a = back-face fraction) with a > limit take the mean of valid
 * 4-neighbours of the same surface, repeated until none changes; then gutters are dilated. Returns
 * how many invalid texels could not be filled (no valid texel on their surface reachable). */
uint32_t lm_iim_fill_invalid(const lm_atlas *a, float *rgba, float limit);

#endif
