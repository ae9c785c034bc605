/* A whole file read into memory: the command line's one reader (an edit script, a part.json, an MPI
 * rank's part). */
#ifndef LM_CLI_READ_FILE_H
#define LM_CLI_READ_FILE_H

#include <stddef.h>

/* The file at path in a malloc'd buffer with a NUL after its bytes (so text can be read as a string),
 * its length in *size. Read as a stream, so a pipe reads as well as a file. NULL with errno set when it
 * cannot be opened (ENOENT: not there), holds more than `limit` bytes (EFBIG: no more than limit + 1 of
 * them are read; SIZE_MAX: no limit), cannot be read (EIO), or memory runs out (ENOMEM). */
char *lm_cli_read_file(const char *path, size_t limit, size_t *size);

#endif
