/* Indirect illumination maps (IIMs): double-buffered textures and blending (Larsen & Christensen
 * section 4; DESIGN.md step 4). Which texels are regathered and when a surface is complete is the
 * scheduler's (photonmap/iim_schedule.h, `sched` below), which alone writes the photon store's delta_i;
 * this module only reads its commit flags (and clears them) and its frame counter.
 *
 * Double buffering (GPU, no read-back): the gather writes into `fresh`. Committing a surface copies,
 * for its texels, the currently displayed value into `old` and `fresh` into `new`; from then on
 * display = mix(old, new, t) with t = min(1, (frames since the commit + 1) / blend_frames), each texel
 * keeping the frame of its own last commit (a texel may be committed alone: lm_iim_commit_texels). A texel
 * thus never leaves [old, new], and a surface committed again mid-blend starts from what was on screen (no
 * popping). The commit's own frame shows a first 1 / blend_frames of the step, so that a texel committed
 * again every frame (gathered every update beside a moving node) follows its gathers as a running mean over
 * about blend_frames updates; with none shown there it would keep its first value for as long as the
 * commits go on. The alpha channel (back-face fraction) blends alike, but a texel that turns valid or
 * invalid (a moving object's foot) shows its new value at once: a blend with the dark value gathered from inside
 * geometry would show as a dark square.
 *
 * Progressive refinement (issue 32, item 3): texels regathered ahead of their surface come one by one, so a
 * changed region used to show as hard-edged squares, each gathered texel among stale neighbours. The
 * texels still waiting (lm_iim_set_pending: their hemisphere's estimated change passed the threshold;
 * iim_pending.h) show instead their own value plus the changes of the texels of their chart within
 * `spread` texels committed after them, weighted by distance (glsl/iim_blend_cs.glsl, mode 2): a coarse
 * estimate from the first gathers, refined as each texel is gathered in turn. For that each commit keeps
 * its texel's change and what the estimate added on screen, which then fades out with the blend instead
 * of popping (two more atlas-sized RGBA32F textures, 32 bytes a cell, and 8 for each cell's chart and
 * flag); an estimate costs (2 spread + 1)^2 reads, drawn again only while its surface has texels
 * committed or blending.
 *
 * A footprint texel whose chart is that texel alone (charts.h, lm_texel_turns) also has a turn: how its
 * light changes with the normal across the piece it stands for (lm_footprint_turn), three more atlas-sized
 * RGBA16F maps (24 bytes a cell) made only where the atlas has such texels; the frame scales the displayed value by it at each pixel (docs/charts.md,
 * "Turning with the normal").
 *
 * Invalid texels (back-face fraction above the limit: the texel sees the inside of geometry) are
 * filled on the CPU copy used for output (lm_iim_fill_invalid), then gutters are dilated. */
#ifndef LM_IIM_H
#define LM_IIM_H

#include <stdint.h>

#include "../../charts/charts.h"
#include "../../core/error.h"
#include "../../photonmap/iim_schedule.h"
#include "iim_pending.h"

#define LM_IIM_DEFAULT_TEXELS_PER_FRAME 20 /* the paper's */
/* Texels either side whose estimates of their own (lm_iim_set_sight) a waiting texel's averages, each weighed
 * by a tent: one texel's few rays mottle, and its neighbours see about the same change. */
#define LM_IIM_SIGHT_SPREAD 2
/* And by exp(-(f / LM_IIM_SIGHT_APART)^2), f the frames between the two texels' last commits: each change is
 * since its own texel's gather, so neighbours gathered at other times saw other parts of a moving shadow's
 * change. Over 120 updates of the animated box (seeds 0 and 1), a floor block under the cube's path stayed
 * 10% off for 15 updates averaged with every neighbour alike, 9 with this weight (1, 2, 4 and 8 alike). */
#define LM_IIM_SIGHT_APART 4
/* Frames at most a texel that showed an estimate of its own blends in its gather over: the estimate was
 * already the change, and its gather only refines it. Over blend_frames the moving cube's own faces
 * trailed their light by 5 updates (10% off for 60 updates in the animated Cornell box), over 2 for 33. */
#define LM_IIM_SIGHT_BLEND 2
/* A waiting texel's estimate brought up to date by less than this share of its light is not drawn again:
 * about one step of an 8-bit display. Every small change redrawn rewrote 3.5 times as many surfaces as
 * before the estimates after the shared room's glass was recoloured (lmgi bench --edits). */
#define LM_IIM_SIGHT_KEEP (1.0f / 256.0f)
/* Over the animated box's whole loop (240 updates, photon seeds 0 to 4), the near rays' estimates averaged
 * with their neighbours' held a floor block over 10% for 12 updates at seed 2 as the cube's shadow fell on
 * it: the block showed about 10% above a fresh bake, its edge texels' neighbours outside the shadow diluting
 * its change. Alone, 6 (lm_iim_set_sight). The sight cell's alpha that says so (the blend shader's). */
#define LM_IIM_SIGHT_ALONE 2.0f

typedef struct {
    int texels_per_frame;  /* gather budget per frame (default LM_IIM_DEFAULT_TEXELS_PER_FRAME) */
    int blend_frames;      /* frames an updated surface takes to blend from old to new (default 8; 0 = pop) */
    double delta_threshold; /* a surface is refreshed when its delta_i exceeds this (default 0) */
    float texel_change;    /* a texel is regathered ahead of its surface when its hemisphere's estimated
                            * change exceeds this fraction of the mean irradiance (photonmap/texel_change.h;
                            * default 1/32; a negative value: never) */
    float backface_limit;  /* a texel whose back-face fraction (alpha) is above this is invalid, as the
                            * gather's: one turning valid or invalid shows its new value at once, never a
                            * blend with what it saw from inside geometry (default 0.1) */
    int spread;            /* texels a pending texel borrows changes from (header; default 3, 0: none,
                            * each texel shows its old value until gathered) */
    int estimate_rays;     /* rays a pending texel's estimate of its own casts (update/ray_estimate.h; default
                            * 36, 0: none, its neighbours' loans alone); read by the lightmap path */
} lm_iim_settings;

typedef struct {
    lm_iim_settings set;   /* blend_frames used here; texels_per_frame and delta_threshold are sched's */
    lm_iim_sched sched;    /* which texels to regather; its frame counter is the blend's clock */
    int width, height;
    int *blend_start;      /* per surface: frame of its last commit (very negative: fully blended) */
    int *texel_start;      /* per surface: frame some of its texels were last committed on their own */
    uint32_t *list, list_count; /* atlas cells to commit on their own at the next blend */
    lm_iim_pending pending; /* the texels that wait, shown with the estimate (iim_pending.h) */
    uint8_t *version_touch; /* per surface: a texel of it began or stopped waiting (its version moves) */
    uint8_t *active;       /* scratch per surface: a texel of it committed or blending this frame */
    uint32_t *version;     /* per surface: blends that changed its displayed texels (a commit, or a blend
                            * still under way) */
    float *sight;          /* per atlas cell, 4: a waiting texel's own estimate (lm_iim_set_sight), rgb its change,
                            * a 1 while it holds one, -1 in the frame its texel is gathered (its commit carries
                            * what it showed: no rebase), 0 none */
    uint32_t *spent, spent_count; /* the cells at -1, cleared after the blend */
    int sight_dirty[4];    /* the rectangle of cells whose sight changed since its upload: x0, y0, x1, y1
                            * (x0 > x1: none), uploaded alone, so that an update's few hundred estimates cost
                            * their rows, not a page's */
    int settled;           /* display already holds every surface's new map: lm_iim_blend has nothing to do */
    /* GPU side (0 when created without GL) */
    unsigned fresh_tex, old_tex, new_tex, display_tex, delta_tex, carry_tex, sight_tex;
    unsigned turn_tex[3];  /* the footprint texels' turns (hemicube.h, lm_gather_set_turn), RGBA16F, written
                            * by the gather as it goes, not blended: relative, so the value they turn is
                            * the displayed one; all 0 where no texel turns */
    unsigned scale_prog, factor_buf; /* lm_iim_scale's program and factors, made at its first call */
    unsigned blend_prog, surface_buf, params_buf, start_buf, list_buf, chart_buf, redraw_buf, flag_buf, ops_buf;
} lm_iim;

void lm_iim_settings_default(lm_iim_settings *s);
/* with_gl: also make the four atlas-sized RGBA32F textures and the blend program (current context). */
lm_status lm_iim_init(lm_iim *iim, const lm_atlas *a, const lm_iim_settings *set, int with_gl, lm_error *err);
void lm_iim_free(lm_iim *iim);

/* The texels (lm_atlas.texels indices) are committed on their own at the next blend, whatever their
 * surface does: texels regathered ahead of their surface (photonmap/texel_change.h) show at once, each
 * blending from what was shown over blend_frames from then. */
void lm_iim_commit_texels(lm_iim *iim, const lm_atlas *a, const uint32_t *texels, uint32_t n);
/* The texels (lm_atlas.texels indices) that wait to be regathered this frame (iim_pending.h): each shows
 * the estimate from its neighbours committed since it was (header). */
void lm_iim_set_pending(lm_iim *iim, const lm_atlas *a, const uint32_t *texels, uint32_t n);
/* Waiting texels[0 .. n) show, until their gather, their own value plus change[3 texels[j] + c] (per texel
 * index; update/ray_estimate.h) instead of their neighbours' loans: averaged with their waiting neighbours'
 * (LM_IIM_SIGHT_SPREAD), or alone where rays[texels[j]] >= many (rays: per texel index, NULL: none), whose
 * rays are many enough not to mottle (ray_estimate.h's near rays). One that shows a change already within
 * LM_IIM_SIGHT_KEEP of light[3 texels[j] + c] (its light, summed over the channels) of the new one, the same
 * way, keeps it, and its surface is not rewritten for it. */
void lm_iim_set_sight(lm_iim *iim, const lm_atlas *a, const uint32_t *texels, const float *change, const float *light,
                      const uint8_t *rays, uint8_t many, uint32_t n);
/* Texels[0 .. n) are gathered this frame: what their estimate showed is carried by their commit, and
 * they hold none from the next frame on. */
void lm_iim_sight_gathered(lm_iim *iim, const lm_atlas *a, const uint32_t *texels, uint32_t n);
/* Ends the frame on the GPU: commits the surfaces the scheduler completed (clearing their flags),
 * writes display = mix(old, new, t), then advances the scheduler's frame counter. instant: committed surfaces show new at once (after the first gather). */
lm_status lm_iim_blend(lm_iim *iim, int instant, lm_error *err);

/* Every texel i of the atlas, in every map (fresh, old, new, displayed, its change and what its estimate
 * carries), multiplied by factor[3 i + c] per channel (a->texel_count x 3 floats; alpha stays), and
 * add[3 i + c] added to its values (fresh, old, new, displayed; add may be NULL: none): a light's edit
 * shows at once (update/light_scale.h). Each surface with a texel changed moves its version and has
 * scaled[k] set (surface_count bytes, written before anything can fail). Without GL only the versions
 * move. */
lm_status lm_iim_scale(lm_iim *iim, const lm_atlas *a, const float *factor, const float *add, uint8_t *scaled,
                       lm_error *err);

/* Every texel's colour in every map (fresh, old, new, displayed, the changes) set to 0, as lm_iim_scale by
 * 0 does, its alpha kept: a scene that lost its last light shows no indirect light at once, not the last
 * gather's, and a texel that sees the inside of geometry stays invalid (filled from its neighbours on
 * output) until its regather, not a black texel among the first guess's when a light comes back (once,
 * the back-face fractions cleared too, a black block under the Cornell box's sphere). Errors: out of
 * memory, GL. */
lm_status lm_iim_clear(lm_iim *iim, const lm_atlas *a, lm_error *err);

/* CPU: texels (rgba, atlas-sized, a = back-face fraction) with a > limit take the mean of valid
 * 4-neighbours of the same surface, repeated until none changes; then gutters are dilated. Returns
 * how many invalid texels could not be filled (no valid texel on their surface reachable). */
uint32_t lm_iim_fill_invalid(const lm_atlas *a, float *rgba, float limit);
/* The same over the atlas window win = {x, y, w, h}, rgba holding the window alone: exact (as the whole
 * atlas's) for every surface all of whose texels lie in the window, and, after the dilation, for the
 * texels at least lm_atlas_dilate_reach from its edges whose neighbourhood is such surfaces'. */
uint32_t lm_iim_fill_invalid_window(const lm_atlas *a, float *rgba, float limit, const int win[4]);

#endif
