/* A whole file read into memory (read_file.h). */
#include "read_file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>

char *lm_cli_read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    long n = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    char *data = n >= 0 && fseek(f, 0, SEEK_SET) == 0 ? malloc((size_t)n + 1) : NULL;
    int got = data && fread(data, 1, (size_t)n, f) == (size_t)n;
    fclose(f);
    if (!got) {
        free(data);
        errno = EIO;
        return NULL;
    }
    data[n] = '\0';
    *size = (size_t)n;
    return data;
}
