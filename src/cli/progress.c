#include "progress.h"

#include <stdio.h>
#include <time.h>
#include <unistd.h>

static int on_terminal(void)
{
    static int tty = -1;
    if (tty < 0)
        tty = isatty(fileno(stderr));
    return tty;
}

static void bar(const char *what, double fraction)
{
    int width = 40, filled = (int)(width * (fraction < 0.0 ? 0.0 : fraction > 1.0 ? 1.0 : fraction));
    fprintf(stderr, "\r%s [", what);
    for (int i = 0; i < width; i++)
        fputc(i < filled ? '#' : '.', stderr);
    fputc(']', stderr);
}

void lm_progress(const char *what, int done, int total)
{
    if (!on_terminal() || total <= 0)
        return;
    bar(what, (double)done / total);
    fprintf(stderr, " %d/%d", done, total);
    if (done >= total)
        fputc('\n', stderr);
    fflush(stderr);
}

double lm_cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void lm_progress_fraction(const char *what, float fraction, const char *stage, double started)
{
    if (!on_terminal())
        return;
    bar(what, fraction);
    double spent = lm_cli_now() - started;
    fprintf(stderr, " %3d%% %-8s", (int)(100.0f * fraction), stage);
    if (fraction >= 1.0f)
        fprintf(stderr, " %.1f s         \n", spent);
    else if (fraction > 0.02f) /* too early, the estimate is noise */
        fprintf(stderr, " %.0f s left     ", spent * (1.0 - fraction) / fraction);
    else
        fprintf(stderr, "                 ");
    fflush(stderr);
}
