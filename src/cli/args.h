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
    /* photon stage and reference solver (0 / NULL = the command's default) */
    int frames;             /* --frames N */
    unsigned seed;          /* --seed N */
    int photons;            /* --photons N: total photon budget */
    int groups;             /* --groups G */
    int per_group;          /* --per-group M */
    int retrace;            /* --retrace k: photons re-traced per group per frame */
    int group_budget;       /* --group-budget B: invalid groups re-traced per frame (-1 unset, 0 all) */
    int nearest;            /* --nearest N: photons per AIM estimate */
    int surface_budget;     /* --surfaces-per-frame K: AIM refreshes per frame */
    int shadow_maps;        /* --shadow-maps-per-frame N: stale shadow maps re-rendered per frame (-1 unset, 0 all) */
    float target_error;     /* --target-error E: relative standard error per texel (reference) */
    int samples;            /* --samples N: samples per texel/pixel per pass (reference) */
    int caustic_photons;    /* --caustic-photons N: caustic photons per light and mirror/glass node (a run's, or
                             * the reference command's light-traced ones) */
    int ref_caustic_photons; /* --reference-caustic-photons N: the reference's light-traced ones (check) */
    const char *cache_dir;  /* --cache DIR (reference) */
    int no_cache;           /* --no-cache */
    int camera;             /* --camera I (default: the file's first, else automatic) */
    /* lmgi run (0 = default) */
    int texels_per_frame;   /* --texels-per-frame N: IIM gather budget per frame */
    int exr_every;          /* --exr-every K: every K-th frame also as EXR */
    int hemicube;           /* --hemicube R: hemicube plane pixels per side */
    int hemicube_samples;   /* --hemicube-samples N: AIM lookups per hemicube pixel (1 or 4) */
    int hemicube_coverage;  /* --hemicube-coverage N: MSAA coverage samples per hemicube pixel (1 to 16) */
    int rim_samples;        /* --rim-samples K: directions for the rim outside the plane (0: 1 / F(a)); -1 unset */
    int reflection_size;    /* --reflection-size N: environment map side (0: no reflections); -1 unset */
    int reflection_faces;   /* --reflection-faces N: environment map faces re-rendered a frame; 0 unset */
    float caustic_retrace;  /* --caustic-retrace F: share of the caustic photons re-traced a frame; 0 unset */
    int caustic_filter;     /* --caustic-filter K: k of the caustics' (2k + 1)^2 filter; -1 unset */
    int caustic_world;      /* --caustic-space screen|world: 1 filters by world distance */
    int caustic_tile;       /* --caustic-tile N: tile side of the caustics' occlusion queries; 0 unset */
    float enlargement;      /* --enlargement a: hemicube plane half-side at distance 1 */
    int gather_scheme;      /* --gather-scheme viewports|instanced|layered (-1 = default) */
    int emitter_light;      /* --emitter-light closed|drawn: 1, 0 (-1 = per scene) */
    int emitter_rays;       /* --emitter-rays N: shadow rays per emissive triangle and texel */
    int in_order;           /* --in-order: photon stage before the gather, one thread (no overlap) */
    int force;              /* --force: write into a non-empty --out directory lmgi did not make */
    int tonemap;            /* --tonemap neutral|clamp: lmgi_tonemap of the PNGs (default neutral) */
    unsigned effects_off;   /* --effects -shadows,-indirect,-reflections,-caustics: lmgi_updater_desc.effects_off */
    int indirect;           /* --indirect lightmap|tiled|hashgrid|bruteforce: lmgi_updater_desc.indirect */
    int photon_tile, photon_chunk, photon_stochastic; /* --photon-tile/-chunk/-stochastic; 0 unset */
    float photon_radius;    /* --photon-radius R; 0 unset */
    int aim_direct;         /* --aim-direct emitters|photons|all: lmgi_updater_desc.aim_direct (default photons) */
    int find_portals;       /* --find-portals on|off: lmgi_updater_desc.find_portals (0 on, the default; -1 off) */
    int half;               /* --half (bake): EXR lightmaps as 16-bit half floats */
    int gltf;               /* --gltf (bake): also a glTF copy of the scene with the lightmap's UVs */
    int accuracy;           /* --accuracy (bake): also the lightmaps' estimate of their own error */
    int resume;             /* --resume (bake): continue from DIR/bake.checkpoint */
    float checkpoint_seconds; /* --checkpoint-seconds S (bake): at most one checkpoint every S (0: 10) */
    int shard, shards;      /* --shard K/N (bake): share K (1-based) of N; shards 0: a whole bake */
    int frame_lag;          /* --frame-lag (tradeoff --edits): the frame's lag against the reference too */
    const char *gather_scene; /* --gather-scene FILE (bench): the ~133k-triangle Cornell box */
    const char *edits_path;   /* --edits SCRIPT.json (bench): a scripted edit sequence */
    int soak;                 /* --soak N (bench): N frames of the scene's animation, looped (0: none) */
    int random_edits;         /* --random-edits L (bench --soak): a random edit before each update, up to L lights */
    float budget_ms;          /* --budget MS (bench --soak): lmgi_update's budget_ms (0: texels_per_frame) */
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
