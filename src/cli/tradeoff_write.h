/* What `lmgi tradeoff` measured, and how it is written: DIR/tradeoff.csv (one row per scene and setting),
 * DIR/tradeoff.json (the same, with the run's settings and which error maps are which), the maps as
 * DIR/map_SCENE_WHICH_{iim,frame}.npy (float32, rows top first for the frame, v = 0 first for the
 * atlas; the signed relative error est / ref - 1 with the floor of error_of, NaN where not compared), and
 * the report (tools/tradeoff_report.py) that turns them into DIR/report.html and DIR/plot_*.png. */
#ifndef LM_CLI_TRADEOFF_WRITE_H
#define LM_CLI_TRADEOFF_WRITE_H

#include <stdint.h>

#include "edit_script.h"
#include "tradeoff_knobs.h"

typedef struct {
    double rmse, p99, worst; /* relative RMSE; 99th percentile and worst relative error; NAN: no such map */
    uint32_t count;          /* texels or pixels compared */
} lm_tradeoff_error;

typedef struct {
    lm_tradeoff_setting setting;
    int is_default;          /* every knob at its default */
    uint32_t photons;        /* stored photon paths */
    int coverage;            /* coverage samples as resolved */
    float photon_radius;     /* the tiled gather's radius as resolved (0: not that path) */
    double ms_trace, ms_aim, ms_gather, ms_solution; /* the full solution's stages and sum, medians */
    double ms_update[8];     /* medians per update: total, photons, gather, direct, caustics, reflections,
                              * composite, blend */
    lm_tradeoff_error aim, iim, frame;
    double frame_ratio[3], frame_bias; /* frame / reference per channel; max |ratio - 1| */
    double frame_surface_rms, frame_surface_worst; /* per visible surface (tradeoff_cmd.c surface_errors) */
    lm_tradeoff_error caustic; /* the frame's caustic part against the reference's (NAN: no caustics) */
    double caustic_ratio[3]; /* its sum over the reference's per channel */
    double reference_rel_se; /* the pixel reference's own relative standard error */
    float *iim_map, *frame_map;
    int map_width, map_height, frame_width, frame_height;
} lm_tradeoff_row;

/* One play of a scene's edit script at one update budget (the update-lag study). */
typedef struct {
    const char *knob;        /* "texels_per_frame", "group_budget" or "surfaces_per_frame" */
    int value;
    int is_default;          /* every budget at its default */
    lm_edit_frame *frames;   /* the script's frames, one per update (NULL: the play failed) */
    int frame_lag;           /* its frames' frame_error measured (--frame-lag, the default play) */
} lm_tradeoff_play;

/* The side of the frame --frame-lag checks after every update. */
#define LM_TRADEOFF_LAG_SIDE 64

typedef struct {
    const char *path;
    char name[64];
    const lm_edit_script *script; /* the edit script played on it (NULL: none) */
    lm_tradeoff_play *plays;
    int play_count;           /* the file's base name, letters, digits, - and _ */
    double reference_texels_seconds, reference_texels_rel_se;
    lm_tradeoff_row *rows;
    int count;
    int failed;              /* settings the library refused (their rows hold NAN) */
} lm_tradeoff_scene;

typedef struct {
    int quick, repeats;
    float target_error;      /* the references' */
    const lm_tradeoff_scene *scenes;
    int count;
} lm_tradeoff_run;

void lm_tradeoff_scene_name(const char *path, char *name, size_t size);
/* dst = src with its own copies of the maps (a setting measured once, listed under two knobs). */
void lm_tradeoff_row_copy(lm_tradeoff_row *dst, const lm_tradeoff_row *src);
void lm_tradeoff_scene_free(lm_tradeoff_scene *s);
/* The CSV, the JSON (with the plays: per update the lightmap's distance from the converged one and the
 * update's time, and per edit the updates and milliseconds until it is within 5% and 2%), lag.csv and
 * the maps. 0 (after printing the error) when a file cannot be written. */
int lm_tradeoff_write(const char *dir, const lm_tradeoff_run *run);
/* Runs tools/tradeoff_report.py DIR quietly (found beside the executable: ../tools or ../share/lmgi). 0
 * (after saying why and how to run it, naming `shown`: where the files end up) when it is not found or
 * fails. */
int lm_tradeoff_report(const char *dir, const char *shown);

#endif
