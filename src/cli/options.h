/* The lmgi command's commands and options, in one table each (options.c): the parser (args.c) takes an
 * option only from the table and only for the commands the table gives it, and `lmgi help [COMMAND]` /
 * `lmgi COMMAND --help` print the same table, so the help cannot drift from what is accepted.
 *
 * Layout: lm_cli_options[] ends with a zeroed entry; an option's `commands` is a set of LM_CMD_* bits
 * (0: lmgi-dev's alone). The updater's knobs are options made from their own table (knob_options.h),
 * found and printed with these where the LM_OPT_KNOBS entry stands. Thread-safety: read-only tables (the
 * first lookup lists them all: one thread).
 * Errors: none here; the parser reports. */
#ifndef LM_CLI_OPTIONS_H
#define LM_CLI_OPTIONS_H

#include <stddef.h>
#include <stdio.h>

#include "args.h"

enum {
    LM_CMD_INFO = 1u << 0, LM_CMD_CHARTS = 1u << 1, LM_CMD_RUN = 1u << 2, LM_CMD_BAKE = 1u << 3,
    LM_CMD_CHECK = 1u << 4, LM_CMD_REFERENCE = 1u << 5, LM_CMD_BENCH = 1u << 6, LM_CMD_TRADEOFF = 1u << 7,
    LM_CMD_MERGE = 1u << 8, LM_CMD_VIEW = 1u << 9, LM_CMD_ALL = (1u << 10) - 1,
    /* the commands that make an updater from the options (lm_cli_updater_desc): its knobs' */
    LM_CMD_UPDATER = LM_CMD_RUN | LM_CMD_BAKE | LM_CMD_MERGE | LM_CMD_CHECK | LM_CMD_BENCH | LM_CMD_VIEW
};

/* LM_OPT_KNOBS: no option, the place of the updater's knobs (knob_options.h) in the help's order. */
typedef enum { LM_OPT_FLAG, LM_OPT_INT, LM_OPT_FLOAT, LM_OPT_TEXT, LM_OPT_CUSTOM, LM_OPT_KNOBS } lm_cli_option_kind;

typedef struct {
    const char *name, *alias; /* "--out", "-o" (alias NULL: none) */
    const char *arg;          /* the value's name in the help ("DIR"); NULL for a flag */
    unsigned commands;        /* LM_CMD_* bits of the commands that take it */
    lm_cli_option_kind kind;
    size_t field;             /* FLAG, INT (int), FLOAT (float), TEXT (const char *): offset in lm_cli_args */
    double lo, hi;            /* INT: the range; FLOAT: the least value */
    /* CUSTOM: parses v (NULL: missing) for option o into a; 0 or 2 (printed what was wrong) */
    int (*parse)(const char *o, const char *v, lm_cli_args *a);
    const char *help;         /* lines joined by '\n', the first beside the name */
} lm_cli_option;

typedef struct {
    const char *name;         /* "run" */
    unsigned bit;
    const char *usage;        /* "run SCENE --out DIR" */
    const char *help;         /* what it does, lines joined by '\n' */
} lm_cli_command;

extern const lm_cli_option lm_cli_options[];
extern const lm_cli_command lm_cli_commands[];

/* The command named (NULL: not one of lmgi's). */
const lm_cli_command *lm_cli_find_command(const char *name);
/* The option spelt `word` (its name or alias), NULL if none. */
const lm_cli_option *lm_cli_find_option(const char *word);
/* The option nearest `word` by edit distance, if near enough to be a misspelling (NULL: none). */
const lm_cli_option *lm_cli_nearest_option(const char *word, unsigned commands);
/* "run, bake, check and bench" for a set of commands. */
void lm_cli_command_list(unsigned commands, char *buf, size_t size);

/* `lmgi help`: the commands, then every option with the commands that take it. */
void lm_cli_print_help(FILE *f);
/* `lmgi help COMMAND`, `lmgi COMMAND --help`: its usage, what it does, and every option it takes. */
void lm_cli_print_command_help(FILE *f, const lm_cli_command *c);

#endif
