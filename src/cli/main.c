/* The lmgi command. */
#include <lmgi_tools.h>

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "args.h"
#include "bake_cmd.h"
#include "merge_cmd.h"
#include "bench.h"
#include "check_cmd.h"
#include "options.h"
#include "out_dir.h"
#include "reference_cmd.h"
#include "run_cmd.h"
#include "scene_load.h"
#include "tradeoff_cmd.h"
#include "view_cmd.h"

static int load(const lm_cli_args *a, lmgi_scene **sc)
{
    if (a->file_count != 1) {
        fprintf(stderr, "lmgi: expected exactly one scene file, got %d (see 'lmgi help')\n", a->file_count);
        return 2;
    }
    return lm_cli_load_scene(a->files[0], &a->options, 0, sc) ? 0 : 1;
}

static int cmd_info(const lm_cli_args *a)
{
    lmgi_scene *sc = NULL;
    int rc = load(a, &sc);
    if (rc)
        return rc;
    lmgi_print_info(sc, stdout);
    lmgi_free(sc);
    return 0;
}

static int cmd_charts(const lm_cli_args *a)
{
    if (!a->out_dir) {
        fprintf(stderr, "lmgi: charts needs --out DIR\n");
        return 2;
    }
    lmgi_scene *sc = NULL;
    int rc = load(a, &sc);
    if (rc)
        return rc;
    lmgi_output *o = lm_cli_open_out(a, "charts");
    if (!o) {
        lmgi_free(sc);
        return 1;
    }
    lmgi_error err;
    if (lmgi_write_charts(sc, lmgi_output_folder(o), a->width, a->height, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        rc = 1;
    } else if (!a->quiet) {
        lmgi_info in;
        lmgi_get_info(sc, &in);
        char pages[64] = "";
        if (in.pages > 1)
            snprintf(pages, sizeof pages, ": %d pages of %d x %d side by side", in.pages, in.page_width, in.page_height);
        printf("wrote %s/atlas.png (%d x %d%s, %d charts, %.1f%% used) and %s/surfaces.png (%d surfaces)\n",
               a->out_dir, in.atlas_width, in.atlas_height, pages, in.charts, 100.0 * (double)in.utilization,
               a->out_dir, in.surfaces);
    }
    lmgi_free(sc);
    return lm_cli_close_out(o, rc);
}

int main(int argc, char **argv)
{
    lm_cli_args a;
    int rc = lm_cli_start(argc, argv, lm_cli_print_help, 1, &a);
    if (rc >= 0)
        return rc;
    /* A file that outgrows the file-size limit (ulimit -f) is then a write error naming the file, as a
     * full disk is, instead of a signal that kills the run. */
    signal(SIGXFSZ, SIG_IGN);
    const char *cmd = argv[1];
    static const struct {
        const char *name;
        int (*run)(const lm_cli_args *a);
    } commands[] = {{"info", cmd_info}, {"charts", cmd_charts}, {"reference", lm_cli_reference}, {"run", lm_cli_run},
                    {"bake", lm_cli_bake}, {"merge", lm_cli_merge}, {"check", lm_cli_check}, {"bench", lm_cli_bench},
                    {"tradeoff", lm_cli_tradeoff}, {"view", lm_cli_view}};
    for (size_t i = 0; i < sizeof commands / sizeof *commands; i++)
        if (!strcmp(cmd, commands[i].name)) {
            rc = commands[i].run(&a);
            /* what it printed is part of its result: `lmgi info > /dev/full` is not a success */
            if ((fflush(stdout) != 0 || ferror(stdout)) && rc == 0) {
                fprintf(stderr, "lmgi: error: cannot write the output (%s)\n", strerror(errno));
                rc = 1;
            }
            return rc;
        }
    fprintf(stderr, "lmgi: unknown command '%s' (lmgi help lists them)\n\n", cmd);
    lm_cli_print_help(stderr);
    return 2;
}
