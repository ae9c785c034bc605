/* What the public reference shares with the check: its desc turned into the solver's settings. */
#ifndef LM_LMGI_REFERENCE_H
#define LM_LMGI_REFERENCE_H

#include <lmgi_tools.h>

#include "../reference/reference.h"

/* The solver's settings for desc (NULL or zeros: the defaults), checked: LMGI_ERR_INVALID naming the field
 * after fn (the public call's name). */
lmgi_status lm_api_ref_settings(const lmgi_reference_desc *desc, const char *fn, lm_ref_settings *s, lmgi_error *err);

#endif
