/* The updater's knobs as options of the lmgi command (knob_options.h): each line of the knob table made
 * into a parser of its value and an entry of the options' table. */
#include "knob_options.h"

#include <stddef.h>
#include <stdio.h>

#include "option_values.h"

/* The parts of a line's parenthesised columns, and its names. */
#define RULE_TEST(test, text) (test)
#define RULE_TEXT(test, text) text
#define CHOICE_NAME(name, value) , name
#define CHOICE_VALUE(name, value) , (int)(value)

typedef struct {
    int kind;                 /* LMGI_KNOB_* */
    size_t field;             /* the knob in lm_cli_args (its desc) */
    double lo, hi;
    int cli_zero;             /* LMGI_CLI_ZERO_*: what the value 0 means */
    const char *rule;         /* what its rule wants (NULL: none) */
    int (*rule_ok)(double v);
    const char *const *names; /* its names and their values, [1 .. n] ([0]: a placeholder) */
    const int *values;
    int n;
} knob;

static int parse_real(const knob *k, const char *o, const char *v, float *out)
{
    float f;
    if (lm_cli_parse_float(o, v, k->cli_zero != LMGI_CLI_ZERO_NONE ? 0.0f : (float)k->lo, &f))
        return 2;
    if (f == 0.0f && k->cli_zero != LMGI_CLI_ZERO_NONE) { /* 0: off, or the default */
        *out = k->cli_zero == LMGI_CLI_ZERO_OFF ? (float)LMGI_OFF : 0.0f;
        return 0;
    }
    if (!k->rule_ok(f) || f < k->lo || f > k->hi) {
        char want[80];
        snprintf(want, sizeof want, "a number in [%g, %g]", k->lo, k->hi);
        return lm_cli_bad(o, v, k->rule ? k->rule : want);
    }
    *out = f;
    return 0;
}

/* v for the knob k (its option spelt o) into a's desc; 0, or 2 having said what was wrong. */
static int parse_knob(const knob *k, const char *o, const char *v, lm_cli_args *a)
{
    char *field = (char *)a + k->field;
    if (k->n)
        return lm_cli_choose(o, v, k->names + 1, k->values + 1, k->n, (int *)field);
    if (k->kind == LMGI_KNOB_REAL)
        return parse_real(k, o, v, (float *)field);
    int i;
    if (lm_cli_parse_int(o, v, k->cli_zero != LMGI_CLI_ZERO_NONE ? 0 : (int)k->lo, (int)k->hi, &i))
        return 2;
    if (i != 0 && !k->rule_ok(i))
        return lm_cli_bad(o, v, k->rule);
    if (i == 0 && k->cli_zero == LMGI_CLI_ZERO_OFF)
        i = LMGI_OFF;
    if (k->kind == LMGI_KNOB_COUNT)
        *(uint32_t *)field = (uint32_t)i;
    else
        *(int *)field = i;
    return 0;
}

#define KNOB(stage, field, kind, ctype, def, lo, hi, off, rule, flag, arg, cli_zero, choices, sweep, help)          \
    static int rule_##stage##_##field(double v)                                                                       \
    {                                                                                                                 \
        (void)v;                                                                                                      \
        return RULE_TEST rule;                                                                                        \
    }                                                                                                                 \
    static const char *const names_##stage##_##field[] = {NULL choices(CHOICE_NAME)};                                 \
    static const int values_##stage##_##field[] = {0 choices(CHOICE_VALUE)};                                          \
    static const knob knob_##stage##_##field = {                                                                      \
        kind, offsetof(lm_cli_args, desc.stage.field), lo, hi, cli_zero, RULE_TEXT rule, rule_##stage##_##field,   \
        names_##stage##_##field, values_##stage##_##field,                                                           \
        (int)(sizeof values_##stage##_##field / sizeof *values_##stage##_##field) - 1};                              \
    static int parse_##stage##_##field(const char *o, const char *v, lm_cli_args *a)                                 \
    {                                                                                                                 \
        return parse_knob(&knob_##stage##_##field, o, v, a);                                                          \
    }
LMGI_UPDATER_KNOBS(KNOB)

#define OPTION(stage, field, kind, ctype, def, lo, hi, off, rule, flag, arg, cli_zero, choices, sweep, help)        \
    {flag, NULL, arg, LM_CMD_UPDATER, LM_OPT_CUSTOM, 0, 0, 0, parse_##stage##_##field, help},

const lm_cli_option lm_cli_knob_options[] = {LMGI_UPDATER_KNOBS(OPTION)};
const int lm_cli_knob_option_count = (int)(sizeof lm_cli_knob_options / sizeof *lm_cli_knob_options);
