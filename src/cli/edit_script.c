/* Edit scripts: reading, applying and playing them (edit_script.h). */
#include "edit_script.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "progress.h"
#include "read_file.h"
#include "surface_error.h"

static int bad(const char *path, int i, const char *what)
{
    if (i >= 0)
        fprintf(stderr, "lmgi: %s: edit %d: %s\n", path, i, what);
    else
        fprintf(stderr, "lmgi: %s: %s\n", path, what);
    return 0;
}

/* The member key of an object; NULL when absent or obj is not an object (an edit that is a number or a
 * list has no members). The first of repeated keys, as cJSON keeps them. */
static const cJSON *member(const cJSON *obj, const char *key)
{
    return cJSON_IsObject(obj) ? cJSON_GetObjectItemCaseSensitive(obj, key) : NULL;
}

static double number_or(const cJSON *obj, const char *key, double fallback)
{
    const cJSON *v = member(obj, key);
    return cJSON_IsNumber(v) ? v->valuedouble : fallback;
}

/* The string member key, NULL when absent or not a string. */
static const char *string_of(const cJSON *obj, const char *key)
{
    const cJSON *v = member(obj, key);
    return cJSON_IsString(v) ? v->valuestring : NULL;
}

/* A count from the script as an int: one beyond int's range (1e300 frames) becomes INT_MIN, which the
 * range checks refuse, rather than a conversion C leaves undefined. */
static int whole(double x)
{
    return x > INT_MIN && x < INT_MAX ? (int)x : INT_MIN;
}

static int parse_script(const char *path, const cJSON *root, lm_edit_script *s)
{
    if (!cJSON_IsObject(root))
        return bad(path, -1, "the script must be a JSON object with an \"edits\" array");
    s->frames = whole(number_or(root, "frames", 120));
    s->fps = whole(number_or(root, "fps", 60));
    s->texels = whole(number_or(root, "texels", 3000));
    s->budget_ms = (float)number_or(root, "budget_ms", 8.0);
    s->scene = string_of(root, "scene");
    if (s->frames < 1 || s->frames > 100000 || s->fps < 0 || s->fps > 1000 || s->texels < 64 ||
        !(s->budget_ms >= 0.0f && s->budget_ms < 1e4f))
        return bad(path, -1, "frames (1..100000), fps (0..1000), texels (>= 64) or budget_ms (>= 0) out of range");
    const cJSON *edits = member(root, "edits");
    if (!cJSON_IsArray(edits) || cJSON_GetArraySize(edits) > LM_EDIT_MAX)
        return bad(path, -1, "\"edits\" must be an array of at most 256 edits");
    int i = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, edits) {
        const cJSON *f = member(e, "frame");
        if (!cJSON_IsNumber(f) || f->valuedouble < 0 || f->valuedouble >= s->frames)
            return bad(path, i, "needs a \"frame\" within the script's frames");
        if (i > 0 && f->valuedouble < s->edits[i - 1].frame)
            return bad(path, i, "edits must come in frame order");
        s->edits[i++] = (lm_edit){(int)f->valuedouble, e};
    }
    s->edit_count = i;
    return 1;
}

/* n floats from a JSON array, each finite. */
static int floats(const cJSON *v, float *out, int n)
{
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != n)
        return 0;
    int i = 0;
    const cJSON *x;
    cJSON_ArrayForEach(x, v) {
        if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble))
            return 0;
        out[i++] = (float)x->valuedouble;
    }
    return 1;
}

static int light_of_node(const lmgi_scene *sc, const char *name)
{
    for (int l = 0; l < lmgi_light_count(sc); l++) {
        lmgi_light li;
        if (lmgi_get_light(sc, l, &li, NULL) == LMGI_OK && !strcmp(lmgi_node_name(sc, li.node), name))
            return l;
    }
    return -1;
}

static int material_named(const lmgi_scene *sc, const char *name)
{
    for (int m = 0; m < lmgi_material_count(sc); m++)
        if (!strcmp(lmgi_material_name(sc, m), name))
            return m;
    return -1;
}

/* Applies one edit to a scene; 0 (after saying why) when the script asks for something the scene lacks
 * or lmgi refuses. */
static int apply(const char *path, int i, const cJSON *e, lmgi_scene *sc)
{
    lmgi_error err;
    const char *light = string_of(e, "light"), *node = string_of(e, "node"), *mat = string_of(e, "material");
    lmgi_status st = LMGI_OK;
    if (light) {
        int l = light_of_node(sc, light);
        lmgi_light li;
        if (l < 0 || lmgi_get_light(sc, l, &li, &err) != LMGI_OK)
            return bad(path, i, "no light on that node");
        const cJSON *v;
        if (cJSON_IsNumber(v = member(e, "intensity")))
            li.intensity = (float)v->valuedouble;
        if (cJSON_IsBool(v = member(e, "enabled")))
            li.enabled = cJSON_IsTrue(v);
        if ((v = member(e, "color")) && !floats(v, li.color, 3))
            return bad(path, i, "\"color\" must be 3 numbers");
        st = lmgi_set_light(sc, l, &li, &err);
    } else if (node) {
        int n = lmgi_find_node(sc, node);
        float world[16], move[3];
        if (n < 0 || !lmgi_get_node_transform(sc, n, world))
            return bad(path, i, "no node of that name");
        if (!floats(member(e, "translate"), move, 3))
            return bad(path, i, "a node edit needs \"translate\": [x, y, z]");
        for (int k = 0; k < 3; k++)
            world[12 + k] += move[k];
        st = lmgi_set_node_transform(sc, n, world, &err);
    } else if (mat) {
        int m = material_named(sc, mat);
        lmgi_material mm;
        if (m < 0 || lmgi_get_material(sc, m, &mm, &err) != LMGI_OK)
            return bad(path, i, "no material of that name");
        const cJSON *v;
        if ((v = member(e, "base_color")) && !floats(v, mm.base_color, 3))
            return bad(path, i, "\"base_color\" must be 3 numbers");
        if ((v = member(e, "emissive")) && !floats(v, mm.emissive, 3))
            return bad(path, i, "\"emissive\" must be 3 numbers");
        st = lmgi_set_material(sc, m, &mm, &err);
    } else if ((light = string_of(e, "add_light"))) {
        static const char *const types[3] = {"point", "spot", "directional"};
        lmgi_light li = {.color = {1, 1, 1}, .intensity = 1.0f, .enabled = 1, .direction = {0, -1, 0},
                         .inner_cone = 0.0f, .outer_cone = 0.785398f};
        li.type = (lmgi_light_type)3;
        for (int t = 0; t < 3; t++)
            if (!strcmp(light, types[t]))
                li.type = (lmgi_light_type)t;
        const cJSON *v;
        if ((int)li.type == 3 || !floats(member(e, "position"), li.position, 3))
            return bad(path, i, "\"add_light\" is \"point\", \"spot\" or \"directional\", with a \"position\"");
        if ((v = member(e, "direction")) && !floats(v, li.direction, 3))
            return bad(path, i, "\"direction\" must be 3 numbers");
        if ((v = member(e, "color")) && !floats(v, li.color, 3))
            return bad(path, i, "\"color\" must be 3 numbers");
        if (cJSON_IsNumber(v = member(e, "intensity")))
            li.intensity = (float)v->valuedouble;
        int id;
        st = lmgi_add_light(sc, &li, &id, &err);
    } else if ((light = string_of(e, "remove_light"))) {
        int l = light_of_node(sc, light);
        if (l < 0)
            return bad(path, i, "no light on that node");
        st = lmgi_remove_light(sc, l, &err);
    } else {
        return bad(path, i, "an edit names a \"light\" (its node), a \"node\", a \"material\", \"add_light\" or "
                   "\"remove_light\"");
    }
    return st == LMGI_OK ? 1 : bad(path, i, err.message);
}

int lm_edit_script_apply(const lm_edit_script *s, int i, lmgi_scene *sc)
{
    return apply(s->path, i, s->edits[i].v, sc);
}

/* Relative L1 distance of a from b over valid texels (b's alpha). */
static double distance(const float *a, const float *b, size_t texels)
{
    double d = 0.0, sum = 0.0;
    for (size_t i = 0; i < texels; i++)
        if (b[4 * i + 3] > 0.5f)
            for (int c = 0; c < 3; c++)
                d += fabs((double)a[4 * i + c] - b[4 * i + c]), sum += fabs((double)b[4 * i + c]);
    return sum > 0.0 ? d / sum : 0.0;
}

/* The largest relative L1 distance of one surface's valid texels (MIN_SURFACE_TEXELS or more): an edit
 * whose light stays near it (a moved cube's shadow) moves the whole atlas's distance by a fraction of a
 * percent while the surfaces around it are far off. surface_of: the surface of each atlas pixel, -1 for
 * none; sums: 2 x surfaces doubles of scratch. */
#define MIN_SURFACE_TEXELS 16
static double worst_surface(const float *a, const float *b, size_t texels, const int *surface_of, int surfaces,
                            double *sums)
{
    memset(sums, 0, sizeof *sums * 3 * (size_t)surfaces);
    for (size_t i = 0; i < texels; i++) {
        int s = surface_of[i];
        if (s < 0 || !(b[4 * i + 3] > 0.5f))
            continue;
        for (int c = 0; c < 3; c++)
            sums[3 * s] += fabs((double)a[4 * i + c] - b[4 * i + c]), sums[3 * s + 1] += fabs((double)b[4 * i + c]);
        sums[3 * s + 2] += 1.0;
    }
    double worst = 0.0;
    for (int s = 0; s < surfaces; s++)
        if (sums[3 * s + 2] >= MIN_SURFACE_TEXELS && sums[3 * s + 1] > 0.0)
            worst = fmax(worst, sums[3 * s] / sums[3 * s + 1]);
    return worst;
}

typedef struct {
    lmgi_context *ctx;
    lmgi_scene *sc, *twin;
    lmgi_updater *u, *ref;
    float *iim, *converged, *before; /* before: the converged lightmap before the last edit */
    size_t texels;
    int *surface_of, surfaces;
    double *sums;
    uint8_t *reach;        /* per surface: 1 in the last edit's reach (all of them before the first edit), 0
                            * not, 2 nothing to judge by (mark_reach): its rewrites are not counted */
    uint32_t *version;     /* per surface: lmgi_surface_version after the last update */
    uint32_t *surface_texels;
} bench;

static int setup(const char *scene_path, const lm_edit_script *s, const lmgi_updater_desc *d, bench *b)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = s->texels;
    lmgi_error e;
    lmgi_updater_desc dd = {0};
    if (d)
        dd = *d;
    if (lmgi_context_create(NULL, &b->ctx, &e) != LMGI_OK || lmgi_load(scene_path, &o, &b->sc, &e) != LMGI_OK ||
        lmgi_load(scene_path, &o, &b->twin, &e) != LMGI_OK ||
        lmgi_updater_create(b->ctx, b->sc, &dd, &b->u, &e) != LMGI_OK ||
        lmgi_updater_create(b->ctx, b->twin, &dd, &b->ref, &e) != LMGI_OK) {
        fprintf(stderr, "lmgi: %s: %s\n", scene_path, e.message);
        return 0;
    }
    lmgi_info in;
    lmgi_get_info(b->sc, &in);
    b->texels = (size_t)in.atlas_width * in.atlas_height;
    b->iim = malloc(4 * b->texels * sizeof *b->iim);
    b->converged = malloc(4 * b->texels * sizeof *b->converged);
    b->surfaces = lmgi_surface_count(b->sc);
    b->surface_of = malloc(b->texels * sizeof *b->surface_of);
    size_t ns = (size_t)(b->surfaces ? b->surfaces : 1);
    b->sums = malloc(3 * ns * sizeof *b->sums);
    b->before = malloc(4 * b->texels * sizeof *b->before);
    b->reach = malloc(ns);
    b->version = calloc(ns, sizeof *b->version);
    b->surface_texels = calloc(ns, sizeof *b->surface_texels);
    if (!b->iim || !b->converged || !b->surface_of || !b->sums || !b->before || !b->reach || !b->version ||
        !b->surface_texels)
        return fprintf(stderr, "lmgi: no memory for the lightmaps\n"), 0;
    memset(b->reach, 1, ns);
    unsigned texture; /* made and filled whole before the play: each update's call uploads what changed */
    lmgi_error te;
    if (lmgi_get_lightmap_texture(b->u, &texture, &te) != LMGI_OK)
        return fprintf(stderr, "lmgi: %s\n", te.message), 0;
    for (size_t i = 0; i < b->texels; i++)
        b->surface_of[i] = -1;
    for (uint32_t t = 0; t < lmgi_texel_count(b->sc); t++) {
        lmgi_texel tx;
        lmgi_get_texel(b->sc, t, &tx);
        b->surface_of[(size_t)tx.y * in.atlas_width + tx.x] = tx.surface;
        b->surface_texels[tx.surface]++;
    }
    return 1;
}

static void teardown(bench *b)
{
    free(b->iim);
    free(b->converged);
    free(b->before);
    free(b->surface_of);
    free(b->sums);
    free(b->reach);
    free(b->version);
    free(b->surface_texels);
    lmgi_updater_free(b->u);
    lmgi_updater_free(b->ref);
    lmgi_free(b->sc);
    lmgi_free(b->twin);
    lmgi_context_free(b->ctx);
}

/* The converged lightmap of the twin, edited alike: a bake. */
static int converge(bench *b)
{
    lmgi_error e;
    if (lmgi_bake(b->ref, NULL, NULL, &e) != LMGI_OK ||
        lmgi_get_lightmap(b->ref, LMGI_LIGHTMAP_IIM, b->converged, 4 * b->texels, &e) != LMGI_OK) {
        fprintf(stderr, "lmgi: %s\n", e.message);
        return 0;
    }
    return 1;
}

/* Which surfaces the last edit reached: those whose converged lightmap (b->converged, now the edited
 * scene's) moved from b->before by more than LM_EDIT_REACH, and those an earlier edit reached that have
 * not caught up with it (more than LM_EDIT_CAUGHT_UP from its converged lightmap at the update before:
 * worst_surface's per-surface sums, still in b->sums), whose work goes on. */
static void mark_reach(bench *b)
{
    for (int s = 0; s < b->surfaces; s++)
        b->reach[s] = b->reach[s] == 1 && b->sums[3 * s] > LM_EDIT_CAUGHT_UP * b->sums[3 * s + 1];
    double *moved = b->sums; /* 2 per surface from here */
    memset(moved, 0, sizeof *moved * 2 * (size_t)b->surfaces);
    for (size_t i = 0; i < b->texels; i++) {
        int s = b->surface_of[i];
        if (s < 0 || !(b->converged[4 * i + 3] > 0.5f || b->before[4 * i + 3] > 0.5f))
            continue;
        for (int c = 0; c < 4; c++) /* alpha too: a texel that turned valid or invalid is reached */
            moved[2 * s] += fabs((double)b->converged[4 * i + c] - b->before[4 * i + c]),
                moved[2 * s + 1] += fabs((double)b->before[4 * i + c]);
    }
    for (int s = 0; s < b->surfaces; s++) /* 2: no valid texel, or dark before and after: nothing to judge */
        b->reach[s] = moved[2 * s + 1] == 0.0 && moved[2 * s] == 0.0 ? 2
                      : b->reach[s] || moved[2 * s] > LM_EDIT_REACH * moved[2 * s + 1];
}

/* What an engine uploads after this update, read the way it would: the rectangles of the surfaces whose
 * version moved, each alone (into b->before's room, free until the next edit's copy). */
static int read_changed_rects(bench *b, lm_edit_frame *row)
{
    double start = 1e3 * lm_cli_now();
    for (int s = 0; s < b->surfaces; s++) {
        int r[4];
        lmgi_error e;
        if (lmgi_surface_version(b->u, s) == b->version[s] || !lmgi_surface_lightmap_rect(b->sc, s, r))
            continue;
        if (lmgi_get_lightmap_rect(b->u, LMGI_LIGHTMAP_IIM, r, b->before, 4 * b->texels, &e) != LMGI_OK)
            return fprintf(stderr, "lmgi: %s\n", e.message), 0;
        row->rect_texels += (uint32_t)(r[2] * r[3]);
    }
    row->ms_read_rects = 1e3 * lm_cli_now() - start;
    start = 1e3 * lm_cli_now();
    unsigned texture;
    lmgi_error e;
    if (lmgi_get_lightmap_texture(b->u, &texture, &e) != LMGI_OK)
        return fprintf(stderr, "lmgi: %s\n", e.message), 0;
    row->ms_texture = 1e3 * lm_cli_now() - start;
    return 1;
}

/* The surfaces in and outside the last edit's reach whose displayed lightmap this update rewrote. */
static void count_rewritten(bench *b, lm_edit_frame *row)
{
    for (int s = 0; s < b->surfaces; s++) {
        uint32_t v = lmgi_surface_version(b->u, s);
        row->reach += b->reach[s] == 1;
        if (v != b->version[s] && b->reach[s] == 1)
            row->reached++;
        else if (v != b->version[s] && b->reach[s] == 0)
            row->outside++, row->outside_texels += b->surface_texels[s];
        b->version[s] = v;
    }
}

/* The frame's error per surface against the reference of the scene as it is now (fc's check). */
static int frame_error(bench *b, const lm_edit_frame_check *fc, double *out)
{
    lmgi_camera cam;
    lmgi_check_result c;
    lmgi_error e;
    if (lmgi_scene_camera(b->sc, -1, fc->width, fc->height, &cam, &e) != LMGI_OK ||
        lmgi_check_updater(b->u, &cam, fc->width, fc->height, fc->ref, &c, &e) != LMGI_OK)
        return fprintf(stderr, "lmgi: frame check: %s\n", e.message), 0;
    double worst;
    *out = lm_cli_surface_error(b->sc, &c, &worst);
    lmgi_check_free(&c);
    return 1;
}

static int play(const lm_edit_script *s, float budget_ms, const lm_edit_frame_check *fc, bench *b,
                lm_edit_frame *rows)
{
    const char *path = s->path;
    int next = 0;
    if (!converge(b))
        return 0;
    for (int f = 0; f < s->frames; f++) {
        double start = 1e3 * lm_cli_now();
        int edited = 0;
        double ms_edit = 0.0;
        for (; next < s->edit_count && s->edits[next].frame == f; next++, edited = 1) {
            double t0 = 1e3 * lm_cli_now();
            if (!apply(path, next, s->edits[next].v, b->sc))
                return 0;
            ms_edit += 1e3 * lm_cli_now() - t0;
            if (!apply(path, next, s->edits[next].v, b->twin))
                return 0;
        }
        lmgi_update_stats st;
        lmgi_error e;
        if (lmgi_update(b->u, 0.0f, budget_ms, &st, &e) != LMGI_OK) {
            fprintf(stderr, "lmgi: %s\n", e.message);
            return 0;
        }
        rows[f] = (lm_edit_frame){st.ms_total, st.ms_photons, st.ms_gather, st.ms_blend, st.texels_gathered,
                              st.photons_retraced, st.aim_surfaces_refreshed, st.surfaces_changed, 0.0, 0.0, 0, 0, 0, 0,
                              NAN, 0.0, 0.0, 0, 0.0, ms_edit, st.busiest_stage, st.ms_light_scale};
        double spent = 1e3 * lm_cli_now() - start;
        if (s->fps > 0 && spent < 1e3 / s->fps) { /* the game's own frame, with the photon work beside it */
            double left = 1e3 / s->fps - spent;
            struct timespec ts = {(time_t)(left / 1e3), (long)(fmod(left, 1e3) * 1e6)};
            nanosleep(&ts, NULL);
        }
        /* measured outside the update's time: the converged state after this frame's edits, and the
         * distance of the updater's lightmap from it */
        if (edited) {
            memcpy(b->before, b->converged, 4 * b->texels * sizeof *b->before);
            if (!converge(b))
                return 0;
            mark_reach(b);
        }
        if (!read_changed_rects(b, &rows[f]))
            return 0;
        count_rewritten(b, &rows[f]);
        double read = 1e3 * lm_cli_now();
        if (lmgi_get_lightmap(b->u, LMGI_LIGHTMAP_IIM, b->iim, 4 * b->texels, &e) != LMGI_OK)
            return fprintf(stderr, "lmgi: %s\n", e.message), 0;
        rows[f].ms_read_whole = 1e3 * lm_cli_now() - read;
        if (fc && next > 0 && !frame_error(b, fc, &rows[f].frame_error))
            return 0;
        rows[f].error = distance(b->iim, b->converged, b->texels);
        rows[f].worst_surface = worst_surface(b->iim, b->converged, b->texels, b->surface_of, b->surfaces, b->sums);
    }
    return 1;
}

void lm_edit_lag(const lm_edit_frame *rows, int from, int to, double limit, lm_lag_metric by, int *frames,
                 double *ms)
{
    double sum = 0.0;
    for (int f = from; f < to; f++) {
        sum += rows[f].ms_total;
        double e = by == LM_LAG_FRAME ? rows[f].frame_error
                   : by == LM_LAG_WORST_SURFACE ? rows[f].worst_surface
                                                : rows[f].error;
        if (e < limit) {
            *frames = f - from + 1, *ms = sum;
            return;
        }
    }
    *frames = -1, *ms = sum;
}

void lm_edit_describe(const cJSON *e, char *out, size_t n)
{
    static const char *const kinds[5] = {"light", "node", "material", "add_light", "remove_light"};
    for (int k = 0; k < 5; k++) {
        const char *v = string_of(e, kinds[k]);
        if (v) {
            snprintf(out, n, "%s %s", kinds[k], v);
            return;
        }
    }
    snprintf(out, n, "?");
}

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

static const char *skip_space(const char *p, const char *end)
{
    while (p < end && is_space(*p))
        p++;
    return p;
}

/* Says where text (n bytes) stops being JSON, at `stop`, as the line and column an editor shows, and
 * what is there: cJSON gives the place but not the reason. */
static void not_json(const char *path, const char *text, size_t n, const char *stop, const char *what)
{
    int line = 1, col = 1;
    for (const char *q = text; q < stop; q++)
        line += *q == '\n', col = *q == '\n' ? 1 : col + 1;
    char here[64];
    if (what) {
        snprintf(here, sizeof here, "%s", what);
    } else if (skip_space(text, text + n) == text + n) {
        snprintf(here, sizeof here, "no JSON value in it");
    } else if (stop >= text + n) {
        snprintf(here, sizeof here, "the text ends before the JSON value does");
    } else {
        int len = 0; /* the rest of the line, up to 24 characters */
        while (len < 24 && stop + len < text + n && stop[len] != '\n' && stop[len] != '\r')
            len++;
        snprintf(here, sizeof here, "not valid JSON from \"%.*s\"", len, stop);
    }
    fprintf(stderr, "lmgi: %s: line %d, column %d: %s\n", path, line, col, here);
}

/* text: n bytes and a NUL after them. cJSON reads the NUL too (n + 1 bytes): it reports a stop at the end
 * of its buffer as the buffer's last byte, so a text cut short is then placed at its end, not on its last
 * character. It does not require the NUL right after the value: text after a whole value is checked
 * here, to be told apart from text that is not JSON and said where it starts. */
static cJSON *parse_text(const char *path, const char *text, size_t n)
{
    const char *nul = memchr(text, '\0', n);
    if (nul) {
        not_json(path, text, n, nul, "a NUL byte, which JSON text never holds");
        return NULL;
    }
    const char *stop = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, n + 1, &stop, 0);
    if (!stop || stop < text || stop > text + n)
        stop = text + n;
    if (!root) {
        not_json(path, text, n, stop, NULL);
        return NULL;
    }
    stop = skip_space(stop, text + n);
    if (stop != text + n) {
        not_json(path, text, n, stop, "text after the value");
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

static cJSON *read_script(const char *path)
{
    size_t n = 0;
    char *text = lm_cli_read_file(path, (1u << 20) - 1, &n);
    if (!text) {
        fprintf(stderr, "lmgi: %s: %s\n", path, errno == ENOMEM ? "out of memory" : errno == EFBIG ? "larger than 1 MiB"
                                                                                    : "cannot read the edit script");
        return NULL;
    }
    cJSON *root = parse_text(path, text, n);
    free(text);
    return root;
}

int lm_edit_script_read(const char *path, lm_edit_script *s)
{
    memset(s, 0, sizeof *s);
    s->path = path;
    s->root = read_script(path);
    if (!s->root || !parse_script(path, s->root, s)) {
        lm_edit_script_free(s);
        return 0;
    }
    return 1;
}

void lm_edit_script_free(lm_edit_script *s)
{
    cJSON_Delete(s->root);
    s->root = NULL;
    s->edit_count = 0;
}

int lm_edit_script_play(const lm_edit_script *s, const char *scene_path, const lmgi_updater_desc *d,
                        float budget_ms, const lm_edit_frame_check *fc, lm_edit_frame *rows)
{
    bench b;
    memset(&b, 0, sizeof b);
    int ok = setup(scene_path, s, d, &b) && play(s, budget_ms, fc, &b, rows);
    teardown(&b);
    return ok;
}

int lm_edit_span(const lm_edit_script *s, int i, int *from, int *to)
{
    *from = s->edits[i].frame;
    *to = i + 1 < s->edit_count ? s->edits[i + 1].frame : s->frames;
    return !(i + 1 < s->edit_count && *to == *from);
}
