/* lmgi merge (lm_cli_merge, declared in bake_cmd.h) and what a shard leaves for it beside its part:
 * PART/part.json, the scene's absolute path and the bake's option words, so that `lmgi merge PART...
 * --out DIR` needs neither (docs/levels.md, "A bake in shards"). */
#ifndef LM_CLI_MERGE_CMD_H
#define LM_CLI_MERGE_CMD_H

#include "args.h"

/* A shard's bake (a->shards set, a->files[0] its scene, a->words its command line): writes part.json
 * into out's new result, beside part.checkpoint. 0, or 1 having printed why. */
int lm_cli_write_part_json(lmgi_output *out, const lm_cli_args *a);

/* The bake of a merge (bake_cmd.c): the scene a->files[0] and the parts' checkpoint files put together
 * into a->out_dir. The exit code. */
int lm_cli_bake_merge(const lm_cli_args *a, const char *const *parts, int part_count);

#endif
