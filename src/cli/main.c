/* The lmgi command. */
#include <lmgi.h>

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "args.h"
#include "bake_cmd.h"
#include "bench.h"
#include "check_cmd.h"
#include "out_dir.h"
#include "reference_cmd.h"
#include "run_cmd.h"
#include "scene_load.h"
#include "tradeoff_cmd.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: lmgi COMMAND [OPTIONS] SCENE\n"
            "\n"
            "commands:\n"
            "  info SCENE             counts, materials by class, lights, surfaces, charts, atlas, and which\n"
            "                         effects the scene calls for and why\n"
            "  charts SCENE --out DIR write DIR/atlas.png (charts coloured, free space black) and DIR/surfaces.png\n"
            "                         (the scene from its camera, each surface a flat colour)\n"
            "  run SCENE --out DIR    the whole frame loop over the scene's animations (photons, AIMs, IIM\n"
            "                         gather, direct light, composite): DIR/frame_NNNN.png (every K-th also\n"
            "                         .exr), iim.exr/png, aim.exr/png and frames.csv (work and ms per stage)\n"
            "  bake SCENE --out DIR   the full solution for the scene as it is (every photon, AIM and texel),\n"
            "                         with a progress bar and the time left (Ctrl-C or SIGTERM cancels, keeping\n"
            "                         what it finished for --resume; a failed bake leaves the last lightmaps):\n"
            "                         DIR/lightmap.exr\n"
            "                         (irradiance, alpha = valid), lightmap.png (a preview), aim.exr; --gltf:\n"
            "                         also NAME.gltf, the scene for engines with TEXCOORD_1 = lightmap UVs\n"
            "  check SCENE            one frame of 'run' (same options) against the path-traced reference:\n"
            "                         frame / reference per visible surface and over the frame, and the\n"
            "                         relative RMSE (default --size 128x128; --out DIR: the two EXRs)\n"
            "  reference SCENE --out DIR  path-traced ground truth per texel and per pixel, split by light\n"
            "                         path: direct, iim, caustic (light-traced), lost; the picture also\n"
            "                         emission, indirect and reflections (DIR/reference_*.exr)\n"
            "  bench [SCENE...]       time load, surface split, atlas (unwrap, pack, texel table) and BVH build;\n"
            "                         --scaling FILE (repeatable) adds a growth table; with no SCENE also the\n"
            "                         update time budget and every scene's default frame against the\n"
            "                         reference (photon tracing and the gather: lmgi-dev bench, make bench)\n"
            "  bench --edits SCRIPT.json SCENE  a scripted edit sequence through the updater: per-update times,\n"
            "                         budget overruns, each edit's update lag and the surfaces it rewrote in\n"
            "                         its reach and outside it (docs/bench.md; --json FILE)\n"
            "  bench --soak N [SCENE]  N updates of the looped animation (default scenes/cornell.glb, 32 x 32):\n"
            "                         resident memory, update times and non-finite frame values per block\n"
            "  tradeoff SCENE... --out DIR  what accuracy costs in time: every knob that trades one for the\n"
            "                         other swept around the defaults (--knobs LIST: only those), each\n"
            "                         setting's stage times (medians of --repeats) and the error of its AIM,\n"
            "                         IIM and frame (--size, default 96x96) against the reference (to\n"
            "                         --target-error, default 0.03); --quick: fewer values, 64x64, 0.04\n"
            "                         (under 3 minutes on scenes/cornell.glb): DIR/report.html\n"
            "                         (plots, the Pareto front), tradeoff.csv/.json (docs/tradeoff.md);\n"
            "                         --edits SCRIPT,...: the lightmap's lag behind each scripted edit per\n"
            "                         update budget (lag.csv); --frame-lag: the frame's too, against the\n"
            "                         path-traced reference of the edited scene\n"
            "  help                   this text\n"
            "\n"
            "options:\n"
            "  --texel-size S   world units per lightmap texel (default: from --texels)\n"
            "  --texels N       texels the derived texel size aims at (default 65536; 'run': 90 x\n"
            "                   --texels-per-frame, so that its IIM is refreshed in full every 3 s)\n"
            "  --gutter N       empty texels between charts (default 0)\n"
            "  --use-uv1        use the file's TEXCOORD_1 as lightmap UVs instead of unwrapping\n"
            "  --cone DEG       max normal deviation inside one surface (default 30)\n"
            "  --max-atlas N    largest atlas side; the texel size grows to fit (default 8192)\n"
            "  --strict         degenerate triangles and non-manifold edges are errors\n"
            "  --untrusted      a scene from a stranger: every file it names must lie inside its folder\n"
            "                   (else refused, naming it); by default one outside is read with a warning\n"
            "  --size WxH       picture size for 'charts' (default 1024x768) and 'run' (default 512x512)\n"
            "  --frames N       'run': frames to play at 30 per second of animation (default 60)\n"
            "  --texels-per-frame N  'run': IIM texels gathered per frame (default 20)\n"
            "  --hemicube R     'run': hemicube plane pixels per side (default 32)\n"
            "  --hemicube-samples N 'run': AIM lookups per hemicube pixel, 1 or 4 (default 4: no banding)\n"
            "  --hemicube-coverage N 'run': coverage samples per hemicube pixel, 1 to 16 within the GL's\n"
            "                   limit (llvmpipe: 4; default: 4 when emissive triangles are drawn into the\n"
            "                   hemicubes, whose small images alias, else 1)\n"
            "  --emitter-light M 'run': closed (the light of emissive triangles in closed form, visibility\n"
            "                   by shadow rays: no plaid, no coverage samples needed) or drawn into the\n"
            "                   hemicubes (default: closed when the scene has 1 to 64 emissive triangles)\n"
            "  --emitter-rays N 'run': shadow rays per emissive triangle and texel (default 32)\n"
            "  --tonemap T      'run': how PNGs show light: neutral (Khronos PBR Neutral, exposure from the\n"
            "                   median; the default) or clamp (linear, exposure from the 99th percentile);\n"
            "                   EXRs keep the linear numbers either way\n"
            "  --in-order       'run': the photon stage before the gather and render, on one thread (the\n"
            "                   paper's order; default: its tracing and AIM refresh run on a second thread\n"
            "                   beside the render, after the gather, which then sees the previous frame's\n"
            "                   AIMs)\n"
            "  --enlargement A  'run': hemicube plane half-side a (default 2)\n"
            "  --rim-samples K  'run': rays per texel for the light of the hemisphere's rim outside the plane\n"
            "                   (default 64); 0: the paper's 1 / F(a) extrapolation (surfaces 10-30%% off\n"
            "                   where a bright spot lies near their horizon)\n"
            "  --aim-direct M   'run', 'check', 'bake': where the AIMs' direct light comes from: photons\n"
            "                   (the default: first hits, the paper's form, blurred by the estimate's\n"
            "                   radius), emitters (emissive triangles' light computed per texel: sharp\n"
            "                   contact shadows, about 5x slower AIMs) or all (punctual lights' too)\n"
            "  --indirect P     'run', 'check': how frames get indirect light: lightmap (the default: AIMs,\n"
            "                   hemicube gather, IIM), or every visible pixel gathers the photons on the\n"
            "                   GPU (Mara et al. 2013): tiled (per screen tile, from shared memory),\n"
            "                   hashgrid (per pixel from a hash grid) or bruteforce (every photon against\n"
            "                   every pixel: the ground truth, small frames only)\n"
            "  --photon-tile N, --photon-chunk N, --photon-stochastic K, --photon-radius R  'run', 'check'\n"
            "                   with --indirect tiled: tile side (4, 8, 16 or 32; default 16), photons per\n"
            "                   shared-memory load (64 to 512; default 256), k: each pixel reads 1/k^2 of\n"
            "                   its tile's photons, then an edge-aware k x k average (1 to 4; default 1: all);\n"
            "                   the kernel radius (default: the disc of --nearest photons)\n"
            "  --effects LIST   'run', 'check', 'bake': effects left out (-) or kept (+) whatever the scene\n"
            "                   calls for: -shadows (no shadow maps), -indirect (no photon, AIM or gather\n"
            "                   work: direct light only), -reflections (no environment maps), -caustics\n"
            "                   (no caustic photons, no caustic pass)\n"
            "  --reflection-size N 'run': texels per side of the environment cube map of each mirror, glossy\n"
            "                   or glass node (default 128; 0: no reflections, mirrors black)\n"
            "  --reflection-faces N 'run': most environment map faces re-rendered a frame, those whose view\n"
            "                   changed longest ago first, after all of them at the first frame (default 1;\n"
            "                   a still scene renders none)\n"
            "  --caustic-photons N 'run', 'check', 'bake': caustic photons per light and mirror or glass node\n"
            "                   (default 16384); 'reference': the reference's light-traced ones (1048576)\n"
            "  --caustic-retrace F 'run': share of the caustic photons re-traced a frame while anything\n"
            "                   moves (default 0.25; a moved light or mirror/glass node re-traces its own)\n"
            "  --caustic-filter K 'run': k of the caustics' (2k+1)^2 cone filter, 0 to 8 (default 3)\n"
            "  --caustic-space S 'run': screen (default, the paper's filter) or world (by world distance)\n"
            "  --caustic-tile N 'run': screen tile side of the caustics' occlusion queries (default 32)\n"
            "  --gather-scheme S 'run', 'bake', 'check': hemicubes by viewports, instanced or layered\n"
            "                   (layered has no multisampled target: coverage 1 unless given), or rays (Embree\n"
            "                   over each texel's hemisphere, no hemicube); default: rays above 20,000\n"
            "                   triangles on a software GL, else viewports (docs/gather.md, \"Rays\")\n"
            "  --reference-caustic-photons N 'check': the reference's light-traced photons per light and\n"
            "                   mirror or glass node for its caustic part (default 1048576)\n"
            "  --exr-every K    'run': every K-th frame also as linear EXR (default 10)\n"
            "  --repeats N      'bench': runs per scene, the median is reported (default 3)\n"
            "  --json FILE      'bench': also write the results as JSON\n"
            "  --half           'bake': EXR lightmaps in 16-bit half floats\n"
            "  --gltf           'bake': also a glTF copy of the scene with the lightmap (docs/api.md)\n"
            "  --accuracy       'bake': also DIR/accuracy.exr, the lightmaps' estimate of their own error (r: the\n"
            "                   lightmap's relative standard error, g: the AIM's, b: back-face share)\n"
            "  --resume         'bake': continue the bake that was cancelled or killed from DIR/bake.checkpoint\n"
            "                   (what its gather had finished), to the same lightmaps as one that never stopped\n"
            "  --checkpoint-seconds S 'bake': at most one checkpoint every S seconds (default 10)\n"
            "  --sky L | R,G,B | R,G,B/R,G,B | FILE.hdr|.exr  every command: a sky around the scene, uniform\n"
            "                   (linear, the units of an emissive surface), zenith/horizon gradient or an\n"
            "                   equirectangular HDR image (docs/levels.md): lights through photons, the\n"
            "                   gather, the background and reflections; a file's extras.lmgi.sky gives one too\n"
            "  --force          write into a non-empty --out DIR lmgi has not written before; lmgi lists\n"
            "                   its files in DIR/.lmgi and never removes or replaces any other file\n"
            "  -v, -q           more / less on stderr; where stderr is not a terminal, progress comes as a\n"
            "                   line every 5 s (LMGI_PROGRESS_SECONDS)\n");
}

static int load(const lm_cli_args *a, lmgi_scene **sc)
{
    if (a->file_count != 1) {
        fprintf(stderr, "lmgi: expected exactly one scene file, got %d (see 'lmgi help')\n", a->file_count);
        return 2;
    }
    return lm_cli_load_scene(a->files[0], &a->options, 0, sc) ? 0 : 1;
}

static int cmd_info(const lm_cli_args *a)
{
    lmgi_scene *sc = NULL;
    int rc = load(a, &sc);
    if (rc)
        return rc;
    lmgi_print_info(sc, stdout);
    lmgi_free(sc);
    return 0;
}

static int cmd_charts(const lm_cli_args *a)
{
    if (!a->out_dir) {
        fprintf(stderr, "lmgi: charts needs --out DIR\n");
        return 2;
    }
    lmgi_scene *sc = NULL;
    int rc = load(a, &sc);
    if (rc)
        return rc;
    lmgi_output *o = lm_cli_open_out(a, "charts");
    if (!o) {
        lmgi_free(sc);
        return 1;
    }
    lmgi_error err;
    if (lmgi_write_charts(sc, lmgi_output_folder(o), a->width, a->height, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        rc = 1;
    } else if (!a->quiet) {
        lmgi_info in;
        lmgi_get_info(sc, &in);
        printf("wrote %s/atlas.png (%d x %d, %d charts, %.1f%% used) and %s/surfaces.png (%d surfaces)\n",
               a->out_dir, in.atlas_width, in.atlas_height, in.charts, 100.0 * (double)in.utilization, a->out_dir,
               in.surfaces);
    }
    lmgi_free(sc);
    return lm_cli_close_out(o, rc);
}

int main(int argc, char **argv)
{
    lm_cli_args a;
    int rc = lm_cli_start(argc, argv, usage, &a);
    if (rc >= 0)
        return rc;
    /* A file that outgrows the file-size limit (ulimit -f) is then a write error naming the file, as a
     * full disk is, instead of a signal that kills the run. */
    signal(SIGXFSZ, SIG_IGN);
    const char *cmd = argv[1];
    static const struct {
        const char *name;
        int (*run)(const lm_cli_args *a);
    } commands[] = {{"info", cmd_info}, {"charts", cmd_charts}, {"reference", lm_cli_reference}, {"run", lm_cli_run},
                    {"bake", lm_cli_bake}, {"check", lm_cli_check}, {"bench", lm_cli_bench},
                    {"tradeoff", lm_cli_tradeoff}};
    for (size_t i = 0; i < sizeof commands / sizeof *commands; i++)
        if (!strcmp(cmd, commands[i].name)) {
            rc = commands[i].run(&a);
            /* what it printed is part of its result: `lmgi info > /dev/full` is not a success */
            if ((fflush(stdout) != 0 || ferror(stdout)) && rc == 0) {
                fprintf(stderr, "lmgi: error: cannot write the output (%s)\n", strerror(errno));
                rc = 1;
            }
            return rc;
        }
    fprintf(stderr, "lmgi: unknown command '%s'\n\n", cmd);
    usage(stderr);
    return 2;
}
