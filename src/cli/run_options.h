#ifndef LM_CLI_RUN_OPTIONS_H
#define LM_CLI_RUN_OPTIONS_H
/* The loader's options as `lmgi run` and `lmgi check` load a scene (and `make bench`'s scene table, and
 * the tests that check what those commands show): a lightmap density the texel budget keeps up with, and
 * open surfaces coarser. Needs nothing but the public headers. */
#include <lmgi.h>
#include <lmgi_tools.h>
/* Texels each wall or floor gets at least at run's density (lmgi_options.wall_texels) */
#define LM_CLI_RUN_WALL_TEXELS 16
/* The share of the level's worth per area under which an open surface's texels are coarsened, at run's
 * density and any other 'lmgi run' and 'lmgi check' derive (lmgi_options.open_need; docs/charts.md, "Open
 * surfaces"). Not the library's default, nor bake's, until the atlas packs a level's many small charts
 * tighter: truck-town's atlas at 2,000 to 1,000,000 texels is then
 * 26-45% used, under issue 30's 60%. */
#define LM_CLI_RUN_OPEN_NEED 0.25f
/* Where o gives no texel size or count: the density that texels_per_frame (0: the default) keeps up with
 * (lmgi_atlas_texels_for) and LM_CLI_RUN_WALL_TEXELS on a wall. Where it gives no open_need:
 * LM_CLI_RUN_OPEN_NEED. */
void lm_cli_run_options(lmgi_options *o, int texels_per_frame);
#endif
