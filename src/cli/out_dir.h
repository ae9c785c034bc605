/* The directory a command writes into (--out DIR), claimed before any work so that nothing a user put
 * there is lost and no stale frame of an earlier, longer run is left beside the new ones.
 *
 * A directory lmgi writes into holds a marker file, .lmgi. A command may write into a directory that is
 * new, empty, or has the marker; one that holds anything else is refused (exit 1, naming a file found
 * there) unless --force. Before writing, the command removes the files of its own kind of output (its
 * `own` name patterns, fnmatch(3), and any NAME.partial lm_write_file left) and nothing else, so a run of 20 frames after one of 60 leaves 20
 * frames. Not thread-safe (one claim per command). */
#ifndef LM_CLI_OUT_DIR_H
#define LM_CLI_OUT_DIR_H

#include "../core/error.h"

/* Makes DIR if needed, checks it is writable and lmgi's (or force), removes the files matching the
 * NULL-terminated `own` patterns, and writes the marker. */
lm_status lm_cli_claim_out_dir(const char *dir, int force, const char *const *own, lm_error *err);

#endif
