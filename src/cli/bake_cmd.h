#ifndef LM_CLI_BAKE_CMD_H
#define LM_CLI_BAKE_CMD_H
#include "args.h"
/* `lmgi bake SCENE --out DIR [--half]`: the full solution (lmgi_updater_create is the first bake) with a
 * progress bar and the time left; Ctrl-C cancels within about 100 ms and writes nothing. Writes
 * DIR/lightmap.exr (the IIM: irradiance, alpha = validity; --half: 16-bit floats), DIR/lightmap.png (a
 * tone-mapped preview) and DIR/aim.exr. */
int lm_cli_bake(const lm_cli_args *a);
/* A bake's photons when --photons and --per-group are not given: LM_CLI_BAKE_PHOTONS_PER_TEXEL a texel of
 * its atlas, within [MIN, MAX]. Its AIMs are as fine as its atlas, and an N-nearest estimate of fewer photons
 * than texels spans several of them: the sunlit living room baked at 65,536 texels from the updater's
 * 46,080 photons read 3-8% bright on its walls and 25-58% on its furniture, mottled, and from 270,716 within
 * 3% and 7% (docs/photons.md, "A bake's photons"). Tracing them costs a few percent of the gather. */
#define LM_CLI_BAKE_PHOTONS_PER_TEXEL 4u
#define LM_CLI_BAKE_PHOTONS_MIN 46080u
#define LM_CLI_BAKE_PHOTONS_MAX 1048576u
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
/* What a bake's stages took (lm_cli_bake_shared): the whole call in seconds, the first full solution's
 * photon tracing, AIMs and gather in milliseconds (lmgi_updater_info). */
typedef struct {
    double seconds, ms_trace, ms_aim, ms_gather;
} lm_cli_bake_times;
/* What connects the processes of a shared bake (lmgi_updater_desc's photon_exchange, claim_pass and
 * share_user: lmgi-mpi's ranks), and whether this one shows the progress even when quiet. */
typedef struct {
    int (*photon_exchange)(void *user, const void *mine, size_t size, size_t *sizes, void *all);
    int (*claim_pass)(void *user, int passes);
    void *user;
    int progress;
} lm_cli_share;
/* The bake of a merge: the scene a->files[0] and the parts' checkpoint files put together into
 * a->out_dir. The exit code. */
int lm_cli_bake_merge(const lm_cli_args *a, const char *const *parts, int part_count);
/* lm_cli_bake of a shard (a->shards > 1) connected to the others by `share` (NULL: none), its stages'
 * times into *t (may be NULL; zeroed when it fails before the solution). */
int lm_cli_bake_shared(const lm_cli_args *a, const lm_cli_share *share, lm_cli_bake_times *t);
#endif
