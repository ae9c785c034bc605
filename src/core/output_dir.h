/* An output directory that never loses a user's file: each command's new result is written beside the
 * last one and swapped in only when the command succeeds, and lmgi removes only files it wrote itself.
 *
 * Layout of DIR:
 *   .lmgi       the manifest: "lmgi output 1", then one line per file lmgi wrote here,
 *               "COMMAND<TAB>INODE<TAB>SIZE<TAB>MTIME_NS<TAB>NAME", the file as lmgi placed it (all 0 for a
 *               working file, which lmgi rewrites under its name).
 *               An older lmgi's marker ("lmgi writes into this directory...") reads as an empty manifest.
 *   .lmgi.lock  held with flock(2) from open to commit or abort; the kernel releases it when the process
 *               dies, so a killed command never leaves the folder locked. Holds "PID COMMAND" for the
 *               message a second command gets. Never removed (removing a lock file races its next user).
 *   .lmgi-new/  the new result while the command runs (mode 0700); the previous result is untouched until
 *               commit. A killed command's leftover is removed by the next open, which holds the lock.
 *
 * Invariants: a file not in the manifest, or not the file lmgi placed under that name (another inode, or
 * the same one written over: another size or modification time), is "foreign": never removed or replaced, with or without force. Force only lets a command start writing
 * into an unmarked folder (no manifest) that holds foreign files, the mistake of `--out ~`; a folder with a
 * manifest is lmgi's to write into, beside whatever else it holds. The manifest always lists
 * every file lmgi placed in DIR (it is rewritten as the union before the files move in), so a kill during a
 * commit leaves nothing lmgi cannot recognise later. Files named as inputs at open are never replaced or
 * removed: open refuses when the command's earlier output is one of them, commit re-checks by device and
 * inode. Names are plain file names (no '/', not starting with '.', no tab or newline, under 256 bytes).
 *
 * Commit: the new result's names replace this command's earlier files of the same names, and this
 * command's earlier files that the new result lacks are removed (a 20-frame run after a 60-frame one leaves
 * 20 frames); other commands' files stay. Each file moves with rename(2), so each is whole; the result as a
 * whole is swapped file by file (not one atomic step), bracketed by the manifest writes above.
 *
 * Cost: open lists DIR once and reads the manifest; commit renames each file and writes the manifest
 * twice. Errors: LM_ERR_IO naming the path (cannot create, list or write; held by another command; a
 * foreign file in the way; an input in the way), LM_ERR_INVALID (a bad name or command). Not thread-safe for
 * one lm_output; two processes or two lm_outputs on one DIR exclude each other through the lock. */
#ifndef LM_OUTPUT_DIR_H
#define LM_OUTPUT_DIR_H

#include <stddef.h>

#include "error.h"

typedef struct lm_output lm_output;

/* Opens DIR (made with its parents if missing) for COMMAND's new result: takes the lock, reads the
 * manifest, refuses an unmarked folder with foreign files unless force, removes a killed command's
 * leftovers, makes .lmgi-new.
 * inputs: NULL-terminated paths the command reads (NULL: none). */
lm_status lm_output_open(const char *dir, const char *command, int force, const char *const *inputs,
                         lm_output **out, lm_error *err);
/* The folder the new result's files go into (DIR/.lmgi-new). */
const char *lm_output_stage(const lm_output *o);
/* The path of the new result's file NAME (in the stage), refused early when DIR/NAME is foreign or an input. */
lm_status lm_output_file(lm_output *o, const char *name, char *path, size_t size, lm_error *err);
/* A working file kept in DIR itself across a failure or a kill (a bake's checkpoint): listed in the
 * manifest at once, under the command; the next successful commit of the command removes it. */
lm_status lm_output_work_file(lm_output *o, const char *name, char *path, size_t size, lm_error *err);
/* Swaps the new result in (above), releases the lock and frees o, whatever the result; on failure the
 * new result is removed and the message names what was in the way. */
lm_status lm_output_commit(lm_output *o, lm_error *err);
/* Removes the new result, keeps DIR as it was, releases the lock and frees o. NULL: nothing. */
void lm_output_abort(lm_output *o);

#endif
