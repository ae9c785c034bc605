/* The public updater API through the public headers alone: contexts and their logs, updaters on one or two
 * contexts giving the same frames, lmgi_render against the update's own frame, the lightmaps and their
 * change counters, the time budget, and every bad argument refused without changing anything. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi_tools.h>
#include <stb/stb_image.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <time.h>

#include "edit_room.h"
#include "support.h"

#define SIDE 40

static lmgi_context *new_context(void)
{
    lmgi_context *ctx = NULL;
    lmgi_error e;
    if (lmgi_context_create(NULL, &ctx, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return ctx;
}

/* Frees what a test made, in the order the API asks: the updater before its scene and context. */
static void close_all(lmgi_updater *u, lmgi_scene *sc, lmgi_context *ctx)
{
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* One of the project's scenes at a texel budget. */
static lmgi_scene *load_scene(const char *name, int texels) { return lmt_load(lmt_project_scene(name), texels); }

static lmgi_scene *load_cornell(void) { return load_scene("cornell.glb", 1500); }

static void small_desc(lmgi_updater_desc *d)
{
    memset(d, 0, sizeof *d);
    d->photons.count = 6000;
    d->gather.resolution = 16;
    d->gather.rim_samples = 8;
    d->gather.emitter_rays = 4;
    d->frame.reflection_size = 16;
    d->frame.width = d->frame.height = SIDE;
}

static lmgi_updater *make_updater(lmgi_context *ctx, lmgi_scene *sc, const lmgi_updater_desc *d)
{
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

/* An updater with no frame of its own (a game draws its own) and 200 texels an update. */
static lmgi_updater *frameless_updater(lmgi_context *ctx, lmgi_scene *sc)
{
    lmgi_updater_desc d;
    small_desc(&d);
    d.frame.width = d.frame.height = 0;
    d.gather.texels_per_frame = 200;
    return make_updater(ctx, sc, &d);
}

static void update(lmgi_updater *u, float t, float budget, lmgi_update_stats *st)
{
    lmgi_error e;
    if (lmgi_update(u, t, budget, st, &e) != LMGI_OK)
        fail_msg("%s", e.message);
}

static void expect_invalid(lmgi_status st, const lmgi_error *e, const char *words)
{
    assert_int_equal(st, LMGI_ERR_INVALID);
    if (!strstr(e->message, words))
        fail_msg("'%s' does not name '%s'", e->message, words);
}

typedef struct {
    int count[5];
    char last[256];
} log_record;

static void record(void *user, lmgi_log_level level, const char *message)
{
    log_record *r = user;
    r->count[level]++;
    snprintf(r->last, sizeof r->last, "%s", message);
}

static void test_context(void **state)
{
    (void)state;
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    assert_true(strstr(lmgi_context_gl_description(ctx), "4.") != NULL); /* a GL 4.x context */
    lmgi_context_free(ctx);
    lmgi_context_free(NULL);
    assert_string_equal(lmgi_context_gl_description(NULL), "");
    assert_int_equal(lmgi_context_create(NULL, NULL, &e), LMGI_ERR_INVALID);
    lmgi_context_desc d = {.gl_backend = "vulkan"};
    ctx = (lmgi_context *)&d; /* must be reset to NULL on failure */
    assert_int_equal(lmgi_context_create(&d, &ctx, &e), LMGI_ERR_INVALID);
    assert_null(ctx);
    assert_non_null(strstr(e.message, "vulkan"));
    d = (lmgi_context_desc){.log_level = 9};
    assert_int_equal(lmgi_context_create(&d, &ctx, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "log level 9"));
}

/* A context's messages reach its callback, at its level and no other's. */
static void test_log_callback(void **state)
{
    (void)state;
    log_record info, quiet;
    memset(&info, 0, sizeof info);
    memset(&quiet, 0, sizeof quiet);
    lmgi_context_desc d = {.log = record, .log_user = &info, .log_level = LMGI_LOG_INFO};
    lmgi_context_desc q = {.log = record, .log_user = &quiet, .log_level = LMGI_LOG_WARN};
    lmgi_context *a = NULL, *b = NULL;
    assert_int_equal(lmgi_context_create(&d, &a, NULL), LMGI_OK);
    assert_int_equal(lmgi_context_create(&q, &b, NULL), LMGI_OK);
    lmgi_scene *s1 = load_cornell(), *s2 = load_cornell();
    lmgi_updater_desc ud;
    small_desc(&ud);
    lmgi_updater *u1 = make_updater(a, s1, &ud), *u2 = make_updater(b, s2, &ud);
    assert_int_equal(info.count[LMGI_LOG_INFO], 1);
    assert_non_null(strstr(info.last, "updater ready"));
    assert_int_equal(quiet.count[LMGI_LOG_INFO], 0); /* below its level */
    lmgi_updater_free(u1);
    lmgi_updater_free(u2);
    lmgi_free(s1);
    lmgi_free(s2);
    lmgi_context_free(a);
    lmgi_context_free(b);
}

static double max_diff(const float *a, const float *b, size_t n)
{
    double m = 0.0;
    for (size_t i = 0; i < n; i++)
        m = fmax(m, fabs((double)a[i] - b[i]));
    return m;
}

/* Two updaters, each on its own context, updated in turn on one thread give the frames one alone gives:
 * every call makes its own GL context current. And lmgi_render from the same camera repeats the frame. */
static void test_two_contexts_one_thread(void **state)
{
    (void)state;
    lmgi_context *a = NULL, *b = NULL;
    assert_int_equal(lmgi_context_create(NULL, &a, NULL), LMGI_OK);
    assert_int_equal(lmgi_context_create(NULL, &b, NULL), LMGI_OK);
    lmgi_scene *s1 = load_cornell(), *s2 = load_cornell();
    lmgi_updater_desc d;
    small_desc(&d);
    lmgi_updater *u1 = make_updater(a, s1, &d);
    lmgi_updater *u2 = make_updater(b, s2, &d);
    size_t n = 3 * SIDE * SIDE;
    float *f1 = malloc(n * sizeof *f1), *again = malloc(n * sizeof *again);
    for (int f = 0; f < 3; f++) {
        float t = 0.2f * (float)f;
        update(u1, t, 0.0f, NULL);
        memcpy(f1, lmgi_frame(u1, NULL, NULL), n * sizeof *f1);
        update(u2, t, 0.0f, NULL);
        int w = 0, h = 0;
        const float *f2 = lmgi_frame(u2, &w, &h);
        assert_int_equal(w, SIDE);
        assert_int_equal(h, SIDE);
        assert_true(max_diff(f1, f2, n) == 0.0);
    }
    lmgi_camera cam;
    assert_int_equal(lmgi_scene_camera(s1, -1, SIDE, SIDE, &cam, NULL), LMGI_OK);
    lmgi_error e;
    assert_int_equal(lmgi_render(u1, &cam, SIDE, SIDE, again, &e), LMGI_OK);
    double mean = 0.0;
    for (size_t i = 0; i < n; i++)
        mean += f1[i] / (double)n;
    assert_true(mean > 0.05);
    assert_true(max_diff(f1, again, n) <= 1e-4 * mean);
    free(f1);
    free(again);
    lmgi_updater_free(u1);
    lmgi_updater_free(u2);
    lmgi_free(s1);
    lmgi_free(s2);
    lmgi_context_free(a);
    lmgi_context_free(b);
}

/* The lightmaps: validity 0 or 1 as alpha, finite light on every valid texel and some on most; each
 * surface's rectangle holds its texels; change counters at 1 after the first gather, still while
 * nothing moves once the fade is over, moving when the cube does. */
static void test_lightmaps_and_versions(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *sc = load_cornell();
    lmgi_updater *u = frameless_updater(ctx, sc);
    assert_null(lmgi_frame(u, NULL, NULL));
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = (size_t)in.atlas_width * in.atlas_height;
    float *iim = malloc(4 * n * sizeof *iim), *aim = malloc(4 * n * sizeof *aim);
    lmgi_error e;
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, iim, 4 * n, &e), LMGI_OK);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_AIM, aim, 4 * n, &e), LMGI_OK);
    size_t valid = 0, lit = 0;
    for (size_t i = 0; i < n; i++) {
        assert_true(iim[4 * i + 3] == 0.0f || iim[4 * i + 3] == 1.0f);
        assert_true(aim[4 * i + 3] == iim[4 * i + 3]);
        for (int c = 0; c < 3; c++)
            assert_true(isfinite(iim[4 * i + c]) && iim[4 * i + c] >= 0.0f && isfinite(aim[4 * i + c]));
        valid += iim[4 * i + 3] == 1.0f;
        lit += iim[4 * i + 3] == 1.0f && iim[4 * i] + iim[4 * i + 1] + iim[4 * i + 2] > 0.0f;
    }
    assert_true(valid > in.texels / 2 && valid <= in.texels);
    assert_true(lit > valid * 9 / 10);

    int surfaces = lmgi_surface_count(sc);
    assert_int_equal(surfaces, in.surfaces);
    for (int s = 0; s < surfaces; s++)
        assert_int_equal(lmgi_surface_version(u, s), 1);
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        int r[4];
        assert_true(lmgi_surface_rect(sc, t.surface, r));
        assert_true(t.x >= r[0] && t.x < r[0] + r[2] && t.y >= r[1] && t.y < r[1] + r[3]);
    }
    /* the scene at rest (time 0 throughout): after the first updates' re-traces settle and the fades end,
     * no surface changes */
    lmgi_update_stats st;
    int quiet_run = 0;
    for (int f = 0; f < 60 && quiet_run < 10; f++) {
        update(u, 0.0f, 0.0f, &st);
        quiet_run = st.surfaces_changed == 0 ? quiet_run + 1 : 0;
    }
    assert_int_equal(quiet_run, 10);
    uint32_t before = 0;
    for (int s = 0; s < surfaces; s++)
        before += lmgi_surface_version(u, s);
    int changed = 0;
    for (int f = 1; f <= 10; f++) { /* the cube moves: some surfaces change, and their counters with them */
        update(u, 0.1f * (float)f, 0.0f, &st);
        changed += st.surfaces_changed;
    }
    uint32_t after = 0;
    for (int s = 0; s < surfaces; s++)
        after += lmgi_surface_version(u, s);
    assert_true(changed > 0);
    assert_int_equal(after - before, (uint32_t)changed);
    free(iim);
    free(aim);
    close_all(u, sc, ctx);
}

/* An edit reaches the updater at its next update, relights what it touches, and playing time does not
 * take it back. */
/* The rectangle of lmgi_get_lightmap_rect against the whole read, bit for bit. */
static void expect_rect_matches(lmgi_updater *u, lmgi_lightmap kind, const float *whole, int atlas_w, const int r[4])
{
    float *part = malloc(4 * sizeof(float) * (size_t)r[2] * r[3]);
    assert_non_null(part);
    lmgi_error e;
    if (lmgi_get_lightmap_rect(u, kind, r, part, 4 * (size_t)r[2] * r[3], &e) != LMGI_OK)
        fail_msg("%s", e.message);
    for (int y = 0; y < r[3]; y++)
        if (memcmp(part + 4 * (size_t)y * r[2], whole + 4 * ((size_t)(r[1] + y) * atlas_w + r[0]),
                   4 * sizeof(float) * (size_t)r[2]))
            fail_msg("kind %d, rectangle (%d, %d) %d x %d: row %d differs from the whole read", (int)kind, r[0], r[1],
                     r[2], r[3], y);
    free(part);
}

/* What an engine uploads when a surface's version moves: each surface's lightmap rectangle (its texels
 * and the gutter around them) read alone gives exactly the whole read's values there, for the IIM (its
 * invalid texels filled, under the boxes) and the AIM, after the cube has moved; so do rectangles cut
 * anywhere, at the atlas's edges too. Bad rectangles are refused. */
static void test_lightmap_rect(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *sc = load_cornell();
    lmgi_updater *u = frameless_updater(ctx, sc);
    for (int f = 1; f <= 6; f++)
        update(u, 0.1f * (float)f, 0.0f, NULL);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = (size_t)in.atlas_width * in.atlas_height;
    float *whole = malloc(4 * n * sizeof *whole);
    assert_non_null(whole);
    lmgi_error e;
    const lmgi_lightmap kinds[3] = {LMGI_LIGHTMAP_IIM, LMGI_LIGHTMAP_AIM, LMGI_LIGHTMAP_ERROR};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(lmgi_get_lightmap(u, kinds[k], whole, 4 * n, &e), LMGI_OK);
        int surfaces = lmgi_surface_count(sc), tried = 0;
        for (int s = 0; s < surfaces; s += k == 0 ? 1 : 3) {
            int r[4], t[4];
            assert_int_equal(lmgi_surface_lightmap_rect(sc, s, r), lmgi_surface_rect(sc, s, t));
            if (!r[2])
                continue;
            assert_true(r[0] <= t[0] && r[1] <= t[1] && r[0] + r[2] >= t[0] + t[2] && r[1] + r[3] >= t[1] + t[3]);
            expect_rect_matches(u, kinds[k], whole, in.atlas_width, r);
            tried++;
        }
        assert_true(tried >= 3);
        const int cuts[3][4] = {{0, 0, in.atlas_width, in.atlas_height},
                                {in.atlas_width - 7, in.atlas_height - 5, 7, 5},
                                {in.atlas_width / 3, in.atlas_height / 4, in.atlas_width / 2, 3}};
        for (int c = 0; c < 3; c++)
            expect_rect_matches(u, kinds[k], whole, in.atlas_width, cuts[c]);
        /* single texels under the boxes, filled from their surface's valid texels farther off */
        int under = 0;
        for (uint32_t i = 0; k == 0 && i < in.texels && under < 40; i++) {
            lmgi_texel t;
            lmgi_get_texel(sc, i, &t);
            if (whole[4 * ((size_t)t.y * in.atlas_width + t.x) + 3] != 0.0f)
                continue;
            const int one[4] = {t.x, t.y, 1, 1};
            expect_rect_matches(u, kinds[k], whole, in.atlas_width, one);
            under++;
        }
        if (k == 0)
            print_message("%d invalid texels read alone\n", under);
        assert_true(k != 0 || under >= 5);
    }
    float one[4];
    const int outside[4] = {in.atlas_width - 1, 0, 2, 1}, empty[4] = {0, 0, 0, 1}, fits[4] = {0, 0, 1, 1};
    expect_invalid(lmgi_get_lightmap_rect(u, LMGI_LIGHTMAP_IIM, outside, one, 8, &e), &e, "not inside");
    expect_invalid(lmgi_get_lightmap_rect(u, LMGI_LIGHTMAP_IIM, empty, one, 4, &e), &e, "not inside");
    expect_invalid(lmgi_get_lightmap_rect(u, LMGI_LIGHTMAP_IIM, fits, one, 3, &e), &e, "holds 3 floats");
    expect_invalid(lmgi_get_lightmap_rect(u, (lmgi_lightmap)9, fits, one, 4, &e), &e, "not a lightmap kind");
    expect_invalid(lmgi_get_lightmap_rect(u, LMGI_LIGHTMAP_IIM, NULL, one, 4, &e), &e, "rect is NULL");
    expect_invalid(lmgi_get_lightmap_rect(NULL, LMGI_LIGHTMAP_IIM, fits, one, 4, &e), &e, "NULL");
    int r[4] = {1, 2, 3, 4};
    assert_int_equal(lmgi_surface_lightmap_rect(sc, -1, r), 0);
    assert_true(r[0] == 0 && r[2] == 0);
    free(whole);
    close_all(u, sc, ctx);
}

/* Every page read alone gives the whole read's values in its rectangle, bit for bit. */
static void expect_pages_match(lmgi_updater *u, const lmgi_scene *sc, const lmgi_info *in, lmgi_lightmap kind,
                               const float *whole)
{
    float *page = malloc(4 * sizeof(float) * (size_t)in->page_width * in->page_height);
    assert_non_null(page);
    for (int p = 0; p < in->pages; p++) {
        int r[4];
        lmgi_error e;
        assert_int_equal(lmgi_page_rect(sc, p, r), 1);
        assert_true(r[2] == in->page_width && r[3] == in->page_height);
        if (lmgi_get_lightmap_page(u, kind, p, page, 4 * (size_t)r[2] * r[3], &e) != LMGI_OK)
            fail_msg("%s", e.message);
        for (int y = 0; y < r[3]; y++)
            if (memcmp(page + 4 * (size_t)y * r[2], whole + 4 * ((size_t)(r[1] + y) * in->atlas_width + r[0]),
                       4 * sizeof(float) * (size_t)r[2]))
                fail_msg("kind %d, page %d: row %d differs from the whole read", (int)kind, p, y);
    }
    free(page);
}

/* A texel's page and place there, a triangle's page UVs and a surface's page agree with the page
 * rectangles: each texel inside its page's, each triangle's texels on its page, where its page UVs put
 * them. Returns how many surfaces lie on one page. */
static int check_page_layout(const lmgi_scene *sc, const lmgi_info *in)
{
    int surfaces = lmgi_surface_count(sc), one_page = 0, *page = malloc(sizeof(int) * (size_t)surfaces);
    assert_non_null(page);
    for (int s = 0; s < surfaces; s++)
        one_page += (page[s] = lmgi_surface_page(sc, s)) >= 0;
    for (uint32_t i = 0; i < in->texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        int r[4];
        float uv[6], whole[6];
        assert_int_equal(lmgi_page_rect(sc, t.page, r), 1);
        assert_true(t.page_x == t.x - r[0] && t.page_y == t.y - r[1]);
        assert_true(t.page_x >= 0 && t.page_x < r[2] && t.page_y >= 0 && t.page_y < r[3]);
        assert_int_equal(lmgi_triangle_lightmap_page(sc, t.triangle, uv), t.page);
        assert_true(page[t.surface] < 0 || page[t.surface] == t.page);
        assert_int_equal(lmgi_triangle_lightmap_uv(sc, t.triangle, whole), 1);
        for (int k = 0; k < 6; k++) {
            assert_true(uv[k] >= 0.0f && uv[k] <= 1.0f);
            assert_float_equal(r[k % 2] + uv[k] * r[2 + k % 2], whole[k] * (k % 2 ? in->atlas_height : in->atlas_width),
                               1e-3);
        }
    }
    free(page);
    return one_page;
}

/* Lightmap pages through the API: the Cornell box at 6,000 texels on pages of 64 takes several; every
 * page read alone (IIM, AIM, error) is the whole read's rectangle, bit for bit; texels, triangles and
 * surfaces name their pages consistently. With one page, page 0 is the whole atlas and the page UVs are
 * the atlas UVs, bit for bit. Bad pages and page sides are refused, naming them. */
static void test_lightmap_pages(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *sc = lmt_paged_cornell();
    lmgi_updater *u = frameless_updater(ctx, sc);
    for (int f = 1; f <= 3; f++)
        update(u, 0.1f * (float)f, 0.0f, NULL);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    print_message("Cornell box at 6,000 texels on pages of 64: %d pages of %d x %d in a %d x %d atlas, %u texels, "
                  "%.1f%% of the pages used\n", in.pages, in.page_width, in.page_height, in.atlas_width,
                  in.atlas_height, in.texels, 100.0 * in.utilization);
    assert_true(in.pages > 1 && in.page_width <= 64 && in.page_height <= 64);
    assert_true(in.atlas_width >= in.page_width && in.atlas_height >= in.page_height);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *whole = malloc(n * sizeof *whole);
    assert_non_null(whole);
    lmgi_error e;
    const lmgi_lightmap kinds[3] = {LMGI_LIGHTMAP_IIM, LMGI_LIGHTMAP_AIM, LMGI_LIGHTMAP_ERROR};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(lmgi_get_lightmap(u, kinds[k], whole, n, &e), LMGI_OK);
        expect_pages_match(u, sc, &in, kinds[k], whole);
    }
    int one_page = check_page_layout(sc, &in);
    print_message("%d of %d surfaces on one page\n", one_page, lmgi_surface_count(sc));
    assert_int_equal(one_page, lmgi_surface_count(sc));

    float px[6];
    int r[4] = {1, 1, 1, 1};
    expect_invalid(lmgi_get_lightmap_page(u, LMGI_LIGHTMAP_IIM, -1, whole, n, &e), &e, "page -1");
    expect_invalid(lmgi_get_lightmap_page(u, LMGI_LIGHTMAP_IIM, in.pages, whole, n, &e), &e, "is not one of");
    expect_invalid(lmgi_get_lightmap_page(u, LMGI_LIGHTMAP_IIM, 0, px, 4, &e), &e, "holds 4 floats");
    expect_invalid(lmgi_get_lightmap_page(u, LMGI_LIGHTMAP_IIM, 0, NULL, n, &e), &e, "rgba is NULL");
    expect_invalid(lmgi_get_lightmap_page(u, (lmgi_lightmap)9, 0, whole, n, &e), &e, "not a lightmap kind");
    expect_invalid(lmgi_get_lightmap_page(NULL, LMGI_LIGHTMAP_IIM, 0, whole, n, &e), &e, "NULL");
    assert_int_equal(lmgi_page_rect(sc, in.pages, r), 0);
    assert_true(r[0] == 0 && r[2] == 0);
    assert_int_equal(lmgi_page_rect(NULL, 0, r), 0);
    assert_int_equal(lmgi_surface_page(sc, -1), -1);
    assert_int_equal(lmgi_surface_page(NULL, 0), -1);
    assert_int_equal(lmgi_triangle_lightmap_page(sc, UINT32_MAX, px), -1);
    free(whole);
    lmgi_updater_free(u);
    lmgi_free(sc);

    sc = lmt_load_paged(lmt_project_scene("cornell.glb"), 6000, 8192); /* one page: the atlas itself */
    lmgi_get_info(sc, &in);
    assert_int_equal(in.pages, 1);
    assert_true(in.page_width == in.atlas_width && in.page_height == in.atlas_height);
    assert_int_equal(check_page_layout(sc, &in), lmgi_surface_count(sc));
    for (uint32_t t = 0; t < in.triangles; t++) {
        float uv[6], page_uv[6];
        int has = lmgi_triangle_lightmap_uv(sc, t, uv);
        assert_int_equal(lmgi_triangle_lightmap_page(sc, t, page_uv), has ? 0 : -1);
        if (has)
            assert_memory_equal(uv, page_uv, sizeof uv);
    }
    lmgi_free(sc);
    lmgi_options o;
    lmgi_options_init(&o);
    static const int bad[] = {63, 32769, 65537};
    for (int i = 0; i < 3; i++) {
        o.max_atlas_size = bad[i];
        expect_invalid(lmgi_load(lmt_project_scene("cornell.glb"), &o, &sc, &e), &e, "max_atlas_size");
    }
    lmgi_options_init(&o);
    static const float bad_bend[] = {-2.0f, 181.0f, NAN};
    for (int i = 0; i < 3; i++) {
        o.bend_deg = bad_bend[i];
        expect_invalid(lmgi_load(lmt_project_scene("cornell.glb"), &o, &sc, &e), &e, "bend_deg");
    }
    lmgi_context_free(ctx);
}

static void test_edit_reaches_updater(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *sc = load_cornell();
    lmgi_updater *u = frameless_updater(ctx, sc);
    lmgi_update_stats st;
    for (int f = 0; f < 40; f++) /* at rest at time 0 */
        update(u, 0.0f, 0.0f, &st);
    assert_int_equal(st.surfaces_changed, 0);
    int cube = lmgi_find_node(sc, "dynamic_cube");
    float m[16];
    assert_true(lmgi_get_node_transform(sc, cube, m));
    m[12] = -0.6f, m[14] = 0.6f; /* to the floor's front left corner */
    lmgi_error e;
    assert_int_equal(lmgi_set_node_transform(sc, cube, m, &e), LMGI_OK);
    int changed = 0;
    for (int f = 1; f <= 20; f++) { /* time runs on: the cube's animation must not take it back */
        update(u, 0.05f * (float)f, 0.0f, &st);
        changed += st.surfaces_changed;
    }
    assert_true(changed > 0);
    float now[16];
    assert_true(lmgi_get_node_transform(sc, cube, now));
    assert_memory_equal(now, m, sizeof m);
    const float org[3] = {-0.6f, 1.9f, 0.6f}, down[3] = {0, -1, 0};
    lmgi_hit h;
    lmgi_intersect(sc, org, down, INFINITY, &h);
    assert_true(h.hit);
    assert_int_equal(h.node, cube);
    close_all(u, sc, ctx);
}

/* lmgi_intersect's material and barycentrics, for an editor picking what is under the cursor: rays down
 * onto the Cornell box's floor hit a material of the scene, and the lightmap UV the barycentrics give
 * (over lmgi_triangle_lightmap_uv's corners) falls in a texel of the hit triangle whose world position is
 * within two texels of the point hit; a miss gives material -1. */
static void test_intersect_material_and_uv(void **state)
{
    (void)state;
    lmgi_scene *sc = load_cornell();
    lmgi_info in;
    lmgi_get_info(sc, &in);
    int *at = lmt_texel_ids(sc);
    const float down[3] = {0.0f, -1.0f, 0.0f};
    int found = 0;
    double worst = 0.0;
    for (int k = 0; k < 16; k++) {
        float x = in.bounds_min[0] + (0.1f + 0.05f * (float)k) * (in.bounds_max[0] - in.bounds_min[0]);
        float z = in.bounds_min[2] + (0.9f - 0.05f * (float)k) * (in.bounds_max[2] - in.bounds_min[2]);
        const float org[3] = {x, in.bounds_max[1] - 1e-3f, z};
        lmgi_hit h;
        lmgi_intersect(sc, org, down, INFINITY, &h);
        assert_true(h.hit);
        assert_true(h.material >= 0 && h.material < lmgi_material_count(sc));
        float uv[6];
        if (h.surface < 0 || !lmgi_triangle_lightmap_uv(sc, h.triangle, uv))
            continue;
        float w0 = 1.0f - h.uv[0] - h.uv[1];
        assert_true(w0 >= -1e-5f && h.uv[0] >= -1e-5f && h.uv[1] >= -1e-5f);
        int tx = (int)((w0 * uv[0] + h.uv[0] * uv[2] + h.uv[1] * uv[4]) * (float)in.atlas_width);
        int ty = (int)((w0 * uv[1] + h.uv[0] * uv[3] + h.uv[1] * uv[5]) * (float)in.atlas_height);
        int i = at[(size_t)ty * (size_t)in.atlas_width + (size_t)tx];
        if (i < 0)
            continue; /* a texel of the rim whose centre lies outside every triangle */
        lmgi_texel t;
        lmgi_get_texel(sc, (uint32_t)i, &t);
        double d = 0.0;
        for (int c = 0; c < 3; c++) {
            double p = org[c] + h.t * down[c] - t.position[c];
            d += p * p;
        }
        worst = fmax(worst, sqrt(d) / in.texel_size);
        found++;
    }
    print_message("%d floor hits found their texel through the barycentrics, the farthest %.2f texels away\n", found,
                  worst);
    assert_true(found >= 8);
    assert_true(worst < 2.0);
    const float up[3] = {0.0f, 1.0f, 0.0f}, above[3] = {0.0f, in.bounds_max[1] + 1.0f, 0.0f};
    lmgi_hit miss;
    lmgi_intersect(sc, above, up, INFINITY, &miss);
    assert_false(miss.hit);
    assert_int_equal(miss.material, -1);
    free(at);
    lmgi_free(sc);
}

/* Dimming a light in room A of the two rooms with the door closed relights room A and leaves room B's
 * surfaces, IIM and AIM untouched to the bit (the paper's Fig. 5: an edit costs only what it reaches). */
static void test_light_edit_stays_in_its_room(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *sc = load_scene("two_rooms.glb", 3000);
    lmgi_error e;
    lmgi_updater_desc d;
    small_desc(&d);
    d.frame.width = d.frame.height = 0;
    d.gather.texels_per_frame = 400;
    lmgi_updater *u = make_updater(ctx, sc, &d);
    lmgi_update_stats st;
    int quiet = 0;
    for (int f = 0; f < 80 && quiet < 10; f++) { /* the door closed at time 0 */
        update(u, 0.0f, 0.0f, &st);
        quiet = st.surfaces_changed == 0 ? quiet + 1 : 0;
    }
    assert_int_equal(quiet, 10);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *iim0 = malloc(n * sizeof *iim0), *aim0 = malloc(n * sizeof *aim0);
    float *iim1 = malloc(n * sizeof *iim1), *aim1 = malloc(n * sizeof *aim1);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, iim0, n, &e), LMGI_OK);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_AIM, aim0, n, &e), LMGI_OK);
    int surfaces = lmgi_surface_count(sc);
    uint32_t *ver0 = calloc((size_t)surfaces, sizeof *ver0);
    for (int s = 0; s < surfaces; s++)
        ver0[s] = lmgi_surface_version(u, s);

    int a1 = lmt_light_on_node(sc, "light_a1");
    lmgi_light li;
    assert_int_equal(lmgi_get_light(sc, a1, &li, &e), LMGI_OK);
    assert_true(li.enabled && li.intensity > 0.0f);
    float *err0 = malloc(n * sizeof *err0), *err1 = malloc(n * sizeof *err1), *err40 = malloc(n * sizeof *err40);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_ERROR, err0, n, &e), LMGI_OK);
    li.intensity *= 0.25f;
    assert_int_equal(lmgi_set_light(sc, a1, &li, &e), LMGI_OK);
    update(u, 0.0f, 0.0f, &st);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_ERROR, err1, n, &e), LMGI_OK);
    for (int f = 1; f < 40; f++)
        update(u, 0.0f, 0.0f, &st);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_ERROR, err40, n, &e), LMGI_OK);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, iim1, n, &e), LMGI_OK);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_AIM, aim1, n, &e), LMGI_OK);
    /* surfaces wholly in room B, and those reaching into the doorway's reveal, on room A's side of the
     * door (room B's floor and walls model their half of it) */
    uint8_t *reaches_a = calloc((size_t)surfaces, 1);
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        reaches_a[t.surface] |= t.position[0] < 0.2f;
    }
    int a_changed = 0, b_texels = 0, b_untouched = 0, a_texels = 0;
    double a_before = 0.0, a_after = 0.0, b_worst = 0.0, settled = 0.0, a_err1 = 0.0, a_err40 = 0.0;
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        size_t k = 4 * ((size_t)t.y * in.atlas_width + t.x);
        settled = fmax(settled, err0[k]);
        if (t.position[0] > 0.2f && !reaches_a[t.surface]) { /* room B alone: no work, not a bit changed */
            b_untouched++;
            assert_true(err1[k] == 0.0f && err40[k] == 0.0f); /* nothing to catch up on */
            assert_memory_equal(iim0 + k, iim1 + k, 4 * sizeof *iim0);
            assert_memory_equal(aim0 + k, aim1 + k, 4 * sizeof *aim0);
            assert_int_equal(lmgi_surface_version(u, t.surface), ver0[t.surface]);
        } else if (t.position[0] > 0.2f) { /* regathered for what their reveal halves see; here the same */
            b_texels++;
            for (int c = 0; c < 3; c++)
                b_worst = fmax(b_worst, fabs((double)iim1[k + c] - iim0[k + c]) / (fabs((double)iim0[k + c]) + 1e-3));
            assert_memory_equal(aim0 + k, aim1 + k, 4 * sizeof *aim0);
        } else if (t.position[0] < -0.2f) {
            a_before += iim0[k] + iim0[k + 1] + iim0[k + 2];
            a_after += iim1[k] + iim1[k + 1] + iim1[k + 2];
            a_changed += lmgi_surface_version(u, t.surface) != ver0[t.surface];
            a_err1 += err1[k], a_err40 += err40[k], a_texels++;
        }
    }
    a_err1 /= a_texels, a_err40 /= a_texels;
    print_message("room A's indirect light changed by %.3f relative\n", fabs(a_after / a_before - 1.0));
    print_message("error atlas: settled at most %.2e; room A's mean after the edit's first update %.3f, after 40 "
                  "%.2e\n", settled, a_err1, a_err40);
    assert_true(settled < 0.02);   /* converged before the edit */
    assert_true(a_err1 > 0.05);    /* a light at a quarter: room A is far from its new light */
    assert_true(a_err40 < 0.5 * a_err1); /* and catches up */
    free(reaches_a);
    print_message("light_a1 at a quarter: room A's indirect light %.3g -> %.3g; %d texels of surfaces wholly in room "
                  "B unchanged, %d more within %.1e\n", a_before, a_after, b_untouched, b_texels, b_worst);
    assert_true(b_untouched > 100 && b_worst < 1e-3);
    assert_true(a_changed > 100);
    assert_true(a_after < 0.9 * a_before); /* one of room A's two lights at a quarter */

    li.enabled = 0; /* off, then on again: back to the quarter */
    assert_int_equal(lmgi_set_light(sc, a1, &li, &e), LMGI_OK);
    update(u, 0.0f, 0.0f, &st);
    lmgi_light back;
    assert_int_equal(lmgi_get_light(sc, a1, &back, &e), LMGI_OK);
    assert_true(!back.enabled && back.intensity == li.intensity);

    lmgi_light bad = li;
    bad.color[1] = NAN;
    expect_invalid(lmgi_set_light(sc, a1, &bad, &e), &e, "colour");
    bad = li;
    bad.intensity = -1.0f;
    expect_invalid(lmgi_set_light(sc, a1, &bad, &e), &e, "intensity");
    bad = li;
    bad.type = LMGI_LIGHT_SPOT;
    expect_invalid(lmgi_set_light(sc, a1, &bad, &e), &e, "fixed at load");
    expect_invalid(lmgi_set_light(sc, 99, &li, &e), &e, "out of range");
    expect_invalid(lmgi_get_light(sc, -1, &back, &e), &e, "out of range");
    expect_invalid(lmgi_set_light(NULL, 0, &li, &e), &e, "NULL");
    assert_int_equal(lmgi_get_light(sc, a1, &back, &e), LMGI_OK);
    assert_true(!back.enabled); /* the refused edits changed nothing */
    free(iim0), free(aim0), free(iim1), free(aim1), free(ver0), free(err0), free(err1), free(err40);
    close_all(u, sc, ctx);
}

typedef struct {
    volatile int cancel;
    float at;            /* set the flag once the gather has passed this fraction */
    double set_time;     /* when it was set */
    int calls;
} canceller;

static double seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void cancel_at(void *user, float fraction, const char *stage)
{
    canceller *c = user;
    c->calls++;
    assert_non_null(stage);
    if (!c->cancel && fraction >= c->at)
        c->cancel = 1, c->set_time = seconds();
}

/* Bakes: the updater's creation is converged, so a bake without edits does nothing; after cutting a light
 * of room A short a bake regathers room A's surfaces only, shows them at once and says so; a cancelled creation
 * or bake stops soon after the flag and leaves the lightmaps as they were. */
static void test_bake(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *sc = load_scene("two_rooms.glb", 3000);
    lmgi_error e;
    lmgi_updater_desc d;
    small_desc(&d);
    d.frame.width = d.frame.height = 0;
    canceller c = {0, 0.5f, 0.0, 0};
    d.progress = cancel_at;
    d.progress_user = &c;
    d.cancel = &c.cancel;
    lmgi_updater *u = NULL;
    assert_int_equal(lmgi_updater_create(ctx, sc, &d, &u, &e), LMGI_ERR_CANCELLED);
    double late = seconds() - c.set_time;
    print_message("creation cancelled %.0f ms after the flag (%d progress calls)\n", 1e3 * late, c.calls);
    assert_null(u);
    assert_true(late < 0.5);
    d.progress = NULL;
    d.cancel = NULL;
    u = make_updater(ctx, sc, &d); /* the scene is free for another updater after the cancel */

    lmgi_bake_report r;
    assert_int_equal(lmgi_bake(u, NULL, &r, &e), LMGI_OK);
    assert_true(r.photons_traced > 0);
    assert_int_equal(r.photons_changed, 0);
    assert_int_equal(r.texels_gathered, 0);
    assert_int_equal(r.surfaces_changed, 0);

    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *before = malloc(n * sizeof *before), *after = malloc(n * sizeof *after);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, before, n, &e), LMGI_OK);
    int a1 = lmgi_find_node(sc, "light_a1"), light = -1;
    lmgi_light li;
    for (int l = 0; l < lmgi_light_count(sc); l++)
        if (lmgi_get_light(sc, l, &li, &e) == LMGI_OK && li.node == a1)
            light = l;
    assert_int_equal(lmgi_get_light(sc, light, &li, &e), LMGI_OK);
    li.range = 1.5f; /* its reach cut short: its photons' paths change (a light dimmed alone would keep them
                      * and show its new light at once, test_light_edits) */
    assert_int_equal(lmgi_set_light(sc, light, &li, &e), LMGI_OK);

    canceller early = {1, 0.0f, 0.0, 0}; /* already set: the bake stops after its photons */
    lmgi_bake_desc bd = {.cancel = &early.cancel};
    assert_int_equal(lmgi_bake(u, &bd, &r, &e), LMGI_ERR_CANCELLED);
    print_message("bake cancelled after its photons: %u of %u photon paths changed (light_a1's), %d AIM surfaces\n",
                  r.photons_changed, r.photons_traced, r.aim_surfaces_refreshed);
    assert_true(r.photons_changed > 0 && r.photons_changed < r.photons_traced / 2); /* one light of four */
    assert_true(r.aim_surfaces_refreshed > 0);
    assert_int_equal(r.texels_gathered, 0);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, after, n, &e), LMGI_OK);
    assert_memory_equal(before, after, n * sizeof *before); /* nothing half done shown */

    canceller watch = {0, 2.0f, 0.0, 0}; /* never cancels; counts the progress calls */
    bd = (lmgi_bake_desc){.progress = cancel_at, .progress_user = &watch};
    assert_int_equal(lmgi_bake(u, &bd, &r, &e), LMGI_OK);
    print_message("the bake after it: %u of %u texels regathered, %d surfaces changed, %.0f ms\n",
                  r.texels_gathered, in.texels, r.surfaces_changed, r.ms_total);
    assert_true(watch.calls >= 3);
    assert_true(r.texels_gathered > 0 && r.texels_gathered < in.texels * 3 / 4);
    assert_true(r.surfaces_changed > 0);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, after, n, &e), LMGI_OK);
    /* Room B's floor and walls include their halves of the doorway's reveal, which lie on room A's side of
     * the door: were they regathered for what those see, their texels deep in room B could still move by
     * the gather's rounding (a texel drawn in another tile of a pass); they must not move by more. */
    int a_darker = 0;
    double b_worst = 0.0;
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        size_t k = 4 * ((size_t)t.y * in.atlas_width + t.x);
        if (t.position[0] > 0.2f)
            for (int c = 0; c < 3; c++)
                b_worst = fmax(b_worst, fabs((double)after[k + c] - before[k + c]) / (fabs((double)before[k + c]) + 1e-3));
        else if (t.position[0] < -0.2f)
            a_darker += after[k + 1] < before[k + 1];
    }
    print_message("room B (x > 0.2): largest relative change %.1e\n", b_worst);
    assert_true(b_worst < 1e-3);
    assert_true(a_darker > 100);
    assert_int_equal(lmgi_bake(u, NULL, &r, &e), LMGI_OK); /* done: nothing left */
    assert_int_equal(r.texels_gathered, 0);
    lmgi_bake_desc nan_time = {.time = NAN};
    expect_invalid(lmgi_bake(u, &nan_time, &r, &e), &e, "time");
    expect_invalid(lmgi_bake(NULL, NULL, &r, &e), &e, "NULL");
    free(before);
    free(after);
    close_all(u, sc, ctx);
}

/* Recolouring the red wall blue, then a bake, gives the lightmap of a scene whose wall was blue from the
 * start (the same photons, the same gather): the edit reaches every photon and AIM it should. Bad
 * material edits are refused. */
static void test_recolour_material(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *edited = load_cornell(), *blue = load_cornell();
    int red = -1;
    for (int m = 0; m < lmgi_material_count(edited); m++)
        if (!strcmp(lmgi_material_name(edited, m), "red"))
            red = m;
    assert_true(red >= 0);
    lmgi_material mat;
    lmgi_error e;
    assert_int_equal(lmgi_get_material(edited, red, &mat, &e), LMGI_OK);
    assert_int_equal(mat.cls, LMGI_MATERIAL_DIFFUSE);
    lmgi_material recoloured = mat;
    recoloured.base_color[0] = 0.05f, recoloured.base_color[1] = 0.06f, recoloured.base_color[2] = 0.63f;
    assert_int_equal(lmgi_set_material(blue, red, &recoloured, &e), LMGI_OK); /* blue from the start */

    lmgi_updater_desc d;
    small_desc(&d);
    d.frame.width = d.frame.height = 0;
    lmgi_updater *u = make_updater(ctx, edited, &d), *truth = make_updater(ctx, blue, &d);
    assert_int_equal(lmgi_set_material(edited, red, &recoloured, &e), LMGI_OK);
    lmgi_bake_report r;
    lmgi_bake_report rt;
    assert_int_equal(lmgi_bake(truth, NULL, &rt, &e), LMGI_OK); /* both at the animations' time 0 (the file's */
    assert_int_equal(lmgi_bake(u, NULL, &r, &e), LMGI_OK);      /* rest pose differs) */
    print_message("red wall recoloured blue: %u of %u photon paths changed, %d AIM surfaces, %u texels regathered "
                  "(%d surfaces for what they see)\n", r.photons_changed, r.photons_traced, r.aim_surfaces_refreshed,
                  r.texels_gathered, r.surfaces_seeing);
    /* The recolour kept the wall's largest channel, so every photon keeps its path: the edit's update
     * reweighted the photons that bounced off the wall and refreshed the AIMs they reach, and the bake
     * finds no path to change; the texels that see the changed AIMs (the cube's faces too, which no changed
     * photon reached) are what it regathers. */
    assert_int_equal(r.photons_changed, 0);
    assert_true(r.texels_gathered > 0);

    lmgi_info in;
    lmgi_get_info(edited, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    for (int k = 0; k < 2; k++) {
        lmgi_lightmap kind = k ? LMGI_LIGHTMAP_AIM : LMGI_LIGHTMAP_IIM;
        assert_int_equal(lmgi_get_lightmap(u, kind, a, n, &e), LMGI_OK);
        assert_int_equal(lmgi_get_lightmap(truth, kind, b, n, &e), LMGI_OK);
        double diff = 0.0, sum = 0.0;
        for (size_t i = 0; i < n; i++)
            if (i % 4 != 3)
                diff += fabs((double)a[i] - b[i]), sum += fabs((double)b[i]);
        print_message("%s after the edit and a bake against blue from the start: mean relative difference %.2e\n",
                      k ? "AIM" : "IIM", diff / sum);
        assert_true(diff / sum < 1e-4);
    }
    /* the frame shows it: the left wall (red in the file) is blue now */
    lmgi_camera cam;
    float *px = malloc(3 * SIDE * SIDE * sizeof *px);
    assert_int_equal(lmgi_scene_camera(edited, -1, SIDE, SIDE, &cam, &e), LMGI_OK);
    assert_int_equal(lmgi_render(u, &cam, SIDE, SIDE, px, &e), LMGI_OK);
    double wall[3] = {0, 0, 0};
    for (int y = SIDE / 3; y < 2 * SIDE / 3; y++)
        for (int x = 1; x < SIDE / 10; x++)
            for (int c = 0; c < 3; c++)
                wall[c] += px[3 * (y * SIDE + x) + c];
    print_message("left wall in the frame: %.3g %.3g %.3g\n", wall[0], wall[1], wall[2]);
    assert_true(wall[2] > 3.0 * wall[0]);
    free(px);
    lmgi_material bad = recoloured;
    bad.base_color[2] = 1.5f;
    expect_invalid(lmgi_set_material(edited, red, &bad, &e), &e, "base colour");
    bad = recoloured;
    bad.emissive[0] = 1.0f;
    expect_invalid(lmgi_set_material(edited, red, &bad, &e), &e, "not emissive at load");
    bad = recoloured;
    bad.cls = LMGI_MATERIAL_MIRROR;
    expect_invalid(lmgi_set_material(edited, red, &bad, &e), &e, "class");
    bad = recoloured;
    bad.base_color[0] = NAN;
    expect_invalid(lmgi_set_material(edited, red, &bad, &e), &e, "base colour");
    expect_invalid(lmgi_set_material(edited, 99, &recoloured, &e), &e, "out of range");
    assert_null(lmgi_material_name(edited, 99));
    assert_int_equal(lmgi_get_material(edited, red, &mat, &e), LMGI_OK);
    assert_memory_equal(mat.base_color, recoloured.base_color, sizeof mat.base_color); /* refusals changed nothing */
    free(a);
    free(b);
    lmgi_updater_free(u);
    lmgi_updater_free(truth);
    lmgi_free(edited);
    lmgi_free(blue);
    lmgi_context_free(ctx);
}

/* A time budget turns into texels from the measured cost: a generous one allows many, a tiny one one. */
static void test_budget_sets_texels(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *sc = load_cornell();
    lmgi_updater_desc d;
    small_desc(&d);
    lmgi_updater *u = make_updater(ctx, sc, &d);
    lmgi_update_stats st;
    update(u, 0.0f, 0.0f, &st);
    assert_int_equal(st.texels_budget, 20); /* texels_per_frame's default */
    update(u, 0.1f, 0.001f, &st);
    assert_int_equal(st.texels_budget, 1);
    update(u, 0.2f, 5000.0f, &st);
    assert_true(st.texels_budget > 200);
    close_all(u, sc, ctx);
}


/* Every bad argument: LMGI_ERR_INVALID with a message, and nothing changed. */
static void test_bad_arguments(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *sc = load_cornell();
    lmgi_updater *u = (lmgi_updater *)sc;
    lmgi_error e;
    lmgi_updater_desc d;
    static const char *const named[] = {"gather.samples 3", "frame 10 x 0", "camera 7", "gather.blend_frames -5",
                                        "gather.enlargement", "photons.groups", "frame.shadow_maps_per_update -5",
                                        "photons.find_portals 2"};
    for (int k = 0; k < 8; k++) {
        small_desc(&d);
        if (k == 0)
            d.gather.samples = 3;
        if (k == 1)
            d.frame.width = 10, d.frame.height = 0;
        if (k == 2)
            d.frame.camera = 7;
        if (k == 3)
            d.gather.blend_frames = -5;
        if (k == 4)
            d.gather.enlargement = NAN;
        if (k == 5)
            d.photons.groups = 5; /* not 2^a 3^b */
        if (k == 6)
            d.frame.shadow_maps_per_update = -5; /* LMGI_OFF is "all", other negatives nothing */
        if (k == 7)
            d.photons.find_portals = 2; /* 0 (on), LMGI_ON or LMGI_OFF */
        u = (lmgi_updater *)sc;
        expect_invalid(lmgi_updater_create(ctx, sc, &d, &u, &e), &e, named[k]);
        assert_null(u);
    }
    expect_invalid(lmgi_updater_create(NULL, sc, NULL, &u, &e), &e, "context is NULL");
    expect_invalid(lmgi_updater_create(ctx, NULL, NULL, &u, &e), &e, "scene is NULL");
    expect_invalid(lmgi_updater_create(ctx, sc, NULL, NULL, &e), &e, "out is NULL");

    small_desc(&d);
    u = make_updater(ctx, sc, &d);
    lmgi_updater *second = NULL;
    expect_invalid(lmgi_updater_create(ctx, sc, &d, &second, &e), &e, "already has an updater");
    lmgi_update_stats st, untouched;
    update(u, 0.0f, 0.0f, &st);
    memset(&untouched, 0x5a, sizeof untouched);
    st = untouched;
    expect_invalid(lmgi_update(u, NAN, 0.0f, &st, &e), &e, "time");
    expect_invalid(lmgi_update(u, INFINITY, 0.0f, &st, &e), &e, "time");
    expect_invalid(lmgi_update(u, 0.1f, -1.0f, &st, &e), &e, "budget");
    expect_invalid(lmgi_update(u, 0.1f, NAN, &st, &e), &e, "budget");
    expect_invalid(lmgi_update(NULL, 0.1f, 0.0f, &st, &e), &e, "updater is NULL");
    assert_memory_equal(&st, &untouched, sizeof st);
    update(u, 0.1f, 0.0f, &st);
    assert_int_equal(st.frame, 1); /* the refused calls did no update */

    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *buf = malloc(n * sizeof *buf);
    expect_invalid(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, buf, n - 1, &e), &e, "needs");
    expect_invalid(lmgi_get_lightmap(u, (lmgi_lightmap)7, buf, n, &e), &e, "not a lightmap kind");
    expect_invalid(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, NULL, n, &e), &e, "rgba is NULL");
    expect_invalid(lmgi_get_lightmap(NULL, LMGI_LIGHTMAP_IIM, buf, n, &e), &e, "updater is NULL");

    lmgi_camera cam;
    expect_invalid(lmgi_scene_camera(sc, 5, 8, 8, &cam, &e), &e, "camera 5");
    expect_invalid(lmgi_scene_camera(sc, -1, 0, 8, &cam, &e), &e, "0 x 8");
    assert_int_equal(lmgi_scene_camera(sc, -1, 8, 8, &cam, &e), LMGI_OK);
    expect_invalid(lmgi_render(u, &cam, 8, 99999, buf, &e), &e, "8 x 99999");
    expect_invalid(lmgi_render(u, NULL, 8, 8, buf, &e), &e, "cam is NULL");
    lmgi_camera flat = cam;
    memset(flat.view, 0, sizeof flat.view);
    expect_invalid(lmgi_render(u, &flat, 8, 8, buf, &e), &e, "not invertible");
    flat = cam;
    flat.proj[5] = NAN;
    expect_invalid(lmgi_render(u, &flat, 8, 8, buf, &e), &e, "not a finite number");

    int r[4] = {1, 2, 3, 4};
    assert_int_equal(lmgi_surface_rect(sc, in.surfaces, r), 0);
    assert_int_equal(r[0] | r[1] | r[2] | r[3], 0);
    assert_int_equal(lmgi_surface_version(u, -1), 0);
    assert_int_equal(lmgi_surface_version(NULL, 0), 0);
    assert_int_equal(lmgi_surface_count(NULL), 0);

    lmgi_free(sc); /* refused while the updater works on it: the scene stays usable */
    update(u, 0.2f, 0.0f, &st);
    assert_int_equal(st.frame, 2);
    lmgi_context_free(ctx); /* refused too while an updater is alive */
    update(u, 0.3f, 0.0f, &st);
    free(buf);
    close_all(u, sc, ctx);
}

/* lmgi_write_image: EXR and PNG written whole, every bad argument named. */
static void test_write_image(void **state)
{
    (void)state;
    float px[4 * 6 * 4];
    for (int i = 0; i < 4 * 6 * 4; i++)
        px[i] = 0.1f * (float)(i % 7);
    char path[1024];
    lmgi_error e;
    const char *names[2] = {"picture.exr", "picture.png"};
    for (int k = 0; k < 2; k++) {
        snprintf(path, sizeof path, "%s/%s", lmt_tmpdir(), names[k]);
        assert_int_equal(lmgi_write_image(path, 6, 4, 4, px, NULL, &e), LMGI_OK);
        size_t size = 0;
        unsigned char *data = lmt_read_file(path, &size, 0);
        assert_true(size > 40);
        assert_memory_equal(data + (k ? 1 : 0), k ? "PNG" : "\x76\x2f\x31\x01", k ? 3 : 4); /* the formats' magic */
        free(data);
    }
    expect_invalid(lmgi_write_image(path, 6, 4, 2, px, NULL, &e), &e, "2 channels");
    expect_invalid(lmgi_write_image(path, 0, 4, 3, px, NULL, &e), &e, "0 x 4");
    expect_invalid(lmgi_write_image(path, 6, 4, 3, px, &(lmgi_image_desc){.tonemap = (lmgi_tonemap)5}, &e), &e, "not a tone map");
    expect_invalid(lmgi_write_image(path, 6, 4, 3, px, &(lmgi_image_desc){.exposure = NAN}, &e), &e, "exposure");
    expect_invalid(lmgi_write_image(path, 6, 4, 3, NULL, NULL, &e), &e, "pixels is NULL");
    snprintf(path, sizeof path, "%s/picture.jpg", lmt_tmpdir());
    expect_invalid(lmgi_write_image(path, 6, 4, 3, px, NULL, &e), &e, ".exr or .png");
    assert_int_equal(lmgi_write_image("/proc/lmgi-nowhere/a.png", 6, 4, 3, px, &(lmgi_image_desc){LMGI_TONEMAP_CLAMP, 1.0f, 0}, &e),
                     LMGI_ERR_IO);
    assert_non_null(strstr(e.message, "/proc/lmgi-nowhere/a.png"));
    assert_float_equal(lmgi_auto_exposure(LMGI_TONEMAP_NEUTRAL, NULL, 3), 1.0f, 0.0);
}

/* lmgi_geometry_hash: the same for two loads, after a node moves or a material changes, and with a lamp
 * more (a node without triangles); another for a vertex moved or a node with triangles renamed (lmgi view
 * --watch tells edits from a new scene by it). */
static void test_geometry_hash(void **state)
{
    (void)state;
    static const float quad[12] = {-1, 0, 1, 1, 0, 1, 1, 0, -1, -1, 0, -1};
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    float moved[12];
    memcpy(moved, quad, sizeof moved);
    moved[4] = 0.001f;
    uint64_t h[5];
    int nodes[5];
    for (int k = 0; k < 5; k++) {
        lmgi_mesh_desc m = {.name = k == 3 ? "plate2" : "plate", .positions = k == 2 ? moved : quad, .vertex_count = 4,
                            .indices = idx, .triangle_count = 2, .dynamic = 1};
        lmgi_light_desc l[2] = {{.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 10.0f, .position = {0, 2, 0}},
                                {.name = "lamp2", .type = LMGI_LIGHT_POINT, .intensity = 5.0f, .position = {1, 2, 0}}};
        lmgi_material_desc mat_d = {.name = "white", .base_color = {0.8f, 0.8f, 0.8f, 1.0f}};
        lmgi_scene_desc d = {.name = "plate", .meshes = &m, .mesh_count = 1, .materials = &mat_d, .material_count = 1,
                             .lights = l, .light_count = k == 4 ? 2 : 1}; /* 4: a lamp more, no triangle more */
        lmgi_options o;
        lmgi_options_init(&o);
        lmgi_scene *sc = NULL;
        lmgi_error e;
        if (lmgi_load_desc(&d, &o, &sc, &e) != LMGI_OK)
            fail_msg("%s", e.message);
        h[k] = lmgi_geometry_hash(sc);
        nodes[k] = lmgi_node_count(sc);
        if (k == 1) { /* moved and recoloured: still the same geometry */
            float w[16];
            assert_true(lmgi_get_node_transform(sc, 0, w));
            w[13] += 0.5f;
            assert_int_equal(lmgi_set_node_transform(sc, 0, w, &e), LMGI_OK);
            lmgi_material mat;
            assert_int_equal(lmgi_get_material(sc, 0, &mat, &e), LMGI_OK);
            mat.base_color[0] = 0.1f;
            assert_int_equal(lmgi_set_material(sc, 0, &mat, &e), LMGI_OK);
            assert_true(lmgi_geometry_hash(sc) == h[k]);
        }
        lmgi_free(sc);
    }
    assert_true(h[0] != 0 && h[0] == h[1]);
    assert_true(h[2] != h[0] && h[3] != h[0]);
    print_message("a lamp more: %d nodes for %d, the same hash: %d\n", nodes[4], nodes[0], h[4] == h[0]);
    assert_true(h[4] == h[0]);
    assert_true(lmgi_geometry_hash(NULL) == 0);
}

/* lmgi_tonemap_rgba8 (a window's pixels, lmgi view) gives the bytes lmgi_write_image's PNG holds, for both
 * tone maps, automatic exposure and a given one. */
static void test_tonemap_rgba8(void **state)
{
    (void)state;
    float px[3 * 6 * 4];
    for (int i = 0; i < 3 * 6 * 4; i++)
        px[i] = 0.37f * (float)(i % 11);
    const lmgi_image_desc descs[3] = {{LMGI_TONEMAP_NEUTRAL, 0.0f, 0}, {LMGI_TONEMAP_CLAMP, 0.0f, 0},
                                      {LMGI_TONEMAP_NEUTRAL, 2.5f, 0}};
    for (int k = 0; k < 3; k++) {
        char path[1024];
        lmgi_error e;
        snprintf(path, sizeof path, "%s/tone.png", lmt_tmpdir());
        assert_int_equal(lmgi_write_image(path, 6, 4, 3, px, &descs[k], &e), LMGI_OK);
        size_t size = 0;
        unsigned char *data = lmt_read_file(path, &size, 0), rgba[4 * 24];
        int w, h, n;
        unsigned char *png = stbi_load_from_memory(data, (int)size, &w, &h, &n, 3);
        assert_non_null(png);
        float k_used = lmgi_tonemap_rgba8(descs[k].tonemap, descs[k].exposure, px, 24, rgba);
        if (descs[k].exposure > 0.0f)
            assert_true(k_used == descs[k].exposure);
        else
            assert_true(k_used == lmgi_auto_exposure(descs[k].tonemap, px, 24));
        for (int i = 0; i < 24; i++) {
            assert_memory_equal(rgba + 4 * i, png + 3 * i, 3);
            assert_int_equal(rgba[4 * i + 3], 255);
        }
        stbi_image_free(png);
        free(data);
    }
    unsigned char out[4];
    assert_true(lmgi_tonemap_rgba8(LMGI_TONEMAP_NEUTRAL, 1.0f, NULL, 1, out) == 0.0f);
    assert_true(lmgi_tonemap_rgba8((lmgi_tonemap)7, 1.0f, px, 1, out) == 0.0f);
}

/* A level from arrays (lmgi_load_desc): a floor, a dynamic box on it and a point light above, loaded,
 * hit where the arrays put them, lit by an updater, and every bad desc refused naming the mesh. */
static void test_scene_from_arrays(void **state)
{
    (void)state;
    static const float floor_pos[12] = {-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2};
    static const uint32_t floor_idx[6] = {0, 1, 2, 0, 2, 3};
    float box_pos[24];
    for (int v = 0; v < 8; v++) /* corners of [-0.25, 0.25] x [0, 0.5] x [-0.25, 0.25] */
        box_pos[3 * v] = v & 1 ? 0.25f : -0.25f, box_pos[3 * v + 1] = v & 2 ? 0.5f : 0.0f,
        box_pos[3 * v + 2] = v & 4 ? 0.25f : -0.25f;
    static const uint32_t box_idx[36] = {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1,
                                         2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3};
    lmgi_mesh_desc meshes[2];
    memset(meshes, 0, sizeof meshes);
    meshes[0] = (lmgi_mesh_desc){.name = "floor", .positions = floor_pos, .vertex_count = 4, .indices = floor_idx,
                                 .triangle_count = 2, .material = 0};
    meshes[1] = (lmgi_mesh_desc){.name = "box", .positions = box_pos, .vertex_count = 8, .indices = box_idx,
                                 .triangle_count = 12, .material = 1, .dynamic = 1};
    meshes[1].transform[0] = meshes[1].transform[5] = meshes[1].transform[10] = meshes[1].transform[15] = 1.0f;
    meshes[1].transform[12] = 0.5f; /* moved along x */
    lmgi_material_desc mats[2] = {{.name = "grey", .base_color = {0.7f, 0.7f, 0.7f, 1.0f}},
                                  {.name = "orange", .base_color = {0.8f, 0.4f, 0.1f, 1.0f}}};
    lmgi_light_desc light = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 10.0f, .position = {0, 2, 0}};
    lmgi_scene_desc d = {.name = "arrays", .meshes = meshes, .mesh_count = 2, .materials = mats, .material_count = 2,
                         .lights = &light, .light_count = 1};
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 1000;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load_desc(&d, &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    assert_int_equal(in.triangles, 14);
    assert_int_equal(in.lights, 1);
    assert_int_equal(in.materials, 2);
    assert_int_equal(in.dynamic_nodes, 1);
    int box = lmgi_find_node(sc, "box");
    assert_true(box >= 0 && lmgi_node_is_dynamic(sc, box));
    const float org[3] = {0.6f, 5.0f, 0.1f}, down[3] = {0, -1, 0};
    lmgi_hit h;
    lmgi_intersect(sc, org, down, INFINITY, &h);
    assert_true(h.hit && h.node == box);
    assert_float_equal(h.t, 4.5f, 1e-5); /* the box's top at y = 0.5 */
    const float beside[3] = {-1.0f, 5.0f, 1.0f};
    lmgi_intersect(sc, beside, down, INFINITY, &h);
    assert_true(h.hit && h.node == lmgi_find_node(sc, "floor"));
    assert_float_equal(h.t, 5.0f, 1e-5);

    lmgi_context *ctx = new_context();
    lmgi_updater_desc ud;
    small_desc(&ud);
    ud.frame.width = ud.frame.height = 0;
    lmgi_updater *u = make_updater(ctx, sc, &ud);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *iim = malloc(n * sizeof *iim);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, iim, n, &e), LMGI_OK);
    double lit = 0.0;
    for (size_t i = 0; i < n; i += 4)
        lit += iim[i + 3] > 0.5f ? iim[i] + iim[i + 1] + iim[i + 2] : 0.0;
    assert_true(lit > 0.0); /* the box's light bounced onto the floor and the floor's onto the box */
    free(iim);
    close_all(u, sc, ctx);

    uint32_t bad_idx[6] = {0, 1, 2, 0, 2, 9};
    meshes[0].indices = bad_idx;
    expect_invalid(lmgi_load_desc(&d, &o, &sc, &e), &e, "mesh 0: index 5 is 9");
    assert_null(sc);
    meshes[0].indices = floor_idx;
    meshes[1].material = 5;
    expect_invalid(lmgi_load_desc(&d, &o, &sc, &e), &e, "mesh 1: material 5");
    meshes[1].material = 1;
    meshes[1].transform[13] = NAN;
    expect_invalid(lmgi_load_desc(&d, &o, &sc, &e), &e, "mesh 1: its transform");
    meshes[1].transform[13] = 0.0f;
    float nan_floor[12];
    memcpy(nan_floor, floor_pos, sizeof nan_floor);
    nan_floor[4] = NAN;
    meshes[0].positions = nan_floor;
    assert_int_not_equal(lmgi_load_desc(&d, &o, &sc, &e), LMGI_OK); /* the loader's own check */
    print_message("a NaN vertex in a desc: %s\n", e.message);
    meshes[0].positions = floor_pos;
    d.mesh_count = 0;
    expect_invalid(lmgi_load_desc(&d, &o, &sc, &e), &e, "no meshes");
    expect_invalid(lmgi_load_desc(NULL, &o, &sc, &e), &e, "NULL");
    expect_invalid(lmgi_load_memory(NULL, 10, "x", &o, &sc, &e), &e, "data is NULL");

    /* a .glb from memory is the file's scene; one naming an external file is refused, saying why */
    size_t size = 0;
    unsigned char *bytes = lmt_read_file(lmt_project_scene("two_rooms.glb"), &size, 0);
    lmgi_scene *from_file = NULL;
    assert_int_equal(lmgi_load_memory(bytes, size, "two rooms in memory", &o, &sc, &e), LMGI_OK);
    assert_int_equal(lmgi_load(lmt_project_scene("two_rooms.glb"), &o, &from_file, &e), LMGI_OK);
    lmgi_info a, b;
    lmgi_get_info(sc, &a);
    lmgi_get_info(from_file, &b);
    assert_true(a.triangles == b.triangles && a.texels == b.texels && a.lights == b.lights);
    lmgi_free(sc);
    lmgi_free(from_file);
    free(bytes);
    const char *external = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"geometry.bin\",\"byteLength\":36}]}";
    assert_int_not_equal(lmgi_load_memory(external, strlen(external), "external", &o, &sc, &e), LMGI_OK);
    print_message("a scene in memory naming geometry.bin: %s\n", e.message);
    assert_non_null(strstr(e.message, "geometry.bin: a scene from memory cannot name external files"));
}

/* liblmgi.so exports exactly the functions lmgi.h and lmgi_tools.h mark LMGI_API: nothing internal, nothing missing. */
/* One context, two threads: while thread A is inside a call on the context (an updater's creation, held
 * in its progress callback), thread B's calls on the context, its other updater and that updater's scene
 * are refused with a message, not raced into a crash; afterwards B's calls go through. */
typedef struct {
    lmgi_context *ctx;
    lmgi_scene *scene;
    lmgi_updater *made;
    atomic_int inside, done;
    lmgi_status status;
} held_call;

static void hold(void *user, float fraction, const char *stage)
{
    (void)fraction, (void)stage;
    held_call *h = user;
    atomic_store(&h->inside, 1);
    while (!atomic_load(&h->done))
        nanosleep(&(struct timespec){0, 1000000}, NULL);
}

static void *create_held(void *user)
{
    held_call *h = user;
    lmgi_updater_desc d;
    small_desc(&d);
    d.progress = hold;
    d.progress_user = h;
    lmgi_error e;
    h->status = lmgi_updater_create(h->ctx, h->scene, &d, &h->made, &e);
    return NULL;
}

static void test_second_thread_refused(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *first = load_cornell(), *second = load_cornell();
    lmgi_updater_desc d;
    small_desc(&d);
    lmgi_updater *u = make_updater(ctx, first, &d);
    held_call h = {.ctx = ctx, .scene = second};
    pthread_t a;
    assert_int_equal(pthread_create(&a, NULL, create_held, &h), 0);
    while (!atomic_load(&h.inside))
        nanosleep(&(struct timespec){0, 1000000}, NULL);
    lmgi_error e;
    lmgi_update_stats st;
    expect_invalid(lmgi_update(u, 0.1f, 0.0f, &st, &e), &e, "lmgi_update: the context is in use by another thread");
    float rgb[3 * 8 * 8];
    lmgi_camera cam;
    assert_int_equal(lmgi_scene_camera(first, -1, 8, 8, &cam, &e), LMGI_OK);
    expect_invalid(lmgi_render(u, &cam, 8, 8, rgb, &e), &e, "in use by another thread");
    expect_invalid(lmgi_set_time(first, 0.5f, &e), &e, "lmgi_set_time: the context is in use by another thread");
    lmgi_scene *third = load_cornell();
    lmgi_updater *v = NULL;
    expect_invalid(lmgi_updater_create(ctx, third, &d, &v, &e), &e, "in use by another thread");
    assert_null(v);
    lmgi_updater_free(u); /* refused: logged, kept */
    atomic_store(&h.done, 1);
    pthread_join(a, NULL);
    assert_int_equal(h.status, LMGI_OK);
    update(u, 0.1f, 0.0f, &st); /* the same calls, now the context is free */
    assert_int_equal(lmgi_set_time(first, 0.5f, &e), LMGI_OK);
    lmgi_updater_free(h.made);
    lmgi_free(second);
    lmgi_free(third);
    close_all(u, first, ctx);
}

/* The gather's first progress report cancels it (a shard with two passes or more stops after one). */
static void cancel_in_gather(void *user, float fraction, const char *stage)
{
    if (!strcmp(stage, "gather") && fraction > 0.0f && fraction < 1.0f)
        *(volatile int *)user = 1;
}

/* A shard's bake is a bake like any other: cancelled, its checkpoint keeps what it finished and a resume
 * of the same shard ends with the same part, byte for byte, as a shard that never stopped; a resume as
 * another shard is refused, naming both; the desc's shard fields are checked. */
static void test_shard_cancelled_and_resumed(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *sc = load_scene("cornell.glb", 8000);
    lmgi_error e;
    char straight[512], stopped[512];
    const char *dir = lmt_tmpdir();
    snprintf(straight, sizeof straight, "%s/straight.part", dir);
    snprintf(stopped, sizeof stopped, "%s/stopped.part", dir);
    lmgi_updater_desc d = {.photons.count = 6000, .shard = 0, .shards = 2, .checkpoint = straight};
    lmgi_updater *u = make_updater(ctx, sc, &d);
    lmgi_updater_free(u);

    volatile int cancel = 0;
    d.checkpoint = stopped;
    d.cancel = &cancel;
    d.progress = cancel_in_gather;
    d.progress_user = (void *)&cancel;
    u = NULL;
    assert_int_equal(lmgi_updater_create(ctx, sc, &d, &u, &e), LMGI_ERR_CANCELLED);
    assert_null(u);
    assert_int_equal(access(stopped, R_OK), 0);
    cancel = 0;
    d.progress = NULL;
    d.resume = 1;
    d.shard = 1;
    assert_int_equal(lmgi_updater_create(ctx, sc, &d, &u, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "a checkpoint of shard 1 of 2, not of this bake's shard 2 of 2"));
    d.shard = 0;
    u = make_updater(ctx, sc, &d);
    lmgi_updater_free(u);
    size_t na, nb;
    unsigned char *a = lmt_read_file(straight, &na, 0), *b = lmt_read_file(stopped, &nb, 0);
    assert_true(na == nb && memcmp(a, b, na) == 0);
    free(a);
    free(b);

    lmgi_updater_desc bad = {.shard = 2, .shards = 2, .checkpoint = straight};
    expect_invalid(lmgi_updater_create(ctx, sc, &bad, &u, &e), &e, "shard 2 of 2");
    bad = (lmgi_updater_desc){.shard = 0, .shards = 2};
    expect_invalid(lmgi_updater_create(ctx, sc, &bad, &u, &e), &e, "needs a checkpoint file");
    const char *const parts[1] = {straight};
    bad = (lmgi_updater_desc){.parts = parts, .part_count = 1, .shards = 2, .checkpoint = straight};
    expect_invalid(lmgi_updater_create(ctx, sc, &bad, &u, &e), &e, "not with a shard");
    bad = (lmgi_updater_desc){.parts = parts, .part_count = 0};
    expect_invalid(lmgi_updater_create(ctx, sc, &bad, &u, &e), &e, "parts given with part_count 0");
    bad = (lmgi_updater_desc){.shard = 0, .shards = 2, .checkpoint = straight, .gather.bounce_passes = 2};
    expect_invalid(lmgi_updater_create(ctx, sc, &bad, &u, &e), &e, "bounce_passes 2 in a shard");
    bad = (lmgi_updater_desc){.photons.count = 6000, .parts = parts, .part_count = 1};
    expect_invalid(lmgi_updater_create(ctx, sc, &bad, &u, &e), &e, "shard 2 of 2 is missing");
    close_all(NULL, sc, ctx);
}

/* ---- a bake shared by processes that work together (the desc's photon_exchange and claim_pass),
 * the processes played by threads, each with its own context ---- */

typedef struct {
    lmt_hub hub;
    atomic_int next;     /* the next pass to hand out */
} share_hub;

typedef struct {
    share_hub *h;
    int id, taken;
    char part[512];
    lmgi_status status;
    char message[1024];
} share_process;

static int share_exchange(void *user, const void *mine, size_t size, size_t *sizes, void *all)
{
    share_process *p = user;
    return lmt_hub_exchange(&p->h->hub, p->id, mine, size, sizes, all);
}

static int share_claim(void *user, int passes)
{
    share_process *p = user;
    int pass = atomic_fetch_add(&p->h->next, 1);
    if (pass >= passes)
        return -1;
    p->taken++;
    return pass;
}

static int claim_beyond(void *user, int passes)
{
    (void)user;
    return passes;
}

static void *share_bake(void *arg)
{
    share_process *p = arg;
    lmgi_context *ctx = NULL;
    lmgi_error e;
    p->status = lmgi_context_create(NULL, &ctx, &e);
    lmgi_scene *sc = p->status == LMGI_OK ? load_scene("cornell.glb", 8000) : NULL;
    lmgi_updater_desc d = {.photons.count = 6000, .shard = p->id, .shards = 2, .checkpoint = p->part,
                           .photon_exchange = share_exchange, .claim_pass = share_claim, .share_user = p};
    lmgi_updater *u = NULL;
    if (p->status == LMGI_OK)
        p->status = lmgi_updater_create(ctx, sc, &d, &u, &e);
    if (p->status != LMGI_OK)
        snprintf(p->message, sizeof p->message, "%s", e.message);
    close_all(u, sc, ctx);
    return NULL;
}

/* Two processes share a bake: the photons traced half each and exchanged, the gather's passes handed out
 * as each finishes one; their two parts put together are one process's bake, bit for bit (IIM and AIM).
 * A part missing, a part resumed and the desc's rules are refused, naming them. */
static void test_shared_bake_is_one_process_bake(void **state)
{
    (void)state;
    share_hub h;
    lmt_hub_init(&h.hub, 2);
    atomic_init(&h.next, 0);
    share_process p[2];
    pthread_t t[2];
    for (int i = 0; i < 2; i++) {
        p[i] = (share_process){.h = &h, .id = i};
        snprintf(p[i].part, sizeof p[i].part, "%s/shared%d.part", lmt_tmpdir(), i);
        assert_int_equal(pthread_create(&t[i], NULL, share_bake, &p[i]), 0);
    }
    for (int i = 0; i < 2; i++) {
        pthread_join(t[i], NULL);
        if (p[i].status != LMGI_OK)
            fail_msg("process %d: %s", i, p[i].message);
    }
    lmt_hub_free(&h.hub);
    print_message("passes taken: %d and %d; %d photon exchange calls\n", p[0].taken, p[1].taken, h.hub.calls[0]);
    assert_true(p[0].taken > 0 && p[1].taken > 0 && h.hub.calls[0] > 0 && h.hub.calls[0] == h.hub.calls[1]);

    lmgi_context *ctx = new_context();
    lmgi_scene *sc = load_scene("cornell.glb", 8000);
    lmgi_error e;
    lmgi_updater_desc whole = {.photons.count = 6000};
    const char *const parts[2] = {p[0].part, p[1].part};
    lmgi_updater_desc merged = {.photons.count = 6000, .parts = parts, .part_count = 2};
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * (size_t)in.atlas_height;
    float *maps[2][2];
    const lmgi_updater_desc *descs[2] = {&whole, &merged};
    for (int k = 0; k < 2; k++) {
        lmgi_updater *u = make_updater(ctx, sc, descs[k]);
        for (int m = 0; m < 2; m++) {
            maps[k][m] = malloc(n * sizeof(float));
            assert_int_equal(lmgi_get_lightmap(u, m ? LMGI_LIGHTMAP_AIM : LMGI_LIGHTMAP_IIM, maps[k][m], n, &e), LMGI_OK);
        }
        lmgi_updater_free(u);
    }
    assert_memory_equal(maps[0][0], maps[1][0], n * sizeof(float));
    assert_memory_equal(maps[0][1], maps[1][1], n * sizeof(float));
    for (int k = 0; k < 2; k++)
        free(maps[k][0]), free(maps[k][1]);

    lmgi_updater *u = NULL;
    merged.part_count = 1;
    expect_invalid(lmgi_updater_create(ctx, sc, &merged, &u, &e), &e, "are in no part");
    lmgi_updater_desc bad = {.photons.count = 6000, .shard = 0, .shards = 2, .checkpoint = p[0].part, .resume = 1};
    expect_invalid(lmgi_updater_create(ctx, sc, &bad, &u, &e), &e, "a shared (MPI) bake: it does not resume");
    bad = (lmgi_updater_desc){.claim_pass = share_claim, .share_user = &p[0], .checkpoint = p[0].part};
    expect_invalid(lmgi_updater_create(ctx, sc, &bad, &u, &e), &e, "claim_pass connects the processes");
    bad = (lmgi_updater_desc){.photons.count = 6000, .shard = 0, .shards = 2, .checkpoint = p[0].part,
                              .claim_pass = claim_beyond};
    expect_invalid(lmgi_updater_create(ctx, sc, &bad, &u, &e), &e, "claim_pass gave pass");
    close_all(NULL, sc, ctx);
}

/* Bounce passes (docs/gather.md) in a bake in shards: the shards gather their parts of the first pass
 * alone (a shard is refused bounce passes: test_shard_cancelled_and_resumed), and the merge makes them from
 * the parts put together, to the same bits as one process's bake with them. */
static void test_merge_makes_the_bounce_passes(void **state)
{
    (void)state;
    lmgi_context *ctx = new_context();
    lmgi_scene *sc = load_scene("cornell.glb", 8000);
    lmgi_error e;
    char part[2][512];
    for (int i = 0; i < 2; i++) {
        snprintf(part[i], sizeof part[i], "%s/bounce%d.part", lmt_tmpdir(), i);
        lmgi_updater_desc d = {.photons.count = 6000, .gather.scheme = LMGI_GATHER_RAYS, .shard = i, .shards = 2,
                               .checkpoint = part[i]};
        lmgi_updater_free(make_updater(ctx, sc, &d));
    }
    const char *const parts[2] = {part[0], part[1]};
    lmgi_updater_desc whole = {.photons.count = 6000, .gather.scheme = LMGI_GATHER_RAYS, .gather.bounce_passes = 2};
    lmgi_updater_desc merged = whole, first = whole;
    merged.parts = parts, merged.part_count = 2;
    first.gather.bounce_passes = LMGI_OFF;
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * (size_t)in.atlas_height;
    float *iim[3];
    const lmgi_updater_desc *descs[3] = {&whole, &merged, &first};
    for (int k = 0; k < 3; k++) {
        lmgi_updater *u = make_updater(ctx, sc, descs[k]);
        iim[k] = malloc(n * sizeof(float));
        assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, iim[k], n, &e), LMGI_OK);
        lmgi_updater_free(u);
    }
    assert_memory_equal(iim[0], iim[1], n * sizeof(float));
    assert_true(memcmp(iim[0], iim[2], n * sizeof(float)) != 0); /* the passes did gather again */
    for (int k = 0; k < 3; k++)
        free(iim[k]);
    close_all(NULL, sc, ctx);
}

/* The library says the version the header it was built with says, part by part. */
static void test_version(void **state)
{
    (void)state;
    assert_int_equal(lmgi_version(), LMGI_VERSION);
    assert_int_equal(lmgi_version() / 10000, LMGI_VERSION_MAJOR);
    assert_int_equal(lmgi_version() / 100 % 100, LMGI_VERSION_MINOR);
    assert_int_equal(lmgi_version() % 100, LMGI_VERSION_PATCH);
}

static void test_exported_symbols(void **state)
{
    (void)state;
    const char *build = getenv("LMGI_BUILD");
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "nm -D --defined-only %s/liblmgi.so", build ? build : "build");
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    char line[1024];
    int exported = 0;
    while (fgets(line, sizeof line, p)) {
        char type[8], name[900];
        if (sscanf(line, "%*s %7s %899s", type, name) != 2)
            continue;
        if (strncmp(name, "lmgi_", 5) != 0)
            fail_msg("liblmgi.so exports %s, which is not in lmgi.h or lmgi_tools.h", name);
        exported++;
    }
    assert_int_equal(pclose(p), 0);
    int declared = 0;
    for (int h = 0; h < 2; h++) { /* the runtime's header and the lab's */
        size_t size = 0;
        char *header = (char *)lmt_read_file(h ? "include/lmgi_tools.h" : "include/lmgi.h", &size, 1);
        header[size] = '\0';
        for (const char *q = header; (q = strstr(q, "\nLMGI_API ")) != NULL; q++)
            declared++;
        free(header);
    }
    print_message("liblmgi.so exports %d symbols, lmgi.h and lmgi_tools.h declare %d\n", exported, declared);
    assert_true(declared > 30);
    assert_int_equal(exported, declared);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_context),
        cmocka_unit_test(test_intersect_material_and_uv),
        cmocka_unit_test(test_log_callback),
        cmocka_unit_test(test_two_contexts_one_thread),
        cmocka_unit_test(test_lightmaps_and_versions),
        cmocka_unit_test(test_lightmap_rect),
        cmocka_unit_test(test_lightmap_pages),
        cmocka_unit_test(test_edit_reaches_updater),
        cmocka_unit_test(test_light_edit_stays_in_its_room),
        cmocka_unit_test(test_bake),
        cmocka_unit_test(test_recolour_material),
        cmocka_unit_test(test_budget_sets_texels),
        cmocka_unit_test(test_bad_arguments),
        cmocka_unit_test(test_write_image),
        cmocka_unit_test(test_tonemap_rgba8),
        cmocka_unit_test(test_geometry_hash),
        cmocka_unit_test(test_scene_from_arrays),
        cmocka_unit_test(test_second_thread_refused),
        cmocka_unit_test(test_shard_cancelled_and_resumed),
        cmocka_unit_test(test_shared_bake_is_one_process_bake),
        cmocka_unit_test(test_merge_makes_the_bounce_passes),
        cmocka_unit_test(test_exported_symbols),
        cmocka_unit_test(test_version),
    };
    lmgi_set_verbosity(0); /* the refusals below log errors on purpose */
    return cmocka_run_group_tests(tests, NULL, NULL);
}
