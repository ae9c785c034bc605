/* Command-line options shared by the lmgi subcommands. */
#ifndef LM_CLI_ARGS_H
#define LM_CLI_ARGS_H

#include <lmgi_tools.h>
#include <stdio.h>

#define LM_CLI_MAX_FILES 4100 /* a merge's parts: one of each of up to 4096 shards, and its scene */

typedef struct {
    lmgi_options options;
    const char *out_dir;
    const char *json_path;
    int width, height;
    int repeats;
    int verbose, quiet;
    int file_count;
    const char *files[LM_CLI_MAX_FILES];
    int scaling_count;
    const char *scaling[LM_CLI_MAX_FILES];
    /* the updater's knobs (include/lmgi_knobs.h: their options are made from its table, knob_options.h)
     * and its --indirect, --effects and --in-order, as lmgi_updater_desc holds them (0: the default) */
    lmgi_updater_desc desc;
    /* the reference solver and what the updater shares with it (0 / NULL = the command's default) */
    int frames;             /* --frames N */
    unsigned seed;          /* --seed N: the updater's photons.seed and the reference's paths */
    float target_error;     /* --target-error E: relative standard error per texel (reference) */
    int samples;            /* --samples N: samples per texel/pixel per pass (reference) */
    int caustic_photons;    /* --caustic-photons N: caustic photons per light and mirror/glass node (a run's, or
                             * the reference command's light-traced ones) */
    int ref_caustic_photons; /* --reference-caustic-photons N: the reference's light-traced ones (check) */
    const char *cache_dir;  /* --cache DIR (reference) */
    int no_cache;           /* --no-cache */
    int camera;             /* --camera I (default: the file's first, else automatic) */
    int exr_every;          /* --exr-every K (run): every K-th frame also as EXR */
    int force;              /* --force: write into a non-empty --out directory lmgi did not make */
    int tonemap;            /* --tonemap neutral|clamp: lmgi_tonemap of the PNGs (default neutral) */
    int half;               /* --half (bake): EXR lightmaps as 16-bit half floats */
    int gltf;               /* --gltf (bake): also a glTF copy of the scene with the lightmap's UVs */
    int accuracy;           /* --accuracy (bake): also the lightmaps' estimate of their own error */
    int resume;             /* --resume (bake): continue from DIR/bake.checkpoint */
    int as_bake;            /* --as-bake (check): the lightmap a bake makes (bake_options.h), not run's */
    float checkpoint_seconds; /* --checkpoint-seconds S (bake): at most one checkpoint every S (0: 10) */
    int shard, shards;      /* --shard K/N (bake): share K (1-based) of N; shards 0: a whole bake */
    int frame_lag;          /* --frame-lag (tradeoff --edits): the frame's lag against the reference too */
    const char *gather_scene; /* --gather-scene FILE (bench): the ~133k-triangle Cornell box */
    const char *edits_path;   /* --edits SCRIPT.json (bench): a scripted edit sequence */
    const char *script_path;  /* --script EDITS.json (view): an edit script played in the window */
    const char *screenshot_path; /* --screenshot FILE (view): the last frame */
    int still;                /* --still (view): the animations at time 0 */
    int watch;                /* --watch (view): follow the scene's file as it is saved */
    int soak;                 /* --soak N (bench): N frames of the scene's animation, looped (0: none) */
    int random_edits;         /* --random-edits L (bench --soak): a random edit before each update, up to L lights */
    float budget_ms;          /* --budget MS (run, bench --soak): lmgi_update's budget_ms (0: the fixed counts) */
    int quick;                /* --quick (tradeoff): fewer values per knob, looser references */
    const char *knobs;        /* --knobs LIST (tradeoff): the knobs to sweep (NULL: all) */
    int word_count;           /* the words parsed (argv[first..argc)), as given: a shard records its */
    char **words;             /* bake's in part.json for lmgi merge */
} lm_cli_args;

/* Parses argv[first..argc) for `command` (its name, for messages): an option outside the `commands` set
 * of LM_CMD_* bits (options.h; ~0u: every option, lmgi-dev's too) is refused naming the commands that
 * take it, an unknown one with the nearest spelling. Returns 0 on success, or prints what was wrong and
 * returns 2. */
int lm_cli_parse(int argc, char **argv, int first, const char *command, unsigned commands, lm_cli_args *a);
/* The start a program of commands shares (`PROGRAM COMMAND [options]`): no command prints usage on
 * stderr (exit 2), help on stdout (exit 0); for lmgi (`lmgi` 1) `help COMMAND` and `COMMAND --help`
 * print that command's usage and options (exit 0), and a command takes only its own options; then
 * argv[2..] is parsed (exit 2 when bad) and the library's verbosity set from -q / -v. Returns -1 to go
 * on with argv[1], else the exit code. */
int lm_cli_start(int argc, char **argv, void (*usage)(FILE *), int lmgi, lm_cli_args *a);

#endif
