#ifndef LM_CLI_BAKE_CMD_H
#define LM_CLI_BAKE_CMD_H
#include "args.h"
#include "bake_options.h"
/* `lmgi bake SCENE --out DIR [--half]`: the full solution (lmgi_updater_create is the first bake) with a
 * progress bar and the time left; Ctrl-C cancels within about 100 ms and writes nothing. Writes
 * DIR/lightmap.exr (the IIM: irradiance, alpha = validity; --half: 16-bit floats), DIR/lightmap.png (a
 * tone-mapped preview) and DIR/aim.exr. */
int lm_cli_bake(const lm_cli_args *a);
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
