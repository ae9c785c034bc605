#include "iim_schedule.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static lm_status group_texels(lm_iim_sched *s, const lm_atlas *a, lm_error *err)
{
    int S = s->surface_count;
    s->surf_first = calloc((size_t)S + 1, sizeof *s->surf_first);
    s->surf_texels = malloc(sizeof *s->surf_texels * (a->texel_count ? a->texel_count : 1));
    if (!s->surf_first || !s->surf_texels)
        return lm_fail(err, LM_ERR_NOMEM, "IIM: no memory for texel lists");
    for (uint32_t i = 0; i < a->texel_count; i++)
        s->surf_first[a->texels[i].surface + 1]++;
    for (int k = 0; k < S; k++)
        s->surf_first[k + 1] += s->surf_first[k];
    uint32_t *fill = s->cursor; /* borrowed as a write position, zeroed after */
    for (uint32_t i = 0; i < a->texel_count; i++) {
        int k = a->texels[i].surface;
        s->surf_texels[s->surf_first[k] + fill[k]++] = i;
    }
    memset(s->cursor, 0, sizeof *s->cursor * (size_t)(S ? S : 1));
    return LM_OK;
}

lm_status lm_iim_sched_init(lm_iim_sched *s, const lm_atlas *a, int texels_per_frame, double delta_threshold,
                            lm_error *err)
{
    memset(s, 0, sizeof *s);
    s->texels_per_frame = texels_per_frame;
    s->delta_threshold = delta_threshold;
    s->surface_count = a->surface_count;
    size_t S = (size_t)(a->surface_count ? a->surface_count : 1);
    s->cursor = calloc(S, sizeof *s->cursor);
    s->last_done = malloc(S * sizeof *s->last_done);
    s->commit = calloc(S, 1);
    s->off = calloc(S, 1);
    s->again = calloc(S, 1);
    s->started = calloc(S, sizeof *s->started);
    s->texel_frame = malloc(sizeof *s->texel_frame * (a->texel_count ? a->texel_count : 1));
    lm_status st = s->cursor && s->last_done && s->commit && s->off && s->again && s->started && s->texel_frame
                       ? group_texels(s, a, err)
                       : lm_fail(err, LM_ERR_NOMEM, "IIM: no memory for %d surfaces", a->surface_count);
    for (size_t k = 0; st == LM_OK && k < S; k++)
        s->last_done[k] = -1;
    for (uint32_t i = 0; st == LM_OK && i < a->texel_count; i++)
        s->texel_frame[i] = INT_MIN;
    if (st != LM_OK)
        lm_iim_sched_free(s);
    return st;
}

void lm_iim_sched_free(lm_iim_sched *s)
{
    free(s->surf_first);
    free(s->surf_texels);
    free(s->cursor);
    free(s->last_done);
    free(s->commit);
    free(s->off);
    free(s->again);
    free(s->started);
    free(s->texel_frame);
    memset(s, 0, sizeof *s);
}

/* Order: larger delta_i first, then older (never refreshed counts as oldest), then lower id. */
static int before(const lm_iim_sched *s, const lm_photon_store *ps, int a, int b)
{
    double da = ps->surfaces[a].delta_i, db = ps->surfaces[b].delta_i;
    if (da != db)
        return da > db;
    long age_a = s->last_done[a] < 0 ? LONG_MAX : (long)s->frame - s->last_done[a];
    long age_b = s->last_done[b] < 0 ? LONG_MAX : (long)s->frame - s->last_done[b];
    if (age_a != age_b)
        return age_a > age_b;
    return a < b;
}

static void complete_surface(lm_iim_sched *s, lm_photon_store *ps, int k)
{
    s->cursor[k] = 0;
    s->last_done[k] = s->frame;
    s->commit[k] = 1;
    lm_photon_store_reset_delta_i(ps, k);
    if (s->again[k]) /* what it sees changed while it was under way */
        lm_iim_sched_raise(s, ps, k);
    s->again[k] = 0;
}

void lm_iim_sched_raise(const lm_iim_sched *s, lm_photon_store *ps, int k)
{
    /* a fixed 1e-30 vanishes beside 1; nextafter's denormal beside 0 reads as 0 on the threads that
     * trace, which flush denormals */
    double th = s->delta_threshold;
    if (!(ps->surfaces[k].delta_i > th))
        ps->surfaces[k].delta_i = th + fmax(1e-30, 1e-9 * th);
}

/* Hands out texels of surface k from its cursor, less those gathered since its refresh began (ahead of
 * it: lm_iim_sched_gathered); completes it when its last texel is out. */
static uint32_t take_texels(lm_iim_sched *s, lm_photon_store *ps, int k, uint32_t *out, uint32_t room)
{
    uint32_t first = s->surf_first[k], count = s->surf_first[k + 1] - first, n = 0;
    if (s->cursor[k] == 0)
        s->started[k] = s->frame;
    while (s->cursor[k] < count && n < room) {
        uint32_t t = s->surf_texels[first + s->cursor[k]++];
        if (s->texel_frame[t] >= s->started[k]) /* gathered ahead since the refresh began (never: INT_MIN) */
            continue;
        s->texel_frame[t] = s->frame;
        out[n++] = t;
    }
    if (s->cursor[k] == count)
        complete_surface(s, ps, k);
    return n;
}

void lm_iim_sched_gathered(lm_iim_sched *s, const uint32_t *texels, uint32_t n, int gathered)
{
    for (uint32_t j = 0; j < n; j++)
        s->texel_frame[texels[j]] = gathered ? s->frame : INT_MIN;
}

uint32_t lm_iim_sched_pick(lm_iim_sched *s, lm_photon_store *ps, uint32_t *out)
{
    return lm_iim_sched_pick_up_to(s, ps, s->texels_per_frame > 0 ? (uint32_t)s->texels_per_frame : 0, out);
}

uint32_t lm_iim_sched_pick_up_to(lm_iim_sched *s, lm_photon_store *ps, uint32_t budget, uint32_t *out)
{
    int *cand = malloc(sizeof(int) * (size_t)(s->surface_count ? s->surface_count : 1));
    if (!cand)
        return 0;
    int nc = 0;
    for (int k = 0; k < s->surface_count; k++) {
        if (s->off[k] || (s->cursor[k] == 0 && !(ps->surfaces[k].delta_i > s->delta_threshold)))
            continue;
        int i = nc++; /* insertion sort: surface counts are small */
        while (i > 0 && before(s, ps, k, cand[i - 1]))
            cand[i] = cand[i - 1], i--;
        cand[i] = k;
    }
    uint32_t n = 0;
    for (int i = 0; i < nc && n < budget; i++)
        n += take_texels(s, ps, cand[i], out + n, budget - n);
    free(cand);
    return n;
}

uint32_t lm_iim_sched_pick_all(lm_iim_sched *s, lm_photon_store *ps, uint32_t *out)
{
    uint32_t n = 0;
    for (int k = 0; k < s->surface_count; k++) {
        s->cursor[k] = 0;
        if (!s->off[k])
            n += take_texels(s, ps, k, out + n, UINT32_MAX);
    }
    return n;
}

void lm_iim_sched_restart(lm_iim_sched *s, lm_photon_store *ps)
{
    for (int k = 0; k < s->surface_count; k++)
        if (s->cursor[k] > 0) {
            s->cursor[k] = 0;
            s->again[k] = 0;
            ps->surfaces[k].delta_i = 1e30;
        }
}

void lm_iim_sched_end_frame(lm_iim_sched *s) { s->frame++; }

void lm_iim_sched_set_off(lm_iim_sched *s, lm_photon_store *ps, int k, int off)
{
    if (!off && s->off[k])
        ps->surfaces[k].delta_i = 1e30;
    s->off[k] = (uint8_t)(off != 0);
    if (off)
        s->cursor[k] = 0, s->again[k] = 0;
}
