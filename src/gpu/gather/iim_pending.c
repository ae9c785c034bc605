/* The texels that wait for their gather, and the frame's estimate work (iim_pending.h). */
#include "iim_pending.h"

#include <stdlib.h>
#include <string.h>

enum { WAITING = 1, NEW = 2, COMMITTED = 3 };

lm_status lm_iim_pending_init(lm_iim_pending *p, uint32_t texel_count, lm_error *err)
{
    memset(p, 0, sizeof *p);
    size_t T = texel_count ? texel_count : 1;
    p->state = calloc(T, 1);
    p->seen = calloc(T, 1);
    p->texel = malloc(sizeof *p->texel * T);
    p->cell = malloc(sizeof *p->cell * T);
    p->surface = malloc(sizeof *p->surface * T);
    p->ops = malloc(sizeof *p->ops * T);
    p->redraw = malloc(sizeof *p->redraw * T);
    if (p->state && p->seen && p->texel && p->cell && p->surface && p->ops && p->redraw)
        return LM_OK;
    lm_iim_pending_free(p);
    return lm_fail(err, LM_ERR_NOMEM, "IIM: no memory for the waiting texels of %u", texel_count);
}

void lm_iim_pending_free(lm_iim_pending *p)
{
    free(p->state);
    free(p->seen);
    free(p->texel);
    free(p->cell);
    free(p->surface);
    free(p->ops);
    free(p->redraw);
    memset(p, 0, sizeof *p);
}

void lm_iim_pending_add(lm_iim_pending *p, const lm_atlas *a, const uint32_t *texels, uint32_t n, uint8_t *touched)
{
    for (uint32_t j = 0; j < n; j++) {
        uint32_t t = texels[j];
        p->seen[t] = 1;
        if (p->state[t])
            continue;
        const lm_texel *x = &a->texels[t];
        p->state[t] = NEW;
        p->texel[p->count] = t;
        p->cell[p->count] = (int32_t)(x->y * a->width + x->x);
        p->surface[p->count++] = x->surface;
        touched[x->surface] = 1;
    }
}

void lm_iim_pending_redraw(lm_iim_pending *p, uint32_t t)
{
    if (p->seen[t])
        p->seen[t] = 2;
}

void lm_iim_pending_committed(lm_iim_pending *p, uint32_t t)
{
    if (p->state[t])
        p->state[t] = COMMITTED;
}

void lm_iim_pending_frame(lm_iim_pending *p, const uint8_t *commit, const uint8_t *active, uint8_t *touched)
{
    uint32_t kept = 0;
    p->op_count = p->redraw_count = 0;
    for (uint32_t j = 0; j < p->count; j++) {
        uint32_t t = p->texel[j];
        int32_t c = p->cell[j];
        int s = p->surface[j];
        int committed = p->state[t] == COMMITTED || commit[s], listed = p->seen[t], fresh = listed == 2;
        p->seen[t] = 0;
        if (committed || !listed) {
            if (p->state[t] != NEW) /* one that began and ended in this frame was never flagged */
                p->ops[p->op_count++] = -(c + 1);
            if (!committed) { /* back to its own value; a committed one is drawn by its commit */
                p->redraw[p->redraw_count++] = c;
                touched[s] = touched[s] ? touched[s] : 1;
            }
            p->state[t] = 0;
            continue;
        }
        if (p->state[t] == NEW)
            p->ops[p->op_count++] = c + 1;
        if (p->state[t] == NEW || active[s] || fresh)
            p->redraw[p->redraw_count++] = c;
        if (fresh) /* its own estimate changed (lm_iim_pending_redraw) */
            touched[s] = touched[s] ? touched[s] : 1;
        p->state[t] = WAITING;
        p->texel[kept] = t, p->cell[kept] = c, p->surface[kept++] = s;
    }
    p->count = kept;
}
