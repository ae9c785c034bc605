/* The lmgi command line: options parsed by the table of options.c, for the command given. */
#include "args.h"
#include "option_values.h"
#include "options.h"
#include "progress.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The word after an option that takes a value, or NULL when there is none or it is another option ("-q",
 * "--out"; a negative number is a value): `--out -q` must not make a directory named -q. */
static const char *value_after(int argc, char **argv, int i)
{
    const char *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (v && v[0] == '-' && v[1] && !(v[1] >= '0' && v[1] <= '9') && v[1] != '.')
        return NULL;
    return v;
}

/* Stores o's value v (NULL: missing) into a; 0, or 2 having said what was wrong. */
static int take(const lm_cli_option *o, const char *word, const char *v, lm_cli_args *a)
{
    char *field = (char *)a + o->field;
    switch (o->kind) {
    case LM_OPT_FLAG:
        *(int *)field = 1;
        return 0;
    case LM_OPT_INT:
        return lm_cli_parse_int(word, v, (int)o->lo, (int)o->hi, (int *)field);
    case LM_OPT_FLOAT:
        return lm_cli_parse_float(word, v, (float)o->lo, (float *)field);
    case LM_OPT_TEXT:
        return v ? (*(const char **)field = v, 0) : lm_cli_bad(word, v, o->arg);
    case LM_OPT_CUSTOM:
        return o->parse(word, v, a);
    case LM_OPT_KNOBS: /* not an option (all_options in options.c never gives it) */
        break;
    }
    return 2;
}

/* An option the command does not take (o: the table's entry), or one lmgi does not know (o NULL): said
 * with what was meant. */
static int refuse(const lm_cli_option *o, const char *word, const char *command, unsigned commands)
{
    if (o) {
        char list[160];
        lm_cli_command_list(o->commands, list, sizeof list);
        fprintf(stderr, "lmgi: '%s' is not an option of '%s' (%s%s; see 'lmgi help %s')\n", word, command,
                o->commands ? "it is one of " : "it is lmgi-dev's", o->commands ? list : "", command);
        return 2;
    }
    const lm_cli_option *near = lm_cli_nearest_option(word, commands);
    if (near)
        fprintf(stderr, "lmgi: unknown option '%s'; did you mean '%s'? (see 'lmgi help %s')\n", word, near->name,
                command);
    else
        fprintf(stderr, "lmgi: unknown option '%s' (see 'lmgi help %s')\n", word, command);
    return 2;
}

int lm_cli_parse(int argc, char **argv, int first, const char *command, unsigned commands, lm_cli_args *a)
{
    memset(a, 0, sizeof *a);
    lmgi_options_init(&a->options);
    a->repeats = 3;
    a->camera = -1;
    a->word_count = argc > first ? argc - first : 0;
    a->words = argv + first;
    int rc = 0;
    for (int i = first; i < argc && rc == 0; i++) {
        const char *word = argv[i];
        if (word[0] != '-' || !word[1]) {
            rc = lm_cli_add_file(a->files, &a->file_count, word);
            continue;
        }
        const lm_cli_option *o = lm_cli_find_option(word);
        if (!o || !(o->commands & commands || commands == ~0u)) {
            rc = refuse(o, word, command, commands);
            continue;
        }
        /* --effects' list starts with - or +: the word after it, whatever it is */
        const char *v = o->parse == lm_cli_opt_effects ? (i + 1 < argc ? argv[i + 1] : NULL) : value_after(argc, argv, i);
        rc = take(o, word, v, a);
        i += o->arg != NULL;
    }
    return rc;
}

static int wants_help(int argc, char **argv)
{
    for (int i = 2; i < argc; i++)
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h"))
            return 1;
    return 0;
}

int lm_cli_start(int argc, char **argv, void (*usage)(FILE *), int lmgi, lm_cli_args *a)
{
    if (argc < 2 || !strcmp(argv[1], "help") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        const lm_cli_command *c = lmgi && argc > 2 ? lm_cli_find_command(argv[2]) : NULL;
        if (lmgi && argc > 2 && !c) {
            fprintf(stderr, "lmgi: no command '%s' to help with (see 'lmgi help')\n", argv[2]);
            return 2;
        }
        if (c)
            lm_cli_print_command_help(stdout, c);
        else
            usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    const lm_cli_command *c = lmgi ? lm_cli_find_command(argv[1]) : NULL;
    if (lmgi && !c) { /* refused by lmgi's main, naming the command */
        memset(a, 0, sizeof *a);
        return -1;
    }
    if (c && wants_help(argc, argv)) {
        lm_cli_print_command_help(stdout, c);
        return 0;
    }
    /* lmgi-dev's commands take every option */
    if (lm_cli_parse(argc, argv, 2, argv[1], c ? c->bit : ~0u, a))
        return 2;
    lmgi_set_verbosity(a->quiet ? 0 : a->verbose ? 2 : 1);
    lm_progress_quiet(a->quiet);
    return -1;
}
