/* The knobs `lmgi tradeoff` sweeps (docs/tradeoff.md): every setting of the updater that trades accuracy
 * for time, each moved alone around the defaults, and a joint grid of the two that matter most (photons
 * per group and N). A setting is the default desc with one knob (or, in the grid, two) moved.
 *
 * Every knob's sweep lists its default value too, so each plot has its default point; a setting that
 * equals an earlier one (the default appears once per knob) is measured once by the caller. */
#ifndef LM_CLI_TRADEOFF_KNOBS_H
#define LM_CLI_TRADEOFF_KNOBS_H

#include <lmgi.h>

typedef struct {
    const char *knob;     /* the knob's key ("photons_per_group", ..., "grid") */
    const char *label;    /* what the plots call it */
    char value[40];       /* the value as printed ("320", "none", "320 x N 64") */
    double x;             /* the value as a number for the plots (grid: photons per group) */
    int target_texels;    /* the atlas it is measured on */
    lmgi_updater_desc desc;
} lm_tradeoff_setting;

typedef struct {
    int quick;            /* fewer values per knob, a smaller grid */
    int default_texels;   /* the atlas `lmgi run` loads the scene at */
    int caustics;         /* the scene calls for caustics: sweep their photons and filter */
    float photon_radius;  /* the tiled gather's default radius on this scene (0: no tiled sweep) */
    const char *only;     /* comma-separated knob keys to sweep (NULL: every knob) */
} lm_tradeoff_plan;

/* *out (malloc'd, *count entries): each knob's sweep in the order of the knob table, then the grid.
 * 0 when out of memory. */
int lm_tradeoff_settings(const lm_tradeoff_plan *p, lm_tradeoff_setting **out, int *count);

/* The knob keys, comma-separated (for messages), and whether `list` names only known ones: 0 and the
 * first unknown key in bad (bad_size bytes) when not. */
const char *lm_tradeoff_knob_keys(void);
int lm_tradeoff_knobs_known(const char *list, char *bad, size_t bad_size);

/* 1 when two settings would run the same updater on the same atlas. */
int lm_tradeoff_same(const lm_tradeoff_setting *a, const lm_tradeoff_setting *b);

#endif
