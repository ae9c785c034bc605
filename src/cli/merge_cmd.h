/* lmgi merge and what a shard leaves for it beside its part:
 * PART/part.json, the scene's absolute path and the bake's option words, so that `lmgi merge PART...
 * --out DIR` needs neither (docs/levels.md, "A bake in shards"). */
#ifndef LM_CLI_MERGE_CMD_H
#define LM_CLI_MERGE_CMD_H

#include "args.h"

/* A shard's bake (a->shards set, a->files[0] its scene, a->words its command line): writes part.json
 * into out's new result, beside part.checkpoint. 0, or 1 having printed why. */
int lm_cli_write_part_json(lmgi_output *out, const lm_cli_args *a);

/* `lmgi merge PART... --out DIR` (the scene and options from the parts' part.json) or `lmgi merge SCENE
 * PART... --out DIR [the bake's options]`: the parts of a bake in shards put together. The exit code. */
int lm_cli_merge(const lm_cli_args *a);

#endif
