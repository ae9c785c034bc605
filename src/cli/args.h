/* Command-line options shared by the lmgi subcommands. */
#ifndef LM_CLI_ARGS_H
#define LM_CLI_ARGS_H

#include <lmgi.h>

#define LM_CLI_MAX_FILES 64

typedef struct {
    lmgi_options options;
    const char *out_dir;
    const char *json_path;
    int width, height;
    int repeats;
    int verbose, quiet;
    int file_count;
    const char *files[LM_CLI_MAX_FILES];
    int scaling_count;
    const char *scaling[LM_CLI_MAX_FILES];
} lm_cli_args;

/* Parses argv[first..argc). Returns 0 on success, or prints what was wrong and returns 2. */
int lm_cli_parse(int argc, char **argv, int first, lm_cli_args *a);

#endif
