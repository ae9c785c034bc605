/* Every scene against the reference (bench_scenes.h). */
#include "bench_scenes.h"

#include <math.h>
#include <stdio.h>
#include <unistd.h>

#include "../core/timing.h"
#include "../api/frame_check.h"
#include "bench.h"

/* scenes/many_rooms.glb is left out: its reference took over 10 minutes here. */
static const char *SCENES[] = {
    "scenes/cornell.glb",
    "scenes/two_rooms.glb",
    "../shared/scenes/cornell-box/CornellBox.glb",
    "../shared/scenes/room/IrradianceVolumeExample.glb",
    "../shared/scenes/depth-of-field/DepthOfFieldExample.glb",
    "../shared/scenes/mixed-lighting/MixedLightingExample.gltf",
    "../shared/scenes/cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf",
};

#define SIZE 96
#define REF_ERROR 0.03f /* looser targets read rare bright paths short (docs/reference.md) */

static double lum(const double c[3]) { return c[0] + c[1] + c[2]; }

/* The surface of MIN pixels furthest from the reference, relative to max(its mean, the frame's). */
static void worst_surface(const lmgi_scene *sc, const lm_frame_check *c, char *out, size_t size)
{
    double mean = lum(c->lit.ref) / (c->lit.pixels ? c->lit.pixels : 1), worst = -1.0;
    snprintf(out, size, "-");
    for (int s = 0; s < c->surface_count; s++) {
        const lm_check_sum *sum = &c->surface[s];
        if (sum->pixels < 100)
            continue;
        double f = lum(sum->frame) / sum->pixels, r = lum(sum->ref) / sum->pixels;
        double d = fabs(f - r) / fmax(fmax(r, mean), 1e-30);
        if (d > worst) {
            worst = d;
            snprintf(out, size, "%+.1f%% %s/%s", r > 0.0 ? 100.0 * (f / r - 1.0) : 0.0,
                     sc->scene->nodes[sc->surfaces.surfaces[s].node].name,
                     sc->scene->materials[sc->surfaces.surfaces[s].material].name);
        }
    }
}

static void check_one(const char *path)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = lm_frame_loop_atlas_texels(LM_IIM_DEFAULT_TEXELS_PER_FRAME);
    lmgi_scene *sc = NULL;
    lmgi_error lerr;
    if (lmgi_load(path, &o, &sc, &lerr) != LMGI_OK) {
        printf("%-34s error: %s\n", lm_cli_base_name(path), lerr.message);
        return;
    }
    lm_frame_loop_settings ls;
    lm_frame_loop_settings_default(&ls);
    ls.width = ls.height = SIZE;
    lm_ref_settings rs;
    lm_ref_settings_default(&rs);
    rs.target_error = REF_ERROR;
    rs.progress = 0;
    lm_frame_check c;
    lm_error err;
    double t0 = lm_now();
    if (lm_frame_check_run(sc, &ls, &rs, 1, &c, &err) != LM_OK) {
        printf("%-34s error: %s\n", lm_cli_base_name(path), err.msg);
    } else if (lum(c.lit.ref) <= 0.0) {
        printf("%-34s no light reaches the camera (the file has no light)\n", lm_cli_base_name(path));
        lm_frame_check_free(&c);
    } else {
        char worst[160];
        worst_surface(sc, &c, worst, sizeof worst);
        printf("%-34s %6.3f %6.3f %6.3f %8.4f  %-36s %6.0f s\n", lm_cli_base_name(path), lm_check_ratio(&c.lit, 0),
               lm_check_ratio(&c.lit, 1), lm_check_ratio(&c.lit, 2), c.rel_rmse, worst, lm_now() - t0);
        lm_frame_check_free(&c);
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
    printf("%-34s %-20s %8s  %-36s %8s\n", "scene", "frame / ref (R G B)", "rel RMSE", "surface furthest off",
           "time");
    for (int i = 0; i < count; i++) {
        if (access(files[i], R_OK) != 0)
            printf("%-34s skipped (not found: %s)\n", lm_cli_base_name(files[i]), files[i]);
        else
            check_one(files[i]);
    }
}
