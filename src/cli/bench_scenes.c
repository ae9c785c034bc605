/* Every scene against the reference (bench_scenes.h), through lmgi_check. */
#include "bench_scenes.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "progress.h"
#include "run_cmd.h"
#include "surface_error.h"

/* scenes/many_rooms.glb is left out: its reference took over 10 minutes here. */
static const char *SCENES[] = {
    "scenes/cornell.glb",
    "scenes/two_rooms.glb",
    "../shared/scenes/cornell-box/CornellBox.glb",
    "../shared/scenes/room/IrradianceVolumeExample.glb",
    "../shared/scenes/depth-of-field/DepthOfFieldExample.glb",
    "../shared/scenes/mixed-lighting/MixedLightingExample.gltf",
    "../shared/scenes/cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf",
    "../shared/scenes/occlusion-room/room_lit.glb", /* the two shared levels (issue 33, item 4) */
    "../shared/scenes/truck-town/town_lit.gltf",
};

#define SIZE 96
#define REF_ERROR 0.03f /* looser targets read rare bright paths short (docs/reference.md) */

static double lum(const double c[3]) { return c[0] + c[1] + c[2]; }

/* The surface of at least 100 pixels furthest from the reference in any channel (lm_cli_surface_channels),
 * after how many of them are within 5% in every channel. */
static void worst_surface(const lmgi_scene *sc, const lmgi_check_result *c, char *out, size_t size)
{
    lm_cli_channel_check ch;
    lm_cli_surface_channels(sc, c, 0.05, &ch);
    if (ch.worst_surface < 0) {
        snprintf(out, size, "%d/%d -", ch.within, ch.surfaces);
        return;
    }
    const lmgi_check_surface *f = &c->surfaces[ch.worst_surface];
    snprintf(out, size, "%d/%d %c %+.1f%% %s/%s", ch.within, ch.surfaces, "RGB"[ch.worst_channel],
             100.0 * ch.worst_ratio, lmgi_node_name(sc, f->node), lmgi_material_name(sc, f->material));
}

static void check_one(lmgi_context *ctx, const char *path)
{
    lmgi_options o;
    lmgi_options_init(&o);
    lm_cli_run_options(&o, 0); /* as lmgi run and lmgi check load it */
    lmgi_scene *sc = NULL;
    lmgi_error err;
    if (lmgi_load(path, &o, &sc, &err) != LMGI_OK) {
        printf("%-34s error: %s\n", lm_cli_base_name(path), err.message);
        return;
    }
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.frame.width = d.frame.height = SIZE;
    d.photons.count = lm_cli_run_photons(sc); /* as lmgi check (lm_cli_run_desc) */
    lmgi_reference_desc rd;
    memset(&rd, 0, sizeof rd);
    rd.target_error = REF_ERROR;
    lmgi_check_result c;
    double t0 = lm_cli_now();
    if (lmgi_check(ctx, sc, &d, &rd, 1, &c, &err) != LMGI_OK) {
        printf("%-34s error: %s\n", lm_cli_base_name(path), err.message);
    } else if (lum(c.reference_mean) <= 0.0) {
        printf("%-34s no light reaches the camera (the file has no light)\n", lm_cli_base_name(path));
        lmgi_check_free(&c);
    } else {
        char worst[160];
        worst_surface(sc, &c, worst, sizeof worst);
        printf("%-34s %6.3f %6.3f %6.3f %8.4f  %-44s %6.0f s\n", lm_cli_base_name(path), c.ratio[0], c.ratio[1],
               c.ratio[2], c.rel_rmse, worst, lm_cli_now() - t0);
        lmgi_check_free(&c);
    }
    fflush(stdout);
    lmgi_free(sc);
}

void lm_cli_bench_scenes(void)
{
    const char *const *files = SCENES;
    int count = (int)(sizeof SCENES / sizeof *SCENES);
    printf("\nevery scene against the reference: `lmgi run`'s defaults, one frame at %dx%d, reference at %.2f "
           "(cached; lmgi check SCENE for the per-surface table)\n", SIZE, SIZE, (double)REF_ERROR);
    printf("%-34s %-20s %8s  %-44s %8s\n", "scene", "frame / ref (R G B)", "rel RMSE",
           "within 5% per channel, furthest off", "time");
    lmgi_context *ctx = NULL;
    lmgi_error err;
    if (lmgi_context_create(NULL, &ctx, &err) != LMGI_OK) {
        printf("error: %s\n", err.message);
        return;
    }
    for (int i = 0; i < count; i++) {
        if (access(files[i], R_OK) != 0)
            printf("%-34s skipped (not found: %s)\n", lm_cli_base_name(files[i]), files[i]);
        else
            check_one(ctx, files[i]);
    }
    lmgi_context_free(ctx);
}
