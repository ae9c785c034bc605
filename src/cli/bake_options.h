#ifndef LM_CLI_BAKE_OPTIONS_H
#define LM_CLI_BAKE_OPTIONS_H
/* The solution `lmgi bake` makes, beyond the loader's own default density: its photons and bounce passes
 * (and `lmgi check --as-bake`, which shows that lightmap against the reference, and the tests that check
 * it). Needs nothing but the public header. */
#include <lmgi.h>
/* A bake's photons when --photons and --per-group are not given: LM_CLI_BAKE_PHOTONS_PER_TEXEL a texel of
 * its atlas, within [MIN, MAX]. Its AIMs are as fine as its atlas, and an N-nearest estimate of fewer photons
 * than texels spans several of them: the sunlit living room baked at 65,536 texels from the updater's
 * 46,080 photons read 3-8% bright on its walls and 25-58% on its furniture, mottled, and from 270,716 within
 * 3% and 7%; at 4 a texel the shared Cornell box's floor by the small box's foot read a contact shadow
 * blurred by the kernel, its face towards the open front 2% bright in its first 3 mm and one texel by its
 * corner 12% (against a reference of a million paths a texel), at 16 within 6% (docs/photons.md, "A bake's
 * photons"). Tracing and estimating them costs a few percent of the gather (the box: 0.15 + 0.66 s at 4 a
 * texel, 0.55 + 0.84 s at 16, of a 27 s bake). */
#define LM_CLI_BAKE_PHOTONS_PER_TEXEL 16u
/* `lmgi run` and `lmgi check`'s photons where more than the updater's floor (lm_cli_run_desc): a texel's
 * share as a bake took it before it took 16, since a run traces them again as it updates */
#define LM_CLI_RUN_PHOTONS_PER_TEXEL 4u
#define LM_CLI_BAKE_PHOTONS_MIN 46080u
#define LM_CLI_BAKE_PHOTONS_MAX 1048576u
/* per_texel photons for each of texels, within [MIN, MAX] */
uint32_t lm_cli_photons_for(uint32_t texels, uint32_t per_texel);
uint32_t lm_cli_bake_photons(uint32_t texels);
/* A bake's bounce passes when --bounce-passes is not given (docs/gather.md, "Bounce passes"): the first
 * solution gathered once more, its bounced light read from the first gather's lightmap. The photons'
 * noise then reaches the lightmap through one more gather: the sunlit living room at a bake's settings
 * read 7, 8 and 8 of its 8 surfaces within 5% for seeds 0-2 without, 8, 8 and 8 with one pass, for about
 * twice the gather's time. Not in a shard (its merge makes them); under a hemicube gather there are none;
 * none where the level has more than LM_CLI_BAKE_PASS_MAX_LIGHTS point and spot lights, each of which the
 * pass takes at every ray's hit by a shadow ray (45 made a generated level of 994k triangles 4.2x as long
 * to bake). */
#define LM_CLI_BAKE_BOUNCE_PASSES 1
#define LM_CLI_BAKE_PASS_MAX_LIGHTS 8
/* A bake's parts a side for the AIMs' computed direct light when --direct-parts is not given (docs/aim.md,
 * "Averaged over the texel"). The rays gather reads its far hits' emitter light from their AIM texels, and
 * near a lamp that lights a ceiling edge-on 2 x 2 parts missed the light's fall-off within a texel:
 * cornell-suzanne's baked atlas read 0.979 of the reference with 2 x 2 and 1.001 with 4 x 4. */
#define LM_CLI_BAKE_DIRECT_PARTS 4
/* d (from the command's options) given a bake's photons where neither --photons nor --per-group set them, its
 * AIMs' direct parts where --direct-parts did not, and its bounce passes where --bounce-passes did not and
 * the bake is `whole` (not a shard, whose passes are its merge's) with at most LM_CLI_BAKE_PASS_MAX_LIGHTS
 * point and spot lights; no waiting texels' estimates where --estimate-rays did not ask for them (a bake
 * shows every texel it gathers, and the estimates' bases would cost every texel's rays for nothing); in:
 * the loaded scene's info. */
void lm_cli_bake_solution(const lmgi_info *in, int whole, lmgi_updater_desc *d);
#endif
