/* The lmgi command's options for the updater's knobs, made from the knob table (include/lmgi_knobs.h):
 * one option per knob that names a flag, taking the knob's range, rule or names, writing the knob into
 * lm_cli_args.desc as lmgi_updater_desc holds it (the option's 0 made LMGI_OFF where the table says so).
 *
 * Layout: lm_cli_knob_options[0 .. lm_cli_knob_option_count), in the table's order (stage by stage); a
 * knob without a flag has an entry with a NULL name, which no word matches. Thread-safety: read-only.
 * Errors: a bad value prints "lmgi: OPTION VALUE: expected WHAT" and the parser returns 2. */
#ifndef LM_CLI_KNOB_OPTIONS_H
#define LM_CLI_KNOB_OPTIONS_H

#include "options.h"

extern const lm_cli_option lm_cli_knob_options[];
extern const int lm_cli_knob_option_count;

#endif
