/* A whole file read into memory (read_file.h). */
#include "read_file.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

char *lm_cli_read_file(const char *path, size_t limit, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *data = NULL;
    size_t n = 0, cap = 0, most = limit < SIZE_MAX - 1 ? limit + 1 : SIZE_MAX - 1; /* a byte past the limit */
    int fail = 0;
    while (!fail) {
        if (n == cap) { /* room for up to `most` bytes and the NUL */
            size_t more = cap ? 2 * cap : 65536;
            cap = more > most || more < cap ? most : more;
            char *grown = realloc(data, cap + 1);
            if (!grown) {
                fail = ENOMEM;
                break;
            }
            data = grown;
        }
        size_t got = fread(data + n, 1, cap - n, f);
        n += got;
        if (n > limit)
            fail = EFBIG;
        else if (got == 0)
            break;
    }
    if (!fail && ferror(f))
        fail = EIO;
    fclose(f);
    if (fail) {
        free(data);
        errno = fail;
        return NULL;
    }
    data[n] = '\0';
    *size = n;
    return data;
}
