/* Which IIM texels wait to be regathered and show, meanwhile, the estimate of progressive refinement
 * (iim.h, glsl/iim_blend_cs.glsl mode 2), and which of those estimates must be drawn this frame.
 *
 * A texel waits while its hemisphere's estimated change is over the threshold (texel_change.h lists them
 * each frame: lm_iim_pending_add) and it is not committed. One that a surface's refresh gathered leaves
 * the list, and shows its own value again until the surface is committed: keeping its estimate till
 * then was tried, and left the Cornell box's steps after one move at 0.31 of the mean texel on average
 * instead of 0.24 (tests/test_motion_trail.c). An estimate reads only the texel's chart, so it changes
 * only while a texel of its surface is committed or still blending in: those are drawn again (with the
 * texels that began or stopped waiting), and the rest keep what the display holds. The cost follows the
 * activity, not the atlas.
 *
 * Layout: per texel two state bytes; the waiting texels as a list (texel, cell, surface); per frame the
 * flag changes for the GPU (cell + 1: now waiting, -(cell + 1): no longer) and the cells to draw.
 * Memory: 2 + 12 bytes a texel, and 8 for the two frame lists at most.
 * Cost: O(waiting texels) a frame. Deterministic; not thread-safe. */
#ifndef LM_IIM_PENDING_H
#define LM_IIM_PENDING_H

#include <stdint.h>

#include "../../charts/charts.h"
#include "../../core/error.h"

typedef struct {
    uint8_t *state;       /* per texel: 0 not waiting; WAITING, NEW (began this frame), COMMITTED (leaves) */
    uint8_t *seen;        /* per texel: listed by lm_iim_pending_add this frame (2: and its estimate changed) */
    uint32_t *texel, count; /* the waiting texels */
    int32_t *cell;        /* their atlas cells */
    int *surface;         /* their surfaces */
    int32_t *ops;         /* this frame's flag changes (header) */
    uint32_t op_count;
    int32_t *redraw;      /* this frame's cells whose estimate is drawn */
    uint32_t redraw_count;
} lm_iim_pending;

lm_status lm_iim_pending_init(lm_iim_pending *p, uint32_t texel_count, lm_error *err);
void lm_iim_pending_free(lm_iim_pending *p);

/* The texels that wait this frame (every one: those not listed stop); touched[surface] is set for each
 * that began to. */
void lm_iim_pending_add(lm_iim_pending *p, const lm_atlas *a, const uint32_t *texels, uint32_t n, uint8_t *touched);
/* Texel t, listed as waiting this frame, shows an estimate of its own that changed (iim.h, lm_iim_set_sight):
 * it is drawn again and its surface's version moves. */
void lm_iim_pending_redraw(lm_iim_pending *p, uint32_t t);
/* Texel t is committed on its own this frame: it stops waiting at lm_iim_pending_frame. */
void lm_iim_pending_committed(lm_iim_pending *p, uint32_t t);
/* The frame's lists: the texels committed (on their own, or with their surface: commit[s]) or no longer
 * listed stop waiting (their flag cleared; those not committed drawn as themselves), those that began are
 * flagged and drawn, and those of surfaces with active[s] set (a texel committed or blending) are drawn
 * again; touched[s] is set to 1, where it was 0, for a surface with a texel drawn back as itself. */
void lm_iim_pending_frame(lm_iim_pending *p, const uint8_t *commit, const uint8_t *active, uint8_t *touched);

#endif
