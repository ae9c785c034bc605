#include "progress.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

static int g_quiet;
static double g_last_line = -1.0; /* when the last whole line was written (not on a terminal) */

void lm_progress_quiet(int quiet) { g_quiet = quiet; }

static int on_terminal(void)
{
    static int tty = -1;
    if (tty < 0)
        tty = isatty(fileno(stderr));
    return tty;
}

double lm_cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double line_interval(void)
{
    static double seconds = -1.0;
    if (seconds < 0.0) {
        const char *env = getenv("LMGI_PROGRESS_SECONDS");
        char *end = NULL;
        double v = env ? strtod(env, &end) : -1.0;
        seconds = env && end != env && *end == '\0' && v >= 0.0 ? v : LM_PROGRESS_LINE_SECONDS;
    }
    return seconds;
}

/* Whether a whole line is due now: the first, the last (done), or one interval after the previous. */
static int line_due(int done)
{
    double now = lm_cli_now();
    if (!done && g_last_line >= 0.0 && now - g_last_line < line_interval())
        return 0;
    g_last_line = done ? -1.0 : now; /* the next piece of work starts with a line of its own */
    return 1;
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
    if (g_quiet || total <= 0)
        return;
    if (!on_terminal()) {
        if (line_due(done >= total))
            fprintf(stderr, "%s: %d/%d\n", what, done, total);
        return;
    }
    bar(what, (double)done / total);
    fprintf(stderr, " %d/%d", done, total);
    if (done >= total)
        fputc('\n', stderr);
    fflush(stderr);
}

void lm_progress_fraction(const char *what, float fraction, const char *stage, double started)
{
    if (g_quiet)
        return;
    double spent = lm_cli_now() - started;
    if (!on_terminal()) {
        if (!line_due(fraction >= 1.0f))
            return;
        if (fraction >= 1.0f)
            fprintf(stderr, "%s: done in %.1f s\n", what, spent);
        else if (fraction > 0.02f)
            fprintf(stderr, "%s: %s %d%% (%.0f s left)\n", what, stage, (int)(100.0f * fraction),
                    spent * (1.0 - fraction) / fraction);
        else
            fprintf(stderr, "%s: %s %d%%\n", what, stage, (int)(100.0f * fraction));
        fflush(stderr);
        return;
    }
    bar(what, fraction);
    fprintf(stderr, " %3d%% %-8s", (int)(100.0f * fraction), stage);
    if (fraction >= 1.0f)
        fprintf(stderr, " %.1f s         \n", spent);
    else if (fraction > 0.02f) /* too early, the estimate is noise */
        fprintf(stderr, " %.0f s left     ", spent * (1.0 - fraction) / fraction);
    else
        fprintf(stderr, "                 ");
    fflush(stderr);
}
