/* Edit scripts (docs/bench.md, "Edit scripts and update lag"): a JSON list of edits made at given updates
 * (lights, nodes, materials, lights added and removed), played through the public updater with each
 * update's time and work, and after each edit the distance of the updater's lightmap from the converged
 * lightmap of the edited scene (a twin scene given the same edits and baked). `lmgi bench --edits` reports
 * one play; `lmgi tradeoff --edits` plays a script once per update budget for the update-lag curves. */
#ifndef LM_CLI_EDIT_SCRIPT_H
#define LM_CLI_EDIT_SCRIPT_H

#include <cjson/cJSON.h>
#include <lmgi_tools.h>

#define LM_EDIT_MAX 256

typedef struct {
    int frame;             /* the update before which the edit is made */
    const cJSON *v;        /* the edit's object in the script */
} lm_edit;

typedef struct {
    const char *path;
    cJSON *root;
    int frames, fps, texels;
    float budget_ms;
    const char *scene;     /* the "scene" key: the file name the script was written for (NULL: not said) */
    int edit_count;
    lm_edit edits[LM_EDIT_MAX];
} lm_edit_script;

/* One update of a play. */
typedef struct {
    double ms_total, ms_photons, ms_gather, ms_blend;
    uint32_t texels, photons;
    int aim, changed;
    double error;          /* relative L1 distance of the IIM from the converged one, over valid texels */
    double worst_surface;  /* the same per surface of 16 or more valid texels, the largest */
    int outside;           /* surfaces outside the last edit's reach (their converged lightmap did not move:
                            * LM_EDIT_REACH) whose displayed lightmap this update rewrote */
    uint32_t outside_texels; /* their texels */
    int reached;           /* the surfaces in its reach this update rewrote */
    int reach;             /* the surfaces in its reach, of those with something to judge by */
    double frame_error;    /* with a frame check: the frame's error per surface (surface_error.h) against the
                            * path-traced reference of the scene as edited so far; NAN before the first
                            * edit and without one */
    double ms_read_whole;  /* the displayed lightmap to an engine: the whole-atlas read (lmgi_get_lightmap) */
    double ms_read_rects;  /* the same by the rectangles of the surfaces this update changed alone
                            * (lmgi_surface_lightmap_rect, lmgi_get_lightmap_rect) */
    uint32_t rect_texels;  /* the texels those rectangles hold */
    double ms_texture;     /* the same into lmgi's GL texture (lmgi_get_lightmap_texture: the rectangles read,
                            * uploaded, and glFinish) */
    double ms_edit;        /* the calls of the edits made before this update (staged: they wait for no photon
                            * work, update/edits.h); 0 without one */
    const char *busiest;   /* the stage that took the update's longest time (lmgi_update_stats.busiest_stage) */
    double ms_light_scale; /* of ms_photons or ms_gather: a light or colour edit's texel factors */
} lm_edit_frame;

/* A play's frame check: after every update from the first edit on, the updater's picture from the scene's
 * camera at width x height against the reference (lmgi_check_updater; ref's cache makes each edited
 * state's reference once). */
typedef struct {
    const lmgi_reference_desc *ref;
    int width, height;
} lm_edit_frame_check;

/* What lm_edit_lag measures the lag by. */
typedef enum { LM_LAG_ATLAS = 0, LM_LAG_WORST_SURFACE = 1, LM_LAG_FRAME = 2 } lm_lag_metric;

/* A surface is in an edit's reach when its converged lightmap moved by more than this (relative L1 over
 * its valid texels) with the edit (a bake leaves the others' texels as they were, to the bit), or when an
 * earlier edit reached it and its lightmap is still further than LM_EDIT_CAUGHT_UP from that edit's
 * converged one: the work under way is the earlier edit's. */
#define LM_EDIT_REACH 1e-4
#define LM_EDIT_CAUGHT_UP 0.02

/* Reads (with cJSON) and checks the script (1 MiB at most). 0, after printing what is wrong (file, edit,
 * key; for text that is not JSON, the line and column where it stops being JSON), when it cannot be read,
 * is not valid JSON or is out of range. */
int lm_edit_script_read(const char *path, lm_edit_script *s);
void lm_edit_script_free(lm_edit_script *s);
/* Plays s on scene_path loaded at the script's texels, with desc d (NULL: the defaults) and lmgi_update's
 * budget budget_ms (the script's, or 0 for d's texels_per_frame): rows[0 .. s->frames); fc: the frame
 * check (NULL: none). 0 after printing the error (an edit the scene cannot take names the edit). */
int lm_edit_script_play(const lm_edit_script *s, const char *scene_path, const lmgi_updater_desc *d,
                        float budget_ms, const lm_edit_frame_check *fc, lm_edit_frame *rows);
/* Makes edit i of s on sc (a window playing the script: lmgi view --script). 0 after printing what is wrong,
 * naming the script and the edit. */
int lm_edit_script_apply(const lm_edit_script *s, int i, lmgi_scene *sc);
/* The updates edit i's effect is measured over, [*from, *to): from its frame to the next edit's (or the
 * end). 0 when a later edit shares its frame (the last of a frame's edits reports). */
int lm_edit_span(const lm_edit_script *s, int i, int *from, int *to);
/* Updates and update milliseconds from `from` until the error `by` measures (the whole atlas's distance,
 * the worst surface's, or the frame's) is under `limit` (*frames -1: not in [from, to); *ms is then the
 * time of all of them). */
void lm_edit_lag(const lm_edit_frame *rows, int from, int to, double limit, lm_lag_metric by, int *frames,
                 double *ms);
/* "light light_b2", "node door", ...: what edit e does, for tables. */
void lm_edit_describe(const cJSON *e, char *out, size_t n);

#endif
