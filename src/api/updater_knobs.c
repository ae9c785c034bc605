/* The updater desc's knobs checked and resolved, each line of include/lmgi_knobs.h made into a few
 * statements here (updater_knobs.h). */
#include "updater_knobs.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The parts of a line's parenthesised columns. */
#define RULE_TEST(test, text) (test)
#define RULE_TEXT(test, text) text
#define CHOICE_VALUE(name, value) , (double)(value)

/* Whether v is a valid value for a knob of this kind, range, LMGI_OFF and rule; valid[0 .. n) are a
 * choice's values (0 first, the default). */
static int knob_ok(int kind, double v, double lo, double hi, int off, int rule, const double *valid, int n)
{
    if (v == 0.0 || (off && v == LMGI_OFF))
        return 1;
    if (kind == LMGI_KNOB_SWITCH)
        return v == LMGI_ON;
    if (kind == LMGI_KNOB_CHOICE) {
        for (int k = 0; k < n; k++)
            if (v == valid[k])
                return 1;
        return 0;
    }
    return v >= lo && v <= hi && rule; /* NaN fails */
}

/* "gather.samples 3 must be 1 or 4 ..." for a value knob_ok refused. */
static lm_status refuse(lm_error *err, const char *fn, const char *name, int kind, double v, double lo, double hi,
                        int off, const char *rule)
{
    char value[48], want[160];
    snprintf(value, sizeof value, kind == LMGI_KNOB_REAL ? "%g" : "%.0f", v);
    if (kind == LMGI_KNOB_SWITCH)
        snprintf(want, sizeof want, "LMGI_ON or LMGI_OFF");
    else if (kind == LMGI_KNOB_CHOICE)
        snprintf(want, sizeof want, "one of its enum's values");
    else if (rule && v >= lo && v <= hi)
        snprintf(want, sizeof want, "%s", rule);
    else
        snprintf(want, sizeof want, "in [%g, %g]%s", lo, hi, off ? " or LMGI_OFF" : "");
    return lm_fail(err, LM_ERR_INVALID, "%s: %s %s must be %s (0: the default)", fn, name, value, want);
}

#define CHECK(stage, field, kind, ctype, def, lo, hi, off, rule, flag, arg, cli_zero, choices, sweep, help)         \
    {                                                                                                                 \
        double v = (double)d->stage.field;                                                                            \
        static const double valid[] = {0 choices(CHOICE_VALUE)};                                                      \
        if (!knob_ok(kind, v, lo, hi, off, RULE_TEST rule, valid, (int)(sizeof valid / sizeof *valid)))              \
            return refuse(err, fn, #stage "." #field, kind, v, lo, hi, off, RULE_TEXT rule);                         \
    }

lm_status lm_updater_knobs_check(const lmgi_updater_desc *d, const char *fn, lm_error *err)
{
    LMGI_UPDATER_KNOBS(CHECK)
    return LM_OK;
}

#define RESOLVE(stage, field, kind, ctype, def, ...)                                                                  \
    if (out->stage.field == 0)                                                                                        \
        out->stage.field = (ctype)(def);

void lm_updater_knobs_resolve(const lmgi_updater_desc *d, lmgi_updater_desc *out)
{
    if (out != d)
        *out = *d;
    LMGI_UPDATER_KNOBS(RESOLVE)
}

void lmgi_updater_defaults(lmgi_updater_desc *d)
{
    if (!d)
        return;
    memset(d, 0, sizeof *d);
    lm_updater_knobs_resolve(d, d);
}
