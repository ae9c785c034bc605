/* The knob table of `lmgi tradeoff`: each knob's values (full sweep and --quick), its default, and how a
 * value goes into the updater's desc. Values come from the range where each knob's cost or error moves
 * (docs/tradeoff.md says what each buys). */
#include "tradeoff_knobs.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_VALUES 6

typedef struct {
    const char *key, *label;
    double full[MAX_VALUES];
    int n_full;
    double quick[MAX_VALUES];
    int n_quick;
    double def; /* the value the zero desc resolves to: left as 0 in the desc (NAN: none, per scene) */
    /* sets the value into d (or the atlas texels); plan for the per-scene ones */
    void (*apply)(lmgi_updater_desc *d, int *texels, double v, const lm_tradeoff_plan *p);
    int when; /* 0: always; 1: the scene has caustics; 2: the tiled gather's radius is known */
} knob;

static void set_per_group(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->photons_per_group = (uint32_t)v;
}
static void set_groups(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->groups = (uint32_t)v;
}
static void set_nearest(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->photons_per_estimate = (int)v;
}
/* v: the atlas's texels as a multiple of the default (the texel size follows as 1 / sqrt(v)) */
static void set_texels(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)d;
    *t = (int)lround(v * p->default_texels);
}
static void set_hemicube(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->hemicube_resolution = (int)v;
}
static void set_enlargement(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->enlargement = (float)v;
}
static void set_samples(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->hemicube_samples = (int)v;
}
static void set_coverage(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->hemicube_coverage = (int)v;
}
/* v = 0: no rim rays, the paper's 1 / F(a) */
static void set_rim(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->rim_samples = v > 0.0 ? (int)v : -1;
}
static void set_aim_direct(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->aim_direct = v > 0.0 ? LMGI_AIM_DIRECT_EMITTERS : LMGI_AIM_DIRECT_PHOTONS;
}
static void set_texels_per_frame(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->texels_per_frame = (int)v;
}
static void set_caustic_photons(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->caustic_photons = (uint32_t)v;
}
static void set_caustic_filter(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->caustic_filter = (int)v;
}
/* k = 1 and the radius x 1 are the tiled gather's defaults, left 0 so that the two sweeps share that point */
static void set_tiled_k(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t, (void)p;
    d->indirect = LMGI_INDIRECT_TILED;
    d->photon_stochastic = v == 1.0 ? 0 : (int)v;
}
/* v: the radius as a multiple of the scene's default one */
static void set_tiled_radius(lmgi_updater_desc *d, int *t, double v, const lm_tradeoff_plan *p)
{
    (void)t;
    d->indirect = LMGI_INDIRECT_TILED;
    d->photon_radius = v == 1.0 ? 0.0f : (float)(v * p->photon_radius);
}

/* The defaults are the values the zero desc resolves to (lmgi.h), so each sweep's default point is the
 * default desc itself; NAN where the default depends on the scene (photons per group: 160, or more up to
 * the scene's floor of 46,080 photons; coverage) and for the tiled gather's own sweeps. */
static const knob KNOBS[] = {
    {"photons_per_group", "photons per group", {40, 80, 160, 320, 640}, 5, {40, 160, 640}, 3, NAN, set_per_group, 0},
    {"groups", "groups per light", {18, 36, 72, 144, 288}, 5, {18, 72, 288}, 3, 72, set_groups, 0},
    {"nearest", "photons per AIM estimate N", {16, 32, 64, 128, 256}, 5, {16, 32, 128}, 3, 32, set_nearest, 0},
    {"texels", "atlas texels (x the default)", {0.25, 0.5, 1, 2, 4}, 5, {0.5, 1}, 2, 1, set_texels, 0},
    {"hemicube", "hemicube resolution R", {16, 24, 32, 48, 64}, 5, {16, 32, 64}, 3, 32, set_hemicube, 0},
    {"enlargement", "hemicube enlargement a", {1, 1.5, 2, 3}, 4, {1, 2, 3}, 3, 2, set_enlargement, 0},
    {"hemicube_samples", "AIM lookups per hemicube pixel", {1, 4}, 2, {1, 4}, 2, 4, set_samples, 0},
    {"coverage", "coverage samples per hemicube pixel", {1, 2, 4}, 3, {1, 4}, 2, NAN, set_coverage, 0},
    {"rim_samples", "rim rays per texel (0: 1 / F(a))", {0, 16, 64, 256}, 4, {0, 64}, 2, 64, set_rim, 0},
    {"aim_direct", "AIM direct light (0 photons, 1 emitters)", {0, 1}, 2, {0, 1}, 2, 0, set_aim_direct, 0},
    {"texels_per_frame", "IIM texels gathered per update", {5, 20, 80}, 3, {0}, 0, 20, set_texels_per_frame, 0},
    {"caustic_photons", "caustic photons per light and node", {4096, 16384, 65536}, 3, {4096, 16384, 65536}, 3,
     16384, set_caustic_photons, 1},
    {"caustic_filter", "caustic filter k", {1, 2, 3, 5}, 4, {1, 3, 5}, 3, 3, set_caustic_filter, 1},
    {"tiled_k", "tiled gather k (stochastic)", {1, 2, 4}, 3, {1, 2, 4}, 3, NAN, set_tiled_k, 2},
    {"tiled_radius", "tiled gather radius (x the default)", {0.5, 1, 2}, 3, {0.5, 1, 2}, 3, NAN, set_tiled_radius, 2},
};
#define N_KNOBS ((int)(sizeof KNOBS / sizeof KNOBS[0]))

/* The joint grid: photons per group x N, the pair that sets the AIMs' noise and blur. */
static const double GRID_PER_GROUP_FULL[] = {40, 160, 640}, GRID_N_FULL[] = {32, 128, 256};
static const double GRID_PER_GROUP_QUICK[] = {80, 320}, GRID_N_QUICK[] = {64, 256};

const char *lm_tradeoff_knob_keys(void)
{
    static char keys[512];
    if (!keys[0]) {
        for (int k = 0; k < N_KNOBS; k++) {
            strcat(keys, KNOBS[k].key);
            strcat(keys, ", ");
        }
        strcat(keys, "grid");
    }
    return keys;
}

static int known(const char *name, size_t len)
{
    if (len == 4 && !strncmp(name, "grid", 4))
        return 1;
    for (int k = 0; k < N_KNOBS; k++)
        if (strlen(KNOBS[k].key) == len && !strncmp(name, KNOBS[k].key, len))
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
    int cap = N_KNOBS * MAX_VALUES + 9, n = 0;
    lm_tradeoff_setting *s = calloc((size_t)cap, sizeof *s);
    if (!s)
        return 0;
    for (int k = 0; k < N_KNOBS; k++) {
        const knob *kb = &KNOBS[k];
        if (!wanted(p, kb->key) || (kb->when == 1 && !p->caustics) || (kb->when == 2 && !(p->photon_radius > 0.0f)))
            continue;
        const double *v = p->quick ? kb->quick : kb->full;
        for (int i = 0; i < (p->quick ? kb->n_quick : kb->n_full); i++) {
            s[n] = base(p, kb->key, kb->label);
            if (v[i] != kb->def) /* the default stays the zero desc's, so every sweep shares that point */
                kb->apply(&s[n].desc, &s[n].target_texels, v[i], p);
            s[n].x = kb->apply == set_texels ? (double)s[n].target_texels : v[i];
            if (kb->apply == set_rim && v[i] == 0.0)
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
                s[n].desc.photons_per_group = (uint32_t)pg[i];
                s[n].desc.photons_per_estimate = (int)nn[j];
                s[n].x = pg[i];
                snprintf(s[n].value, sizeof s[n].value, "%g x N %g", pg[i], nn[j]);
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
