#include "progress.h"

#include <stdio.h>
#include <unistd.h>

void lm_progress(const char *what, int done, int total)
{
    static int tty = -1;
    if (tty < 0)
        tty = isatty(fileno(stderr));
    if (!tty || total <= 0)
        return;
    int width = 40, filled = (int)((long)width * done / total);
    fprintf(stderr, "\r%s [", what);
    for (int i = 0; i < width; i++)
        fputc(i < filled ? '#' : '.', stderr);
    fprintf(stderr, "] %d/%d", done, total);
    if (done >= total)
        fputc('\n', stderr);
    fflush(stderr);
}
