/* A game's runtime lightmap updater, through include/lmgi.h
 * (and include/lmgi_tools.h for its pictures and output directory).
 *
 * Loads a scene, creates an updater that keeps its lightmaps current within a time budget per frame
 * (4 ms unless told otherwise), moves an object every frame, fetches the lightmaps when a surface the
 * game draws has changed (a game would upload only those rectangles to its GPU texture), and at the end
 * writes the lightmap and one frame drawn by lmgi from the scene's camera.
 *
 *   runtime_loop SCENE OUT_DIR [--frames N] [--budget MS | --texels N] [--move NODE] [--fps F]
 *
 * Between updates the game would draw its frame; here the loop sleeps out the rest of each 1/F second
 * (default 60 fps; 0: no pause), and the updater's photon work runs on its own thread meanwhile.
 * --texels N gathers a fixed N texels a frame instead of a time budget: the result is then the same on
 * every run and every machine (`lmgi run --texels-per-frame N` gives the same iim.exr). --move NODE
 * slides a dynamic node (by name) back and forth through lmgi_set_node_transform. OUT_DIR is made if
 * missing; its earlier results are replaced only when this run succeeds (lmgi_output_open). */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, nanosleep */
#include <lmgi_tools.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct {
    const char *scene, *out, *move;
    int frames, texels;
    float budget_ms, fps;
} options;

static int parse(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->frames = 60;
    o->budget_ms = 4.0f;
    o->fps = 60.0f;
    int positional = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--frames") && v)
            o->frames = atoi(v), i++;
        else if (!strcmp(a, "--budget") && v)
            o->budget_ms = (float)atof(v), o->texels = 0, i++;
        else if (!strcmp(a, "--texels") && v)
            o->texels = atoi(v), o->budget_ms = 0.0f, i++;
        else if (!strcmp(a, "--fps") && v)
            o->fps = (float)atof(v), i++;
        else if (!strcmp(a, "--move") && v)
            o->move = v, i++;
        else if (a[0] != '-' && positional == 0)
            o->scene = a, positional++;
        else if (a[0] != '-' && positional == 1)
            o->out = a, positional++;
        else
            return 0;
    }
    return o->scene && o->out && o->frames > 0;
}

static int fail(const char *what, const lmgi_error *e)
{
    fprintf(stderr, "runtime_loop: %s: %s\n", what, e->message);
    return 1;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* The rest of the frame, which a game spends drawing. */
static void wait_until(double t_ms)
{
    double left = t_ms - now_ms();
    if (left <= 0.0)
        return;
    struct timespec ts = {(time_t)(left / 1e3), (long)(fmod(left, 1e3) * 1e6)};
    nanosleep(&ts, NULL);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The game's side of the bargain: which surfaces changed since it last uploaded, and how many texels
 * their rectangles hold (what it would copy into its lightmap texture). */
static long upload_changed(const lmgi_scene *sc, const lmgi_updater *u, uint32_t *uploaded, int *surfaces)
{
    long texels = 0;
    *surfaces = 0;
    for (int s = 0; s < lmgi_surface_count(sc); s++) {
        uint32_t v = lmgi_surface_version(u, s);
        int r[4];
        if (v == uploaded[s] || !lmgi_surface_rect(sc, s, r))
            continue;
        uploaded[s] = v;
        texels += (long)r[2] * r[3];
        (*surfaces)++;
    }
    return texels;
}

static int write_results(lmgi_scene *sc, lmgi_updater *u, lmgi_output *out)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *iim = malloc(n * sizeof *iim), *frame = malloc(3 * 256 * 256 * sizeof *frame);
    lmgi_camera cam;
    lmgi_error e;
    char path[4200];
    int rc = 0;
    if (!iim || !frame)
        rc = 1, fprintf(stderr, "runtime_loop: out of memory\n");
    else if (lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, iim, n, &e) != LMGI_OK)
        rc = fail("lightmap", &e);
    else if (lmgi_output_file(out, "iim.exr", path, sizeof path, &e) != LMGI_OK ||
             lmgi_write_image(path, in.atlas_width, in.atlas_height, 4, iim, NULL, &e))
        rc = fail("write", &e);
    else if (lmgi_scene_camera(sc, -1, 256, 256, &cam, &e) != LMGI_OK ||
             lmgi_render(u, &cam, 256, 256, frame, &e) != LMGI_OK)
        rc = fail("render", &e);
    else if (lmgi_output_file(out, "frame.png", path, sizeof path, &e) != LMGI_OK ||
             lmgi_write_image(path, 256, 256, 3, frame, NULL, &e))
        rc = fail("write", &e);
    free(iim);
    free(frame);
    return rc;
}

/* Slides `node` along x by up to 0.3 units of its start, a little further each frame. */
static int move(lmgi_scene *sc, int node, const float start[16], int frame)
{
    float m[16];
    memcpy(m, start, sizeof m);
    m[12] += 0.3f * sinf(0.1f * (float)frame);
    lmgi_error e;
    return lmgi_set_node_transform(sc, node, m, &e) == LMGI_OK ? 0 : fail("move", &e);
}

static int run(const options *o, lmgi_context *ctx, lmgi_scene *sc, lmgi_output *out)
{
    lmgi_updater_desc d = {0}; /* zeros: the defaults; no frame composited: the game draws its own */
    d.gather.texels_per_frame = o->texels;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        return fail("updater", &e);
    int node = o->move ? lmgi_find_node(sc, o->move) : -1;
    float start[16];
    if (o->move && !lmgi_get_node_transform(sc, node, start)) {
        fprintf(stderr, "runtime_loop: no node '%s'\n", o->move);
        lmgi_updater_free(u);
        return 1;
    }
    uint32_t *uploaded = calloc((size_t)lmgi_surface_count(sc) + 1, sizeof *uploaded);
    double *ms = malloc(sizeof *ms * (size_t)o->frames);
    long texels = 0, upload = 0;
    int rc = uploaded && ms ? 0 : 1, surfaces = 0;
    for (int f = 0; f < o->frames && rc == 0; f++) {
        double frame_start = now_ms();
        if (node >= 0 && (rc = move(sc, node, start, f)) != 0)
            break;
        lmgi_update_stats st;
        if (lmgi_update(u, (float)f / 30.0f, o->budget_ms, &st, &e) != LMGI_OK) {
            rc = fail("update", &e);
            break;
        }
        int changed;
        upload += upload_changed(sc, u, uploaded, &changed);
        surfaces += changed;
        texels += st.texels_gathered;
        ms[f] = st.ms_total;
        if (o->fps > 0.0f)
            wait_until(frame_start + 1e3 / o->fps);
    }
    if (rc == 0) {
        qsort(ms, (size_t)o->frames, sizeof *ms, cmp_double);
        printf("%d frames, %s: update median %.2f ms, 95th percentile %.2f ms; %.1f texels gathered a frame; "
               "%d surface uploads, %ld texels\n", o->frames, o->texels ? "fixed texels" : "time budget",
               ms[o->frames / 2], ms[(int)(0.95 * (o->frames - 1))], (double)texels / o->frames, surfaces, upload);
        rc = write_results(sc, u, out);
    }
    free(uploaded);
    free(ms);
    lmgi_updater_free(u);
    return rc;
}

int main(int argc, char **argv)
{
    options o;
    if (!parse(argc, argv, &o)) {
        fprintf(stderr, "usage: runtime_loop SCENE OUT_DIR [--frames N] [--budget MS | --texels N] [--move NODE] "
                "[--fps F]\n");
        return 2;
    }
    lmgi_context *ctx = NULL;
    lmgi_error e;
    if (lmgi_context_create(NULL, &ctx, &e) != LMGI_OK)
        return fail("context", &e);
    lmgi_options lo;
    lmgi_options_init(&lo);
    lo.target_texels = lmgi_atlas_texels_for(o.texels); /* a density the texel budget keeps up with */
    lmgi_scene *sc = NULL;
    lmgi_output *out = NULL;
    const char *const inputs[] = {o.scene, NULL};
    int rc = lmgi_load(o.scene, &lo, &sc, &e) != LMGI_OK                               ? fail(o.scene, &e)
             : lmgi_output_open(o.out, "runtime-loop", 0, inputs, &out, &e) != LMGI_OK ? fail(o.out, &e)
                                                                                       : run(&o, ctx, sc, out);
    if (out && rc == 0 && lmgi_output_commit(out, &e) != LMGI_OK)
        rc = fail(o.out, &e);
    else if (out && rc != 0)
        lmgi_output_abort(out);
    lmgi_free(sc);
    lmgi_context_free(ctx);
    return rc;
}
