/* The updater desc's knobs, checked and resolved from their table (include/lmgi_knobs.h): the library's
 * side of the table, which the lmgi command reads too (src/cli/knob_options.c).
 *
 * A knob is valid when it is 0 (its default), LMGI_OFF where its line allows it, one of its choices, or
 * within its range and rule. Resolving makes each 0 its default, leaving 0 where the scene chooses (the
 * line's default is 0) and LMGI_OFF as it is. Cost: one pass over the ~40 knobs. Thread-safety: pure
 * functions. Errors: lm_updater_knobs_check fails with LM_ERR_INVALID naming the knob as the desc spells
 * it ("gather.samples 3 must be 1 or 4 ..."). */
#ifndef LM_API_UPDATER_KNOBS_H
#define LM_API_UPDATER_KNOBS_H

#include <lmgi.h>

#include "../core/error.h"

/* Every knob of d against its line; `fn` (the public function) begins the message. */
lm_status lm_updater_knobs_check(const lmgi_updater_desc *d, const char *fn, lm_error *err);
/* out's knobs: d's, each 0 made its default; out's other fields are d's. out may be d. */
void lm_updater_knobs_resolve(const lmgi_updater_desc *d, lmgi_updater_desc *out);

#endif
