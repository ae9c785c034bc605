/* The command's outputs: --out DIR through lmgi_output_open (README, "Output directories"), and single
 * files such as --json FILE; neither ever replaces a file the command reads. */
#ifndef LM_CLI_OUT_DIR_H
#define LM_CLI_OUT_DIR_H

#include "args.h"

/* Opens a->out_dir (a->force as given) for `command`'s new result, the command line's files (scenes,
 * --edits, --gather-scene, the --sky image) named as its inputs; prints "lmgi: error: ..." and returns
 * NULL when refused. */
lmgi_output *lm_cli_open_out(const lm_cli_args *a, const char *command);
/* The path NAME of the new result is written to; prints the error and returns 0 when refused. */
int lm_cli_out_path(lmgi_output *o, const char *name, char *path, size_t size);
/* Commits o when rc is 0, else drops the new result (the previous one stays); returns rc, or 1 when the
 * commit failed (printed). NULL o: rc. */
int lm_cli_close_out(lmgi_output *o, int rc);

/* lmgi_write_image of the new result's NAME (the format from NAME's extension). */
lmgi_status lm_cli_write_image(lmgi_output *o, const char *name, int width, int height, int channels,
                               const float *pixels, const lmgi_image_desc *desc, lmgi_error *err);

/* A single output file such as --json FILE, written in memory and then whole (lmgi_write_file): never
 * one of the command line's input files, and a failure is the command's (the caller exits non-zero). */
typedef struct {
    FILE *f; /* write here between open and close */
    char *data;
    size_t size;
} lm_cli_single;
/* Refuses PATH early when it is an input (printed; 0). */
int lm_cli_single_allowed(const lm_cli_args *a, const char *path);
/* 0 (printed) when out of memory. */
int lm_cli_single_open(lm_cli_single *s);
/* Writes what went to s->f to PATH and frees it; 0 (printed) on any failure. */
int lm_cli_single_close(const lm_cli_args *a, const char *path, lm_cli_single *s);

#endif
