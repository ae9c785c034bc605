/* Structured fuzzing of the public API's call sequences, beside fuzz_loader (bytes) and fuzz_pipeline
 * (files): through include/lmgi.h alone, a scene with an updater gets random calls in random order with
 * values drawn from the valid range, its edges, and past them (NaN, infinities, 1e30, negatives, ids out
 * of range): updates and bakes, node transforms, light edits, additions and removals, material edits, the
 * sky, node effects, renders from random cameras, lightmap reads of every kind, the updater freed and made
 * again, the scene's time. Built and run under ASan + UBSan.
 *
 * A call passes when it returns LMGI_OK, or an error whose message is not empty; never an abort, a
 * sanitizer report, LMGI_ERR_BACKEND (a stage that made a NaN or infinity: lmgi_update and
 * lmgi_get_lightmap check), a non-finite value in a frame or lightmap it returned, or more than 10 s.
 *
 * LMGI_FUZZ_API_SEQUENCES (default 3: the slice in make test) sequences of LMGI_FUZZ_API_STEPS calls
 * (default 60), from LMGI_FUZZ_SEED (default 1); make fuzz runs more over several seeds. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <lmgi.h>
#include <math.h>

#include "../src/core/timing.h"
#include "support.h"

#define SLOW_SECONDS 10.0
#define SIDE 24

static uint32_t g_rng;

static uint32_t rnd(void) { return lmt_xorshift(&g_rng); }
static int below(int n) { return n > 0 ? (int)(rnd() % (uint32_t)n) : 0; }
static float unit(void) { return (float)(rnd() >> 8) / 16777216.0f; }

/* A value for a parameter whose valid range is [lo, hi]: mostly inside, sometimes its edges, sometimes far
 * past them or not a number at all. */
static float value(float lo, float hi)
{
    static const float wild[] = {NAN, INFINITY, -INFINITY, 1e30f, -1e30f, -1.0f, 1e-30f, 3.4e38f, 0.0f};
    int pick = below(20);
    if (pick < 14)
        return lo + (hi - lo) * unit();
    if (pick < 16)
        return pick == 14 ? lo : hi;
    return wild[below((int)(sizeof wild / sizeof *wild))];
}

static int id(int count) { return below(8) == 0 ? (below(2) ? -1 - below(3) : count + below(3)) : below(count); }

typedef struct {
    lmgi_context *ctx;
    lmgi_scene *sc;
    lmgi_updater *u;
    float time;
    int calls, refused;
    char last[96]; /* the call under way, for the failure message */
} session;

/* A status and its message: OK, or an error that says something; never a stage that made a NaN. */
static void judge(session *s, lmgi_status st, const lmgi_error *e)
{
    s->calls++;
    if (st == LMGI_OK)
        return;
    s->refused++;
    if (st == LMGI_ERR_BACKEND || !e->message[0])
        fail_msg("%s: status %s, \"%s\"", s->last, lmgi_status_name(st), e->message);
}

static void all_finite(const session *s, const float *v, size_t n, const char *what)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            fail_msg("%s: %s value %zu is %g", s->last, what, i, (double)v[i]);
}

static void make_updater(session *s)
{
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.photons.count = 3000;
    d.gather.resolution = 16;
    d.gather.rim_samples = 4;
    d.gather.emitter_rays = 2;
    d.frame.reflection_size = 8;
    d.caustics.photons = 2000;
    d.frame.width = d.frame.height = SIDE;
    lmgi_error e;
    snprintf(s->last, sizeof s->last, "lmgi_updater_create");
    judge(s, lmgi_updater_create(s->ctx, s->sc, &d, &s->u, &e), &e);
}

static void random_matrix(float m[16])
{
    float a = value(-3.2f, 3.2f), k = below(4) ? 1.0f : value(0.01f, 4.0f);
    memset(m, 0, 16 * sizeof *m);
    m[0] = k * cosf(a), m[2] = -k * sinf(a), m[5] = k, m[8] = k * sinf(a), m[10] = k * cosf(a), m[15] = 1.0f;
    for (int i = 12; i < 15; i++)
        m[i] = value(-2.0f, 2.0f);
    if (below(10) == 0)
        m[below(16)] = value(-1.0f, 1.0f); /* shear, a zero scale, a NaN */
}

static void edit_light(session *s, lmgi_error *e)
{
    int n = lmgi_light_count(s->sc), which = below(3);
    lmgi_light l;
    memset(&l, 0, sizeof l);
    if (which == 0 || n == 0) { /* add */
        l.type = (lmgi_light_type)below(3);
        for (int k = 0; k < 3; k++)
            l.color[k] = value(0.0f, 1.0f), l.position[k] = value(-1.0f, 1.0f), l.direction[k] = value(-1.0f, 1.0f);
        l.intensity = value(0.0f, 20.0f), l.range = below(2) ? 0.0f : value(0.0f, 10.0f);
        l.inner_cone = value(0.0f, 0.7f), l.outer_cone = value(0.0f, 1.5f), l.enabled = below(4) != 0;
        int got;
        snprintf(s->last, sizeof s->last, "lmgi_add_light");
        judge(s, lmgi_add_light(s->sc, &l, &got, e), e);
        return;
    }
    int light = id(n);
    if (which == 1) {
        snprintf(s->last, sizeof s->last, "lmgi_remove_light %d", light);
        judge(s, lmgi_remove_light(s->sc, light, e), e);
        return;
    }
    snprintf(s->last, sizeof s->last, "lmgi_set_light %d", light);
    if (lmgi_get_light(s->sc, light, &l, e) != LMGI_OK) {
        judge(s, LMGI_ERR_INVALID, e);
        return;
    }
    l.intensity = below(2) ? l.intensity * value(0.0f, 2.0f) : value(0.0f, 50.0f);
    l.color[below(3)] = value(0.0f, 1.0f);
    l.enabled = below(5) != 0;
    judge(s, lmgi_set_light(s->sc, light, &l, e), e);
}

static void edit_material(session *s, lmgi_error *e)
{
    int m = id(lmgi_material_count(s->sc));
    lmgi_material mat;
    snprintf(s->last, sizeof s->last, "lmgi_set_material %d", m);
    if (lmgi_get_material(s->sc, m, &mat, e) != LMGI_OK) {
        judge(s, LMGI_ERR_INVALID, e);
        return;
    }
    mat.base_color[below(3)] = value(0.0f, 1.0f);
    if (below(3) == 0)
        mat.emissive[below(3)] = value(0.0f, 10.0f);
    if (below(4) == 0)
        mat.roughness = value(0.0f, 1.0f), mat.metallic = value(0.0f, 1.0f);
    judge(s, lmgi_set_material(s->sc, m, &mat, e), e);
}

static void read_lightmap(session *s, lmgi_error *e)
{
    lmgi_info in;
    lmgi_get_info(s->sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *rgba = malloc(n * sizeof *rgba);
    assert_non_null(rgba);
    lmgi_lightmap kind = (lmgi_lightmap)below(4);
    snprintf(s->last, sizeof s->last, "lmgi_get_lightmap %d", (int)kind);
    lmgi_status st = lmgi_get_lightmap(s->u, kind, rgba, n - (below(10) == 0), e); /* now and then one short */
    judge(s, st, e);
    if (st == LMGI_OK)
        all_finite(s, rgba, n, "lightmap");
    free(rgba);
}

static void render(session *s, lmgi_error *e)
{
    lmgi_camera cam;
    snprintf(s->last, sizeof s->last, "lmgi_render");
    lmgi_status st = lmgi_scene_camera(s->sc, below(4) ? -1 : id(1), SIDE, SIDE, &cam, e);
    if (st == LMGI_OK && below(3) == 0)
        cam.view[12 + below(3)] += value(-5.0f, 5.0f);
    float rgb[3 * SIDE * SIDE];
    if (st == LMGI_OK)
        st = lmgi_render(s->u, &cam, SIDE, SIDE, rgb, e);
    judge(s, st, e);
    if (st == LMGI_OK)
        all_finite(s, rgb, 3 * SIDE * SIDE, "render");
}

static void step(session *s)
{
    lmgi_error e;
    memset(&e, 0, sizeof e);
    int op = below(13);
    if (!s->u && op != 9)
        op = 12;
    switch (op) {
    case 0:
    case 1:
    case 2: { /* the most common call: an update, at a time that moves on (or not) */
        s->time += below(4) ? 1.0f / 30.0f : value(-1.0f, 1.0f);
        lmgi_update_stats st;
        float budget = below(3) ? 0.0f : value(0.0f, 20.0f);
        snprintf(s->last, sizeof s->last, "lmgi_update t=%g budget=%g", (double)s->time, (double)budget);
        lmgi_status r = lmgi_update(s->u, s->time, budget, &st, &e);
        judge(s, r, &e);
        int w, h;
        const float *img = lmgi_frame(s->u, &w, &h);
        if (r == LMGI_OK && img)
            all_finite(s, img, 3 * (size_t)w * h, "frame");
        break;
    }
    case 3: {
        int node = id(lmgi_node_count(s->sc));
        float m[16];
        random_matrix(m);
        snprintf(s->last, sizeof s->last, "lmgi_set_node_transform %d", node);
        judge(s, lmgi_set_node_transform(s->sc, node, m, &e), &e);
        break;
    }
    case 4:
        edit_light(s, &e);
        break;
    case 5:
        edit_material(s, &e);
        break;
    case 6: {
        float sky[3] = {value(0.0f, 2.0f), value(0.0f, 2.0f), value(0.0f, 2.0f)};
        snprintf(s->last, sizeof s->last, "lmgi_set_environment");
        judge(s, lmgi_set_environment(s->sc, sky, &e), &e);
        break;
    }
    case 7:
        read_lightmap(s, &e);
        break;
    case 8:
        render(s, &e);
        break;
    case 9: /* the updater goes, a bake-like pause, and it comes back */
        snprintf(s->last, sizeof s->last, "lmgi_updater_free");
        lmgi_updater_free(s->u);
        s->u = NULL;
        break;
    case 10: {
        lmgi_node_effects fx = {below(2), below(2), below(2), below(8) ? below(2) : 7};
        int node = id(lmgi_node_count(s->sc));
        snprintf(s->last, sizeof s->last, "lmgi_set_node_effects %d", node);
        judge(s, lmgi_set_node_effects(s->sc, node, &fx, &e), &e);
        break;
    }
    case 11: {
        snprintf(s->last, sizeof s->last, "lmgi_bake");
        lmgi_bake_report r;
        judge(s, lmgi_bake(s->u, NULL, &r, &e), &e);
        break;
    }
    default:
        if (!s->u)
            make_updater(s);
        else {
            float t = value(-2.0f, 5.0f);
            snprintf(s->last, sizeof s->last, "lmgi_set_time %g", (double)t);
            judge(s, lmgi_set_time(s->sc, t, &e), &e);
        }
    }
}

static int env_int(const char *name, int fallback)
{
    const char *v = getenv(name);
    return v && atoi(v) > 0 ? atoi(v) : fallback;
}

static void test_fuzz_api(void **state)
{
    (void)state;
    int sequences = env_int("LMGI_FUZZ_API_SEQUENCES", 3), steps = env_int("LMGI_FUZZ_API_STEPS", 60);
    g_rng = 0x9e3779b9u ^ (uint32_t)env_int("LMGI_FUZZ_SEED", 1) * 2654435761u;
    lmgi_set_verbosity(0); /* refusals are counted here, not printed */
    int calls = 0, refused = 0;
    double slowest = 0.0, t0 = lm_now();
    for (int q = 0; q < sequences; q++) {
        session s;
        memset(&s, 0, sizeof s);
        lmgi_error e;
        assert_int_equal(lmgi_context_create(NULL, &s.ctx, &e), LMGI_OK);
        lmgi_options o;
        lmgi_options_init(&o);
        o.target_texels = 600;
        static const char *const scenes[2] = {"cornell.glb", "two_rooms.glb"};
        if (lmgi_load(lmt_project_scene(scenes[q % 2]), &o, &s.sc, &e) != LMGI_OK)
            fail_msg("%s", e.message);
        make_updater(&s);
        for (int k = 0; k < steps; k++) {
            double t = lm_now();
            step(&s);
            double took = lm_now() - t;
            slowest = took > slowest ? took : slowest;
            if (took > SLOW_SECONDS)
                fail_msg("sequence %d step %d: %s took %.1f s", q, k, s.last, took);
        }
        lmgi_updater_free(s.u);
        lmgi_free(s.sc);
        lmgi_context_free(s.ctx);
        calls += s.calls, refused += s.refused;
    }
    print_message("fuzz_api: %d sequences, %d calls, %d refused with a message, slowest %.2f s, %.1f s in all\n",
                  sequences, calls, refused, slowest, lm_now() - t0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_fuzz_api)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
