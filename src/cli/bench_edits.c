/* lmgi bench --edits SCRIPT.json SCENE: a scripted edit sequence through the public updater (lmgi.h
 * only), timed per update, with each edit's update lag against the converged lightmap of the edited
 * scene (a twin scene given the same edits and baked). docs/bench.md describes the script. */
#include "bench_edits.h"

#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "order_stats.h"
#include "json.h"
#include "progress.h"

#define MAX_EDITS 256

typedef struct {
    int frame;
    const json_value *v;   /* the edit's object in the script */
} edit;

typedef struct {
    int frames, fps, texels;
    float budget_ms;
    int edit_count;
    edit edits[MAX_EDITS];
} script;

typedef struct {
    double ms_total, ms_photons, ms_gather, ms_blend;
    uint32_t texels, photons;
    int aim, changed;
    double error;          /* relative L1 distance of the IIM from the converged one */
} frame_row;

static int bad(const char *path, int i, const char *what)
{
    if (i >= 0)
        fprintf(stderr, "lmgi: %s: edit %d: %s\n", path, i, what);
    else
        fprintf(stderr, "lmgi: %s: %s\n", path, what);
    return 0;
}

static double number_or(const json_value *root, const char *key, double fallback)
{
    const json_value *v = json_get(root, key);
    return v && v->type == JSON_NUMBER ? v->number : fallback;
}

static int parse_script(const char *path, const json_value *root, script *s)
{
    if (root->type != JSON_OBJECT)
        return bad(path, -1, "the script must be a JSON object with an \"edits\" array");
    s->frames = (int)number_or(root, "frames", 120);
    s->fps = (int)number_or(root, "fps", 60);
    s->texels = (int)number_or(root, "texels", 3000);
    s->budget_ms = (float)number_or(root, "budget_ms", 8.0);
    if (s->frames < 1 || s->frames > 100000 || s->fps < 0 || s->fps > 1000 || s->texels < 64 ||
        !(s->budget_ms >= 0.0f && s->budget_ms < 1e4f))
        return bad(path, -1, "frames (1..100000), fps (0..1000), texels (>= 64) or budget_ms (>= 0) out of range");
    const json_value *edits = json_get(root, "edits");
    if (!edits || edits->type != JSON_ARRAY || edits->count > MAX_EDITS)
        return bad(path, -1, "\"edits\" must be an array of at most 256 edits");
    s->edit_count = (int)edits->count;
    for (int i = 0; i < s->edit_count; i++) {
        const json_value *e = &edits->items[i];
        const json_value *f = json_get(e, "frame");
        if (!f || f->type != JSON_NUMBER || f->number < 0 || f->number >= s->frames)
            return bad(path, i, "needs a \"frame\" within the script's frames");
        if (i > 0 && f->number < s->edits[i - 1].frame)
            return bad(path, i, "edits must come in frame order");
        s->edits[i] = (edit){(int)f->number, e};
    }
    return 1;
}

/* n floats from a JSON array, each finite. */
static int floats(const json_value *v, float *out, size_t n)
{
    if (!v || v->type != JSON_ARRAY || v->count != n)
        return 0;
    for (size_t i = 0; i < n; i++) {
        if (v->items[i].type != JSON_NUMBER || !isfinite(v->items[i].number))
            return 0;
        out[i] = (float)v->items[i].number;
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
static int apply(const char *path, int i, const json_value *e, lmgi_scene *sc)
{
    lmgi_error err;
    const json_value *light = json_get(e, "light"), *node = json_get(e, "node"), *mat = json_get(e, "material");
    lmgi_status st = LMGI_OK;
    if (light && light->type == JSON_STRING) {
        int l = light_of_node(sc, light->string);
        lmgi_light li;
        if (l < 0 || lmgi_get_light(sc, l, &li, &err) != LMGI_OK)
            return bad(path, i, "no light on that node");
        const json_value *v;
        if ((v = json_get(e, "intensity")) && v->type == JSON_NUMBER)
            li.intensity = (float)v->number;
        if ((v = json_get(e, "enabled")) && v->type == JSON_BOOL)
            li.enabled = v->number != 0.0;
        if ((v = json_get(e, "color")) && !floats(v, li.color, 3))
            return bad(path, i, "\"color\" must be 3 numbers");
        st = lmgi_set_light(sc, l, &li, &err);
    } else if (node && node->type == JSON_STRING) {
        int n = lmgi_find_node(sc, node->string);
        float world[16], move[3];
        if (n < 0 || !lmgi_get_node_transform(sc, n, world))
            return bad(path, i, "no node of that name");
        if (!floats(json_get(e, "translate"), move, 3))
            return bad(path, i, "a node edit needs \"translate\": [x, y, z]");
        for (int k = 0; k < 3; k++)
            world[12 + k] += move[k];
        st = lmgi_set_node_transform(sc, n, world, &err);
    } else if (mat && mat->type == JSON_STRING) {
        int m = material_named(sc, mat->string);
        lmgi_material mm;
        if (m < 0 || lmgi_get_material(sc, m, &mm, &err) != LMGI_OK)
            return bad(path, i, "no material of that name");
        const json_value *v;
        if ((v = json_get(e, "base_color")) && !floats(v, mm.base_color, 3))
            return bad(path, i, "\"base_color\" must be 3 numbers");
        if ((v = json_get(e, "emissive")) && !floats(v, mm.emissive, 3))
            return bad(path, i, "\"emissive\" must be 3 numbers");
        st = lmgi_set_material(sc, m, &mm, &err);
    } else if ((light = json_get(e, "add_light")) && light->type == JSON_STRING) {
        static const char *const types[3] = {"point", "spot", "directional"};
        lmgi_light li = {.color = {1, 1, 1}, .intensity = 1.0f, .enabled = 1, .direction = {0, -1, 0},
                         .inner_cone = 0.0f, .outer_cone = 0.785398f};
        li.type = (lmgi_light_type)3;
        for (int t = 0; t < 3; t++)
            if (!strcmp(light->string, types[t]))
                li.type = (lmgi_light_type)t;
        const json_value *v;
        if ((int)li.type == 3 || !floats(json_get(e, "position"), li.position, 3))
            return bad(path, i, "\"add_light\" is \"point\", \"spot\" or \"directional\", with a \"position\"");
        if ((v = json_get(e, "direction")) && !floats(v, li.direction, 3))
            return bad(path, i, "\"direction\" must be 3 numbers");
        if ((v = json_get(e, "color")) && !floats(v, li.color, 3))
            return bad(path, i, "\"color\" must be 3 numbers");
        if ((v = json_get(e, "intensity")) && v->type == JSON_NUMBER)
            li.intensity = (float)v->number;
        int id;
        st = lmgi_add_light(sc, &li, &id, &err);
    } else if ((light = json_get(e, "remove_light")) && light->type == JSON_STRING) {
        int l = light_of_node(sc, light->string);
        if (l < 0)
            return bad(path, i, "no light on that node");
        st = lmgi_remove_light(sc, l, &err);
    } else {
        return bad(path, i, "an edit names a \"light\" (its node), a \"node\", a \"material\", \"add_light\" or "
                   "\"remove_light\"");
    }
    return st == LMGI_OK ? 1 : bad(path, i, err.message);
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

typedef struct {
    lmgi_context *ctx;
    lmgi_scene *sc, *twin;
    lmgi_updater *u, *ref;
    float *iim, *converged;
    size_t texels;
} bench;

static int setup(const lm_cli_args *a, const script *s, bench *b)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = s->texels;
    lmgi_error e;
    lmgi_updater_desc d = {0};
    if (lmgi_context_create(NULL, &b->ctx, &e) != LMGI_OK || lmgi_load(a->files[0], &o, &b->sc, &e) != LMGI_OK ||
        lmgi_load(a->files[0], &o, &b->twin, &e) != LMGI_OK ||
        lmgi_updater_create(b->ctx, b->sc, &d, &b->u, &e) != LMGI_OK ||
        lmgi_updater_create(b->ctx, b->twin, &d, &b->ref, &e) != LMGI_OK) {
        fprintf(stderr, "lmgi: bench: %s\n", e.message);
        return 0;
    }
    lmgi_info in;
    lmgi_get_info(b->sc, &in);
    b->texels = (size_t)in.atlas_width * in.atlas_height;
    b->iim = malloc(4 * b->texels * sizeof *b->iim);
    b->converged = malloc(4 * b->texels * sizeof *b->converged);
    return b->iim && b->converged;
}

static void teardown(bench *b)
{
    free(b->iim);
    free(b->converged);
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
        fprintf(stderr, "lmgi: bench: %s\n", e.message);
        return 0;
    }
    return 1;
}

static int play(const lm_cli_args *a, const script *s, bench *b, frame_row *rows)
{
    const char *path = a->edits_path;
    int next = 0;
    if (!converge(b))
        return 0;
    for (int f = 0; f < s->frames; f++) {
        double start = 1e3 * lm_cli_now();
        int edited = 0;
        for (; next < s->edit_count && s->edits[next].frame == f; next++, edited = 1)
            if (!apply(path, next, s->edits[next].v, b->sc) || !apply(path, next, s->edits[next].v, b->twin))
                return 0;
        lmgi_update_stats st;
        lmgi_error e;
        if (lmgi_update(b->u, 0.0f, s->budget_ms, &st, &e) != LMGI_OK) {
            fprintf(stderr, "lmgi: bench: %s\n", e.message);
            return 0;
        }
        rows[f] = (frame_row){st.ms_total, st.ms_photons, st.ms_gather, st.ms_blend, st.texels_gathered,
                              st.photons_retraced, st.aim_surfaces_refreshed, st.surfaces_changed, 0.0};
        double spent = 1e3 * lm_cli_now() - start;
        if (s->fps > 0 && spent < 1e3 / s->fps) { /* the game's own frame, with the photon work beside it */
            double left = 1e3 / s->fps - spent;
            struct timespec ts = {(time_t)(left / 1e3), (long)(fmod(left, 1e3) * 1e6)};
            nanosleep(&ts, NULL);
        }
        /* measured outside the update's time: the converged state after this frame's edits, and the
         * distance of the updater's lightmap from it */
        if (edited && !converge(b))
            return 0;
        if (lmgi_get_lightmap(b->u, LMGI_LIGHTMAP_IIM, b->iim, 4 * b->texels, &e) != LMGI_OK)
            return fprintf(stderr, "lmgi: bench: %s\n", e.message), 0;
        rows[f].error = distance(b->iim, b->converged, b->texels);
    }
    return 1;
}

/* Frames and update milliseconds from an edit's frame until the error is under `limit` (-1: never). */
static void lag(const frame_row *rows, int from, int to, double limit, int *frames, double *ms)
{
    double sum = 0.0;
    for (int f = from; f < to; f++) {
        sum += rows[f].ms_total;
        if (rows[f].error < limit) {
            *frames = f - from + 1, *ms = sum;
            return;
        }
    }
    *frames = -1, *ms = sum;
}

static void describe(const json_value *e, char *out, size_t n)
{
    static const char *const kinds[5] = {"light", "node", "material", "add_light", "remove_light"};
    for (int k = 0; k < 5; k++) {
        const json_value *v = json_get(e, kinds[k]);
        if (v && v->string) {
            snprintf(out, n, "%s %s", kinds[k], v->string);
            return;
        }
    }
    snprintf(out, n, "?");
}

static void report(const lm_cli_args *a, const script *s, const frame_row *rows)
{
    printf("lmgi bench --edits %s %s: %d updates, budget %.1f ms, %d fps, %d texels\n", a->edits_path, a->files[0],
           s->frames, (double)s->budget_ms, s->fps, s->texels);
    printf("%-28s %6s %10s %14s %14s\n", "edit", "frame", "error", "to 5%", "to 2%");
    FILE *json = a->json_path ? fopen(a->json_path, "w") : NULL;
    if (json)
        fprintf(json, "{\n  \"script\": \"%s\", \"scene\": \"%s\", \"budget_ms\": %g,\n  \"edits\": [\n",
                a->edits_path, a->files[0], (double)s->budget_ms);
    for (int i = 0; i < s->edit_count; i++) {
        int from = s->edits[i].frame, to = i + 1 < s->edit_count ? s->edits[i + 1].frame : s->frames;
        if (i + 1 < s->edit_count && to == from)
            continue; /* several edits in one frame: the last one reports */
        int f5, f2;
        double ms5, ms2;
        lag(rows, from, to, 0.05, &f5, &ms5);
        lag(rows, from, to, 0.02, &f2, &ms2);
        char what[128], l5[48], l2[48];
        describe(s->edits[i].v, what, sizeof what);
        snprintf(l5, sizeof l5, f5 < 0 ? "not in %d fr" : "%d fr %.0f ms", f5 < 0 ? to - from : f5, ms5);
        snprintf(l2, sizeof l2, f2 < 0 ? "not in %d fr" : "%d fr %.0f ms", f2 < 0 ? to - from : f2, ms2);
        printf("%-28s %6d %9.1f%% %14s %14s\n", what, from, 100.0 * rows[from].error, l5, l2);
        if (json)
            fprintf(json, "    {\"edit\": \"%s\", \"frame\": %d, \"error\": %.5f, \"frames_to_5\": %d, \"ms_to_5\": %.2f, "
                    "\"frames_to_2\": %d, \"ms_to_2\": %.2f}%s\n", what, from, rows[from].error, f5, ms5, f2, ms2,
                    i + 1 < s->edit_count ? "," : "");
    }
    double *ms = malloc(sizeof *ms * (size_t)s->frames);
    int over = 0;
    double texels = 0.0;
    for (int f = 0; ms && f < s->frames; f++) {
        ms[f] = rows[f].ms_total;
        over += s->budget_ms > 0.0f && rows[f].ms_total > 1.1 * s->budget_ms;
        texels += rows[f].texels;
    }
    if (ms) {
        double p95 = lm_cli_quantile(ms, s->frames, 0.95); /* sorts ms */
        printf("updates: median %.2f ms, 95th percentile %.2f ms, worst %.2f ms; %d of %d over the budget by more "
               "than 10%%; %.1f texels an update\n", ms[s->frames / 2], p95,
               ms[s->frames - 1], over, s->frames, texels / s->frames);
    }
    if (json) {
        fprintf(json, "  ],\n  \"frames\": [\n");
        for (int f = 0; f < s->frames; f++)
            fprintf(json, "    {\"ms\": %.3f, \"photons_ms\": %.3f, \"gather_ms\": %.3f, \"blend_ms\": %.3f, "
                    "\"texels\": %u, \"photons\": %u, \"aim_surfaces\": %d, \"surfaces_changed\": %d, "
                    "\"error\": %.5f}%s\n", rows[f].ms_total, rows[f].ms_photons, rows[f].ms_gather, rows[f].ms_blend,
                    rows[f].texels, rows[f].photons, rows[f].aim, rows[f].changed, rows[f].error,
                    f + 1 < s->frames ? "," : "");
        fprintf(json, "  ]\n}\n");
        if (fclose(json) != 0)
            fprintf(stderr, "lmgi: bench: %s: write failed\n", a->json_path);
    }
    free(ms);
}

static json_value *read_script(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "lmgi: %s: cannot read the edit script\n", path);
        return NULL;
    }
    char *text = malloc(1 << 20);
    size_t n = text ? fread(text, 1, 1 << 20, f) : 0;
    int too_big = text && n == 1 << 20;
    fclose(f);
    char err[512];
    json_value *root = text && !too_big ? json_parse(text, n, err, sizeof err) : NULL;
    if (!root)
        fprintf(stderr, "lmgi: %s: %s\n", path, !text ? "out of memory" : too_big ? "larger than 1 MiB" : err);
    free(text);
    return root;
}

int lm_cli_bench_edits(const lm_cli_args *a)
{
    if (a->file_count != 1) {
        fprintf(stderr, "lmgi: bench --edits SCRIPT.json takes one scene\n");
        return 2;
    }
    json_value *root = read_script(a->edits_path);
    script s;
    if (!root || !parse_script(a->edits_path, root, &s)) {
        json_free(root);
        return 1;
    }
    bench b;
    memset(&b, 0, sizeof b);
    frame_row *rows = calloc((size_t)s.frames, sizeof *rows);
    int ok = rows && setup(a, &s, &b) && play(a, &s, &b, rows);
    if (ok)
        report(a, &s, rows);
    teardown(&b);
    free(rows);
    json_free(root);
    return ok ? 0 : 1;
}
