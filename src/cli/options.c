/* The lmgi command's commands and options (options.h): one table each, read by the parser and printed
 * by the help. */
#include "options.h"

#include <stdlib.h>
#include <string.h>

#include "knob_options.h"
#include "option_values.h"

const lm_cli_command lm_cli_commands[] = {
    {"info", LM_CMD_INFO, "info SCENE",
     "counts, materials by class, lights, surfaces, charts, atlas, and which effects the scene calls\n"
     "for and why"},
    {"charts", LM_CMD_CHARTS, "charts SCENE --out DIR",
     "write DIR/atlas.png (charts coloured, free space black) and DIR/surfaces.png (the scene from\n"
     "its camera, each surface a flat colour)"},
    {"run", LM_CMD_RUN, "run SCENE --out DIR",
     "the whole frame loop over the scene's animations (photons, AIMs, IIM gather, direct light,\n"
     "composite): DIR/frame_NNNN.png (every K-th also .exr), iim.exr/png, aim.exr/png (with several\n"
     "pages iim_pageP and aim_pageP for each page P) and frames.csv (work and ms per stage)"},
    {"bake", LM_CMD_BAKE, "bake SCENE --out DIR",
     "the full solution for the scene as it is (every photon, AIM and texel), with a progress bar and\n"
     "the time left (Ctrl-C or SIGTERM cancels, keeping what it finished for --resume; a failed bake\n"
     "leaves the last lightmaps): DIR/lightmap.exr (irradiance, alpha = valid), lightmap.png (a\n"
     "preview), aim.exr, or with several pages (--max-atlas) lightmap_pageP.exr, .png and\n"
     "aim_pageP.exr for each page P; --gltf: also NAME.gltf, the scene for engines with TEXCOORD_1 =\n"
     "lightmap UVs"},
    {"merge", LM_CMD_MERGE, "merge PART... --out DIR | merge SCENE PART... --out DIR",
     "a bake spread over processes put together: the parts the shards wrote (bake SCENE --shard K/N\n"
     "--out PART; each PART a folder, or its part.checkpoint), one of each share, give the lightmaps\n"
     "one bake gives, to the bit (docs/levels.md, \"A bake in shards\"). PART... alone: the scene and\n"
     "the bake's options are those the parts recorded (PART/part.json), and merge takes only --out,\n"
     "--gltf, --accuracy, --half, --force, -q and -v; SCENE PART... (parts of an older lmgi): give\n"
     "the scene and the options the shards were baked with"},
    {"check", LM_CMD_CHECK, "check SCENE",
     "one frame of 'run' (same options) against the path-traced reference: frame / reference per\n"
     "visible surface and over the frame, and the relative RMSE (default --size 128x128; --out DIR:\n"
     "the two EXRs)"},
    {"reference", LM_CMD_REFERENCE, "reference SCENE --out DIR",
     "path-traced ground truth per texel and per pixel, split by light path: direct, iim, caustic\n"
     "(light-traced), lost; the picture also emission, indirect and reflections\n"
     "(DIR/reference_*.exr)"},
    {"bench", LM_CMD_BENCH, "bench [SCENE...] | bench --edits SCRIPT.json SCENE | bench --soak N [SCENE] [--random-edits L]",
     "time load, surface split, atlas (unwrap, pack, texel table) and BVH build; --scaling FILE\n"
     "(repeatable) adds a growth table; with no SCENE also the update time budget and every scene's\n"
     "default frame against the reference (photon tracing and the gather: lmgi-dev bench, make\n"
     "bench). --edits: a scripted edit sequence through the updater: per-update times, budget\n"
     "overruns, each edit's update lag, the surfaces it rewrote in its reach and outside it, and\n"
     "the lightmap reads an engine makes (docs/bench.md). --soak: N updates of the looped animation,\n"
     "or with --random-edits L of random edits (lights added and removed up to L) at --budget MS"},
    {"tradeoff", LM_CMD_TRADEOFF, "tradeoff SCENE... --out DIR",
     "what accuracy costs in time: every knob that trades one for the other swept around the defaults\n"
     "(--knobs LIST: only those), each setting's stage times (medians of --repeats) and the error of\n"
     "its AIM, IIM and frame against the reference: DIR/report.html (plots, the Pareto front),\n"
     "tradeoff.csv/.json (docs/tradeoff.md); --edits SCRIPT,...: the lightmap's lag behind each\n"
     "scripted edit per update budget (lag.csv)"},
    {"view", LM_CMD_VIEW, "view SCENE",
     "a window showing the lighting as it follows every edit (docs/viewer.md): the updater runs each\n"
     "frame within --budget MS; mouse: left drag orbits, right drag (or shift) pans, the wheel zooms,\n"
     "a click selects a node, ctrl + drag moves it, ctrl + wheel turns it; keys: W A S D Q E fly, R\n"
     "the scene's camera, L the next light, + and - brighten or dim it, O switches it, C recolours it,\n"
     "N adds one, Delete removes it, ctrl+Z and ctrl+Y undo and redo, ctrl+S saves the scene, [ and\n"
     "] the budget, H the panel, P a screenshot, Esc quits. --script EDITS.json plays an edit script\n"
     "(docs/bench.md), --frames N quits after N frames, --screenshot FILE writes the last frame"},
    {NULL, 0, NULL, NULL},
};

/* The commands that make an updater from the options (lm_cli_updater_desc), that solve a reference
 * (lm_cli_reference_desc), and that write into --out. */
#define UPDATER LM_CMD_UPDATER
#define BAKES (LM_CMD_BAKE | LM_CMD_MERGE)
#define REFERENCE_USERS (LM_CMD_REFERENCE | LM_CMD_CHECK | LM_CMD_TRADEOFF)
#define OUTPUTS (LM_CMD_CHARTS | LM_CMD_RUN | BAKES | LM_CMD_CHECK | LM_CMD_REFERENCE | LM_CMD_TRADEOFF)

const lm_cli_option lm_cli_options[] = {
    {"--texel-size", NULL, "S", LM_CMD_ALL, LM_OPT_FLOAT, offsetof(lm_cli_args, options.texel_size), 0, 0, NULL,
     "world units per lightmap texel (default: from --texels)"},
    {"--texels", NULL, "N", LM_CMD_ALL, LM_OPT_INT, offsetof(lm_cli_args, options.target_texels), 16, 1 << 28, NULL,
     "texels the derived texel size aims at (default 65536; run: 90 x\n"
     "--texels-per-frame, so that its IIM is refreshed in full every 3 s)"},
    {"--gutter", NULL, "N", LM_CMD_ALL, LM_OPT_INT, offsetof(lm_cli_args, options.gutter), 0, 64, NULL,
     "empty texels between charts (default 0)"},
    {"--use-uv1", NULL, NULL, LM_CMD_ALL, LM_OPT_FLAG, offsetof(lm_cli_args, options.use_file_uv1), 0, 0, NULL,
     "use the file's TEXCOORD_1 as lightmap UVs instead of unwrapping"},
    {"--cone", NULL, "DEG", LM_CMD_ALL, LM_OPT_FLOAT, offsetof(lm_cli_args, options.surface_cone_deg), 0, 0, NULL,
     "max normal deviation inside one surface (default 30)"},
    {"--bend", NULL, "DEG|off", LM_CMD_ALL, LM_OPT_CUSTOM, 0, 0, 0, lm_cli_opt_bend,
     "the most a surface's shading normals may turn across one texel before its\n"
     "texels are made finer, up to 2x, within --texels (default 15; off: one\n"
     "texel size for all; docs/charts.md, \"Bending normals\")"},
    {"--open-need", NULL, "F|off", LM_CMD_ALL, LM_OPT_CUSTOM, 0, 0, 0, lm_cli_opt_open_need,
     "a surface that sees mostly sky and whose texels are worth less than F of the\n"
     "level's, per area, gets texels by their worth, up to 64x coarser, and the\n"
     "rest of --texels goes to the others (run, check: default 0.25; bake,\n"
     "info: default off; off: texels by area; docs/charts.md, \"Open surfaces\")"},
    {"--max-atlas", NULL, "N", LM_CMD_ALL, LM_OPT_INT, offsetof(lm_cli_args, options.max_atlas_size), 64, 32768, NULL,
     "the largest side of a lightmap page (default 8192): a level that does not fit\n"
     "one page gets several, a file each (docs/levels.md, \"Atlas\")"},
    {"--strict", NULL, NULL, LM_CMD_ALL, LM_OPT_FLAG, offsetof(lm_cli_args, options.strict), 0, 0, NULL,
     "degenerate triangles and non-manifold edges are errors"},
    {"--untrusted", NULL, NULL, LM_CMD_ALL, LM_OPT_FLAG, offsetof(lm_cli_args, options.untrusted), 0, 0, NULL,
     "a scene from a stranger: every file it names must lie inside its folder\n"
     "(else refused, naming it); by default one outside is read with a warning"},
    {"--sky", NULL, "L | R,G,B | R,G,B/R,G,B | FILE.hdr|.exr", LM_CMD_ALL, LM_OPT_CUSTOM, 0, 0, 0, lm_cli_opt_sky,
     "a sky around the scene, uniform (linear, the units of an emissive\n"
     "surface), zenith/horizon gradient or an equirectangular HDR image\n"
     "(docs/levels.md): lights through photons, the gather, the background and\n"
     "reflections; a file's extras.lmgi.sky gives one too"},
    {"--out", "-o", "DIR", OUTPUTS, LM_OPT_TEXT, offsetof(lm_cli_args, out_dir), 0, 0, NULL,
     "the folder the results go to (lmgi lists its files in DIR/.lmgi)"},
    {"--force", NULL, NULL, OUTPUTS | LM_CMD_BENCH | LM_CMD_VIEW, LM_OPT_FLAG, offsetof(lm_cli_args, force), 0, 0,
     NULL,
     "write into a non-empty --out DIR (or over a --json FILE, or view's\n"
     "--screenshot FILE) lmgi has not written before; lmgi never removes or\n"
     "replaces any other file"},
    {"--size", NULL, "WxH", LM_CMD_CHARTS | LM_CMD_RUN | LM_CMD_CHECK | LM_CMD_REFERENCE | LM_CMD_TRADEOFF |
     LM_CMD_BENCH | LM_CMD_VIEW, LM_OPT_CUSTOM, 0, 0, 0, lm_cli_opt_size,
     "picture size (charts: default 1024x768; run: 512x512; check: 128x128;\n"
     "tradeoff: 96x96; bench --soak: 32x32; view: the window, 640x480)"},
    {"--frames", NULL, "N", LM_CMD_RUN | LM_CMD_CHECK | LM_CMD_VIEW, LM_OPT_INT, offsetof(lm_cli_args, frames), 1,
     1000000, NULL,
     "frames to play at 30 per second of animation (default 60; check: the\n"
     "frame it checks; view: quit after N frames, the animation's time\n"
     "then N / 30 s rather than the clock's)"},
    {"--seed", NULL, "N", UPDATER | REFERENCE_USERS, LM_OPT_CUSTOM, 0, 0, 0, lm_cli_opt_seed,
     "the random sequences' seed (photons' scramble, the gather's strata, a light\n"
     "edit's factors, the reference's paths)"},
    {"--target-error", NULL, "E", REFERENCE_USERS, LM_OPT_FLOAT, offsetof(lm_cli_args, target_error), 1e-6, 0, NULL,
     "the reference's relative standard error per texel or pixel (default 0.02;\n"
     "tradeoff: 0.03)"},
    {"--samples", NULL, "N", REFERENCE_USERS, LM_OPT_INT, offsetof(lm_cli_args, samples), 1, 100000000, NULL,
     "the reference's samples per texel or pixel a pass"},
    {"--caustic-photons", NULL, "N", UPDATER | LM_CMD_REFERENCE, LM_OPT_INT,
     offsetof(lm_cli_args, caustic_photons), 1, 1 << 24, NULL,
     "caustic photons per light and mirror or glass node (default 16384);\n"
     "reference: its light-traced ones (1048576)"},
    {"--reference-caustic-photons", NULL, "N", REFERENCE_USERS, LM_OPT_INT,
     offsetof(lm_cli_args, ref_caustic_photons), 1, 1 << 24, NULL,
     "the reference's light-traced photons per light and mirror or glass node\n"
     "for its caustic part (default 1048576)"},
    {"--cache", NULL, "DIR", REFERENCE_USERS, LM_OPT_TEXT, offsetof(lm_cli_args, cache_dir), 0, 0, NULL,
     "where references are kept (default $LMGI_CACHE, else build/reference-cache)"},
    {"--no-cache", NULL, NULL, REFERENCE_USERS, LM_OPT_FLAG, offsetof(lm_cli_args, no_cache), 0, 0, NULL,
     "solve the reference again, keeping none"},
    {"--camera", NULL, "I", UPDATER | LM_CMD_REFERENCE, LM_OPT_INT, offsetof(lm_cli_args, camera), 0, 1000000, NULL,
     "the file's camera I (default: its first, else one framing the scene)"},
    {"--exr-every", NULL, "K", LM_CMD_RUN, LM_OPT_INT, offsetof(lm_cli_args, exr_every), 1, 1000000, NULL,
     "every K-th frame also as linear EXR (default 10)"},
    {"--tonemap", NULL, "T", LM_CMD_RUN | LM_CMD_REFERENCE | LM_CMD_VIEW, LM_OPT_CUSTOM, 0, 0, 0, lm_cli_opt_tonemap,
     "how PNGs show light: neutral (Khronos PBR Neutral, exposure from the\n"
     "median; the default) or clamp (linear, exposure from the 99th\n"
     "percentile); EXRs keep the linear numbers either way"},
    {"--in-order", NULL, NULL, UPDATER, LM_OPT_FLAG, offsetof(lm_cli_args, desc.in_order), 0, 0, NULL,
     "the photon stage before the gather and render, on one thread (the paper's\n"
     "order; default: its tracing and AIM refresh run on a second thread beside\n"
     "the render, after the gather, which then sees the previous frame's AIMs)"},
    {"--indirect", NULL, "P", UPDATER, LM_OPT_CUSTOM, 0, 0, 0, lm_cli_opt_indirect,
     "how frames get indirect light: lightmap (the default: AIMs, hemicube\n"
     "gather, IIM), or every visible pixel gathers the photons on the GPU (Mara\n"
     "et al. 2013): tiled (per screen tile, from shared memory), hashgrid (per\n"
     "pixel from a hash grid) or bruteforce (every photon against every pixel:\n"
     "the ground truth, small frames only)"},
    {"--effects", NULL, "LIST", UPDATER, LM_OPT_CUSTOM, 0, 0, 0, lm_cli_opt_effects,
     "effects left out (-) or kept (+) whatever the scene calls for: -shadows\n"
     "(no shadow maps), -indirect (no photon, AIM or gather work: direct light\n"
     "only), -reflections (no environment maps), -caustics (no caustic photons,\n"
     "no caustic pass)"},
    /* here the updater's knobs, stage by stage (knob_options.c, from include/lmgi_knobs.h) */
    {"", NULL, NULL, 0, LM_OPT_KNOBS, 0, 0, 0, NULL, NULL},
    {"--repeats", NULL, "N", LM_CMD_BENCH | LM_CMD_TRADEOFF, LM_OPT_INT, offsetof(lm_cli_args, repeats), 1, 100, NULL,
     "runs per measurement, the median is reported (default 3)"},
    {"--json", NULL, "FILE", LM_CMD_BENCH, LM_OPT_TEXT, offsetof(lm_cli_args, json_path), 0, 0, NULL,
     "also write the results as JSON"},
    {"--scaling", NULL, "FILE", LM_CMD_BENCH, LM_OPT_CUSTOM, 0, 0, 0, lm_cli_opt_scaling,
     "(repeatable) a scene for the growth table"},
    {"--soak", NULL, "N", LM_CMD_BENCH, LM_OPT_INT, offsetof(lm_cli_args, soak), 1, 100000000, NULL,
     "N updates of the looped animation (default scene scenes/cornell.glb):\n"
     "resident memory, update times and non-finite frame values per block"},
    {"--random-edits", NULL, "L", LM_CMD_BENCH, LM_OPT_INT, offsetof(lm_cli_args, random_edits), 1, 200, NULL,
     "bench --soak: a random edit before each update instead of the animation\n"
     "(nodes moved, lights and materials edited, lights added up to L and then\n"
     "added and removed; --seed picks them)"},
    {"--budget", NULL, "MS", LM_CMD_BENCH | LM_CMD_RUN | LM_CMD_VIEW, LM_OPT_FLOAT, offsetof(lm_cli_args, budget_ms),
     0, 10000, NULL,
     "run, bench --soak: each update's time budget in ms, shared by every stage\n"
     "(lmgi_update's budget_ms; frames.csv says which stage took the time and\n"
     "why); default 0: the fixed counts (--texels-per-frame texels, ...), the\n"
     "same lightmaps on every machine (view: default 16)"},
    {"--still", NULL, NULL, LM_CMD_VIEW, LM_OPT_FLAG, offsetof(lm_cli_args, still), 0, 0, NULL,
     "view: the animations stand at time 0 (the file's pose) instead of playing"},
    {"--watch", NULL, NULL, LM_CMD_VIEW, LM_OPT_FLAG, offsetof(lm_cli_args, watch), 0, 0, NULL,
     "view: follow the scene's file as it is saved (from Blender, on every save):\n"
     "node moves, materials and lights become edits, so only what changed is\n"
     "recomputed; a change of geometry loads the scene again, and says so"},
    {"--script", NULL, "EDITS.json", LM_CMD_VIEW, LM_OPT_TEXT, offsetof(lm_cli_args, script_path), 0, 0, NULL,
     "view: play an edit script (bench --edits' format, docs/bench.md) at its\n"
     "frames"},
    {"--screenshot", NULL, "FILE", LM_CMD_VIEW, LM_OPT_TEXT, offsetof(lm_cli_args, screenshot_path), 0, 0, NULL,
     "view: write the last frame to FILE (.png, or .exr for the linear\n"
     "numbers) when the window closes or --frames ends"},
    {"--edits", NULL, "SCRIPT.json", LM_CMD_BENCH | LM_CMD_TRADEOFF, LM_OPT_TEXT,
     offsetof(lm_cli_args, edits_path), 0, 0, NULL,
     "a scripted edit sequence (docs/bench.md); tradeoff: a comma-separated\n"
     "list of them, the lightmap's lag behind each edit per update budget"},
    {"--gather-scene", NULL, "FILE", 0, LM_OPT_TEXT, offsetof(lm_cli_args, gather_scene), 0, 0, NULL,
     "lmgi-dev bench: the ~133k-triangle Cornell box"},
    {"--half", NULL, NULL, BAKES, LM_OPT_FLAG, offsetof(lm_cli_args, half), 0, 0, NULL,
     "EXR lightmaps in 16-bit half floats"},
    {"--gltf", NULL, NULL, BAKES, LM_OPT_FLAG, offsetof(lm_cli_args, gltf), 0, 0, NULL,
     "also a glTF copy of the scene with the lightmap (docs/api.md)"},
    {"--accuracy", NULL, NULL, BAKES, LM_OPT_FLAG, offsetof(lm_cli_args, accuracy), 0, 0, NULL,
     "also DIR/accuracy.exr, the lightmaps' estimate of their own error (r: the\n"
     "lightmap's relative standard error, g: the AIM's, b: back-face share)"},
    {"--as-bake", NULL, NULL, LM_CMD_CHECK, LM_OPT_FLAG, offsetof(lm_cli_args, as_bake), 0, 0, NULL,
     "the lightmap 'lmgi bake' makes, not the one 'lmgi run' starts from: the\n"
     "bake's density (--texels' default, open surfaces not made coarser), its\n"
     "photons and its bounce pass"},
    {"--resume", NULL, NULL, LM_CMD_BAKE, LM_OPT_FLAG, offsetof(lm_cli_args, resume), 0, 0, NULL,
     "continue the bake that was cancelled or killed from DIR/bake.checkpoint\n"
     "(what its gather had finished), to the same lightmaps as one that never\n"
     "stopped"},
    {"--shard", NULL, "K/N", LM_CMD_BAKE, LM_OPT_CUSTOM, 0, 0, 0, lm_cli_opt_shard,
     "gather only share K of N of the bake's texels into DIR/part.checkpoint\n"
     "(a part, for lmgi merge; docs/levels.md, \"A bake in shards\"), with\n"
     "DIR/part.json: the scene's absolute path and the bake's options"},
    {"--checkpoint-seconds", NULL, "S", LM_CMD_BAKE, LM_OPT_FLOAT,
     offsetof(lm_cli_args, checkpoint_seconds), 0, 0, NULL,
     "at most one checkpoint every S seconds (default 10)"},
    {"--quick", NULL, NULL, LM_CMD_TRADEOFF, LM_OPT_FLAG, offsetof(lm_cli_args, quick), 0, 0, NULL,
     "fewer values per knob, 64x64, target error 0.04 (under 3 minutes on\n"
     "scenes/cornell.glb)"},
    {"--knobs", NULL, "LIST", LM_CMD_TRADEOFF, LM_OPT_TEXT, offsetof(lm_cli_args, knobs), 0, 0, NULL,
     "the knobs to sweep, comma-separated (default: all; docs/tradeoff.md)"},
    {"--frame-lag", NULL, NULL, LM_CMD_TRADEOFF, LM_OPT_FLAG, offsetof(lm_cli_args, frame_lag), 0, 0, NULL,
     "with --edits: the frame's lag too, against the path-traced reference of\n"
     "the edited scene"},
    {"--verbose", "-v", NULL, LM_CMD_ALL, LM_OPT_FLAG, offsetof(lm_cli_args, verbose), 0, 0, NULL,
     "more on stderr"},
    {"--quiet", "-q", NULL, LM_CMD_ALL, LM_OPT_FLAG, offsetof(lm_cli_args, quiet), 0, 0, NULL,
     "less on stderr; where stderr is not a terminal, progress comes as a line\n"
     "every 5 s (LMGI_PROGRESS_SECONDS)"},

    {NULL, NULL, NULL, 0, LM_OPT_FLAG, 0, 0, 0, NULL, NULL},
};

const lm_cli_command *lm_cli_find_command(const char *name)
{
    for (const lm_cli_command *c = lm_cli_commands; name && c->name; c++)
        if (!strcmp(c->name, name))
            return c;
    return NULL;
}

/* Every option in the help's order, NULL-terminated: the table's, with the updater's knobs that have a
 * flag where its LM_OPT_KNOBS entry stands. */
static const lm_cli_option *const *all_options(void)
{
    static const lm_cli_option *all[192];
    if (!all[0]) {
        int n = 0;
        for (const lm_cli_option *o = lm_cli_options; o->name && n < 190; o++) {
            if (o->kind != LM_OPT_KNOBS)
                all[n++] = o;
            for (int k = 0; o->kind == LM_OPT_KNOBS && k < lm_cli_knob_option_count && n < 190; k++)
                if (lm_cli_knob_options[k].name)
                    all[n++] = &lm_cli_knob_options[k];
        }
    }
    return all;
}

const lm_cli_option *lm_cli_find_option(const char *word)
{
    for (const lm_cli_option *const *o = all_options(); *o; o++)
        if (!strcmp((*o)->name, word) || ((*o)->alias && !strcmp((*o)->alias, word)))
            return *o;
    return NULL;
}

/* Levenshtein distance, capped (longer words are not misspellings of each other anyway). */
static int distance(const char *a, const char *b)
{
    enum { MAX = 64 };
    size_t n = strlen(a), m = strlen(b);
    if (n >= MAX || m >= MAX)
        return MAX;
    int row[MAX + 1];
    for (size_t j = 0; j <= m; j++)
        row[j] = (int)j;
    for (size_t i = 1; i <= n; i++) {
        int diag = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= m; j++) {
            int up = row[j], best = diag + (a[i - 1] != b[j - 1]);
            best = up + 1 < best ? up + 1 : best;
            best = row[j - 1] + 1 < best ? row[j - 1] + 1 : best;
            diag = up;
            row[j] = best;
        }
    }
    return row[m];
}

const lm_cli_option *lm_cli_nearest_option(const char *word, unsigned commands)
{
    const lm_cli_option *best = NULL;
    int best_d = 1 << 30;
    for (const lm_cli_option *const *o = all_options(); *o; o++) {
        if (!((*o)->commands & commands))
            continue;
        int d = distance(word, (*o)->name);
        if (d < best_d)
            best = *o, best_d = d;
    }
    /* a slip of a key or two, or a third of a long name */
    int near = (int)strlen(word) / 3 > 2 ? (int)strlen(word) / 3 : 2;
    return best && best_d <= near ? best : NULL;
}

void lm_cli_command_list(unsigned commands, char *buf, size_t size)
{
    int n = 0, total = 0;
    for (const lm_cli_command *c = lm_cli_commands; c->name; c++)
        total += (commands & c->bit) != 0;
    size_t used = 0;
    buf[0] = '\0';
    for (const lm_cli_command *c = lm_cli_commands; c->name && used < size; c++) {
        if (!(commands & c->bit))
            continue;
        const char *sep = n == 0 ? "" : n == total - 1 ? " and " : ", ";
        int w = snprintf(buf + used, size - used, "%s%s", sep, c->name);
        used += w > 0 ? (size_t)w : 0;
        n++;
    }
}

/* The text's lines, the first after `first` columns already printed, the rest indented by `indent`. */
static void print_lines(FILE *f, const char *text, int first, int indent)
{
    int col = first;
    for (const char *p = text; *p;) {
        size_t n = strcspn(p, "\n");
        fprintf(f, "%*s%.*s\n", col, "", (int)n, p);
        col = indent;
        p += n + (p[n] == '\n');
    }
}

#define OPTION_COLUMN 20

static void print_option(FILE *f, const lm_cli_option *o, int with_commands)
{
    char head[128];
    int w = snprintf(head, sizeof head, "  %s%s%s%s%s", o->alias ? o->alias : "", o->alias ? ", " : "", o->name,
                     o->arg ? " " : "", o->arg ? o->arg : "");
    fputs(head, f);
    int pad = w < OPTION_COLUMN - 1 ? OPTION_COLUMN - w : 1;
    if (w > 40) { /* a long value list: the text on the next line */
        fputc('\n', f);
        pad = OPTION_COLUMN;
    }
    print_lines(f, o->help, pad, OPTION_COLUMN);
    if (with_commands && o->commands != LM_CMD_ALL) {
        char list[160];
        lm_cli_command_list(o->commands, list, sizeof list);
        fprintf(f, "%*s[%s]\n", OPTION_COLUMN, "", list);
    }
}

void lm_cli_print_help(FILE *f)
{
    fprintf(f, "usage: lmgi COMMAND [OPTIONS] SCENE\n\ncommands (lmgi help COMMAND, or lmgi COMMAND --help: its "
               "options alone):\n");
    for (const lm_cli_command *c = lm_cli_commands; c->name; c++) {
        fprintf(f, "  %s\n", c->usage);
        print_lines(f, c->help, 6, 6);
    }
    fprintf(f, "  help [COMMAND]\n      this text, or the command's\n\noptions (the commands that take "
               "each in brackets, where not every one):\n");
    for (const lm_cli_option *const *o = all_options(); *o; o++)
        if ((*o)->commands)
            print_option(f, *o, 1);
}

void lm_cli_print_command_help(FILE *f, const lm_cli_command *c)
{
    fprintf(f, "usage: lmgi %s [OPTIONS]\n\n", c->usage);
    print_lines(f, c->help, 0, 0);
    fprintf(f, "\noptions:\n");
    for (const lm_cli_option *const *o = all_options(); *o; o++)
        if ((*o)->commands & c->bit)
            print_option(f, *o, 0);
}
