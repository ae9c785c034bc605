/* lmgi-dev: the developer's commands that look inside the library (they include src/ headers, which the
 * lmgi command may not): the photon stage alone, and the photon and gather benchmarks measured against
 * raw Embree and the paper's tables. Options as the lmgi command's (src/cli/args.h). */
#include <lmgi.h>

#include <stdio.h>
#include <string.h>

#include "../../src/cli/args.h"
#include "bench_caustics.h"
#include "bench_gather.h"
#include "bench_photons.h"
#include "bench_tiled.h"
#include "photons_cmd.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: lmgi-dev photons SCENE --out DIR [--frames N] [photon options]\n"
               "         the photon stage alone over the scene's animations: AIM atlas, a view with AIMs, stats.csv\n"
               "       lmgi-dev bench [--gather-scene FILE]\n"
               "         photon tracing against raw Embree, the final gather against the paper's Table 2, the\n"
               "         caustic pass and reflections against the paper's section 5 figures, the per-pixel\n"
               "         photon gathers against Mara et al.'s (2013)\n"
               "         (FILE: the ~133k-triangle Cornell box of `build/gen_scenes --cornell-cells 255`)\n"
               "       lmgi-dev bench-caustics\n"
               "         the caustics and reflections part alone\n"
               "       lmgi-dev bench-levels SCENE...\n"
               "         the gather's ms per texel on each scene against the first (triangles, proxy triangles)\n"
               "       lmgi-dev bench-tiled\n"
               "         the per-pixel photon gathers alone (tiled, stochastic, hash grid, brute force)\n"
               "options and their meaning: `lmgi help`\n");
}

int main(int argc, char **argv)
{
    lm_cli_args a;
    int rc = lm_cli_start(argc, argv, usage, 0, &a);
    if (rc >= 0)
        return rc;
    if (!strcmp(argv[1], "photons"))
        return lm_dev_photons(&a);
    if (!strcmp(argv[1], "bench")) {
        lm_dev_bench_photons();
        lm_dev_bench_gather(a.gather_scene);
        lm_dev_bench_caustics();
        lm_dev_bench_tiled();
        return 0;
    }
    if (!strcmp(argv[1], "bench-caustics")) {
        lm_dev_bench_caustics();
        return 0;
    }
    if (!strcmp(argv[1], "bench-levels")) {
        lm_dev_bench_levels(a.files, a.file_count);
        return 0;
    }
    if (!strcmp(argv[1], "bench-tiled")) {
        lm_dev_bench_tiled();
        return 0;
    }
    fprintf(stderr, "lmgi-dev: unknown command '%s'\n\n", argv[1]);
    usage(stderr);
    return 2;
}
