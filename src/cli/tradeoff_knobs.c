/* The knobs `lmgi tradeoff` sweeps: those the knob table (include/lmgi_knobs.h) gives sweep values
 * (full and --quick), in its LMGI_SWEEP order, and the atlas's texels and the tiled gather's radius, which
 * are not knobs of the desc. Values come from the range where each knob's cost or error moves
 * (docs/tradeoff.md says what each buys). */
#include "tradeoff_knobs.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_VALUES 6

typedef struct {
    int order;           /* the sweeps' order (the knob table's LMGI_SWEEP; 0: not swept) */
    const char *key, *label;
    const double *full;
    int n_full;
    const double *quick;
    int n_quick;
    /* a knob of the desc: its default (0: chosen per scene), place, kind, LMGI_OFF and stage */
    double def;
    size_t field;
    int kind, off;
    const char *stage;
    /* else how the value goes in: the atlas's texels, or the tiled gather's radius (plan: per scene) */
    void (*apply)(lmgi_updater_desc *d, int *texels, double v, const lm_tradeoff_plan *p);
    int when; /* 0: always; 1: the scene has caustics; 2: the tiled gather's radius is known */
} knob;

/* v: the atlas's texels as a multiple of the default (the texel size follows as 1 / sqrt(v)); 1, the
 * default, leaves the default atlas */
static void set_texels(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)d;
    if (v != 1.0)
        *t = (int)lround(v * p->default_texels);
}
/* v: the radius as a multiple of the scene's default one (x 1 left 0, the tiled gather's default) */
static void set_tiled_radius(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t;
    d->indirect = LMGI_INDIRECT_TILED;
    d->tiled.radius = v == 1.0 ? 0.0f : (float)(v * p->photon_radius);
}

/* A knob of the desc set to v: its default stays the zero desc's, so that every sweep shares that point;
 * 0 is LMGI_OFF where the knob has one (rim samples: none); the tiled gather's knobs take its path. */
static void set_knob(const knob *k, lmgi_updater_desc *d, double v)
{
    if (!strcmp(k->stage, "tiled"))
        d->indirect = LMGI_INDIRECT_TILED;
    if (v == k->def)
        return;
    char *field = (char *)d + k->field;
    if (k->kind == LMGI_KNOB_REAL)
        *(float *)field = (float)v;
    else if (k->kind == LMGI_KNOB_COUNT)
        *(uint32_t *)field = (uint32_t)v;
    else
        *(int *)field = v == 0.0 && k->off ? LMGI_OFF : (int)v;
}

/* The knob table's sweeps (include/lmgi_knobs.h), with two that are not knobs of the desc. */
#define SWEEP_ORDER(order, key, label, full, quick, when) order
#define SWEEP_KEY(order, key, label, full, quick, when) key
#define SWEEP_LABEL(order, key, label, full, quick, when) label
#define SWEEP_WHEN(order, key, label, full, quick, when) when
#define VALUES(...) {NAN, __VA_ARGS__} /* [0] a placeholder: a list may be empty */
#define SWEEP_FULL(order, key, label, full, quick, when) VALUES full
#define SWEEP_QUICK(order, key, label, full, quick, when) VALUES quick
#define COUNT(a) ((int)(sizeof a / sizeof *a) - 1)

#define SWEEP_VALUES(stage, field, kind, ctype, def, lo, hi, off, rule, flag, arg, cli_zero, choices, sweep, help)      static const double full_##stage##_##field[] = SWEEP_FULL sweep, quick_##stage##_##field[] = SWEEP_QUICK sweep;
LMGI_UPDATER_KNOBS(SWEEP_VALUES)

#define SWEEP_KNOB(stage, field, kind, ctype, def, lo, hi, off, rule, flag, arg, cli_zero, choices, sweep, help)        {SWEEP_ORDER sweep, SWEEP_KEY sweep, SWEEP_LABEL sweep, full_##stage##_##field + 1,                                 COUNT(full_##stage##_##field), quick_##stage##_##field + 1, COUNT(quick_##stage##_##field), (double)(def),         offsetof(lmgi_updater_desc, stage.field), kind, off, #stage, NULL, SWEEP_WHEN sweep},

static const double TEXELS_FULL[] = {0.25, 0.5, 1, 2, 4}, TEXELS_QUICK[] = {0.5, 1};
static const double RADIUS_VALUES[] = {0.5, 1, 2};
static const knob KNOBS[] = {
    LMGI_UPDATER_KNOBS(SWEEP_KNOB)
    {4, "texels", "atlas texels (x the default)", TEXELS_FULL, 5, TEXELS_QUICK, 2, 1, 0, 0, 0, "", set_texels, 0},
    {15, "tiled_radius", "tiled gather radius (x the default)", RADIUS_VALUES, 3, RADIUS_VALUES, 3, 0, 0, 0, 0,
     "tiled", set_tiled_radius, 2},
};
#define N_ENTRIES ((int)(sizeof KNOBS / sizeof KNOBS[0]))

/* The swept knobs in their order; their count. */
static int swept(const knob *out[N_ENTRIES])
{
    int n = 0;
    for (int k = 0; k < N_ENTRIES; k++) {
        if (!KNOBS[k].order)
            continue;
        int i = n++;
        for (; i > 0 && out[i - 1]->order > KNOBS[k].order; i--)
            out[i] = out[i - 1];
        out[i] = &KNOBS[k];
    }
    return n;
}

/* The joint grids: photons per group x N, the pair that sets the AIMs' noise and blur, and N x the
 * smallest radius, which decides whether N acts at all (at lmgi run's density the radius of 1 texel holds
 * more than N hits). */
static const double GRID_PER_GROUP_FULL[] = {40, 160, 640}, GRID_N_FULL[] = {32, 128, 256};
static const double GRID_PER_GROUP_QUICK[] = {80, 320}, GRID_N_QUICK[] = {64, 256};
static const double GRID_RADIUS_FULL[] = {0.25, 0.5}, GRID_RADIUS_QUICK[] = {0.25};

const char *lm_tradeoff_knob_keys(void)
{
    static char keys[512];
    if (!keys[0]) {
        const knob *list[N_ENTRIES];
        int n = swept(list);
        for (int k = 0; k < n; k++) {
            strcat(keys, list[k]->key);
            strcat(keys, ", ");
        }
        strcat(keys, "grid, grid_radius");
    }
    return keys;
}

static int known(const char *name, size_t len)
{
    if ((len == 4 && !strncmp(name, "grid", 4)) || (len == 11 && !strncmp(name, "grid_radius", 11)))
        return 1;
    for (int k = 0; k < N_ENTRIES; k++)
        if (KNOBS[k].order && strlen(KNOBS[k].key) == len && !strncmp(name, KNOBS[k].key, len))
            return 1;
    return 0;
}

int lm_tradeoff_knobs_known(const char *list, char *bad, size_t bad_size)
{
    for (const char *p = list; *p;) {
        size_t len = strcspn(p, ",");
        if (!known(p, len)) {
            snprintf(bad, bad_size, "%.*s", (int)len, p);
            return 0;
        }
        p += len + (p[len] == ',');
    }
    return 1;
}

static int wanted(const lm_tradeoff_plan *p, const char *key)
{
    if (!p->only)
        return 1;
    size_t n = strlen(key);
    for (const char *s = p->only; *s;) {
        size_t len = strcspn(s, ",");
        if (len == n && !strncmp(s, key, n))
            return 1;
        s += len + (s[len] == ',');
    }
    return 0;
}

static lm_tradeoff_setting base(const lm_tradeoff_plan *p, const char *key, const char *label)
{
    lm_tradeoff_setting s;
    memset(&s, 0, sizeof s);
    s.knob = key;
    s.label = label;
    s.target_texels = p->default_texels;
    return s;
}

int lm_tradeoff_settings(const lm_tradeoff_plan *p, lm_tradeoff_setting **out, int *count)
{
    const knob *list[N_ENTRIES];
    int swept_count = swept(list), cap = swept_count * MAX_VALUES + 9 + 6, n = 0;
    lm_tradeoff_setting *s = calloc((size_t)cap, sizeof *s);
    if (!s)
        return 0;
    for (int k = 0; k < swept_count; k++) {
        const knob *kb = list[k];
        if (!wanted(p, kb->key) || (kb->when == 1 && !p->caustics) || (kb->when == 2 && !(p->photon_radius > 0.0f)))
            continue;
        const double *v = p->quick ? kb->quick : kb->full;
        for (int i = 0; i < (p->quick ? kb->n_quick : kb->n_full); i++) {
            s[n] = base(p, kb->key, kb->label);
            if (kb->apply)
                kb->apply(&s[n].desc, &s[n].target_texels, v[i], p);
            else
                set_knob(kb, &s[n].desc, v[i]);
            s[n].x = kb->apply == set_texels ? (double)s[n].target_texels : v[i];
            if (kb->off && v[i] == 0.0)
                snprintf(s[n].value, sizeof s[n].value, "none");
            else
                snprintf(s[n].value, sizeof s[n].value, "%g", kb->apply == set_texels ? s[n].x : v[i]);
            n++;
        }
    }
    if (wanted(p, "grid")) {
        const double *pg = p->quick ? GRID_PER_GROUP_QUICK : GRID_PER_GROUP_FULL;
        const double *nn = p->quick ? GRID_N_QUICK : GRID_N_FULL;
        int npg = p->quick ? 2 : 3, nnn = p->quick ? 2 : 3;
        for (int i = 0; i < npg; i++)
            for (int j = 0; j < nnn; j++) {
                s[n] = base(p, "grid", "photons per group x N");
                s[n].desc.photons.per_group = (uint32_t)pg[i];
                s[n].desc.aim.nearest = (int)nn[j];
                s[n].x = pg[i];
                snprintf(s[n].value, sizeof s[n].value, "%g x N %g", pg[i], nn[j]);
                n++;
            }
    }
    if (wanted(p, "grid_radius")) {
        const double *rr = p->quick ? GRID_RADIUS_QUICK : GRID_RADIUS_FULL;
        const double *nn = p->quick ? GRID_N_QUICK : GRID_N_FULL;
        int nr = p->quick ? 1 : 2, nnn = p->quick ? 2 : 3;
        for (int i = 0; i < nr; i++)
            for (int j = 0; j < nnn; j++) {
                s[n] = base(p, "grid_radius", "smallest radius x N");
                s[n].desc.aim.min_radius = (float)rr[i];
                s[n].desc.aim.nearest = (int)nn[j];
                s[n].x = nn[j];
                snprintf(s[n].value, sizeof s[n].value, "%g texels x N %g", rr[i], nn[j]);
                n++;
            }
    }
    *out = s;
    *count = n;
    return 1;
}

int lm_tradeoff_same(const lm_tradeoff_setting *a, const lm_tradeoff_setting *b)
{
    /* the descs are built from zeroed memory and set field by field, so their bytes compare */
    return a->target_texels == b->target_texels && !memcmp(&a->desc, &b->desc, sizeof a->desc);
}
