/* A whole file read into memory: the command line's one reader (a part.json, an MPI rank's part). */
#ifndef LM_CLI_READ_FILE_H
#define LM_CLI_READ_FILE_H

#include <stddef.h>

/* The file at path in a malloc'd buffer with a NUL after its bytes (so text can be read as a string),
 * its length in *size. NULL with errno set when it cannot be opened (ENOENT: not there) or read (EIO). */
char *lm_cli_read_file(const char *path, size_t *size);

#endif
