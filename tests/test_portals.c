/* Portals (issue 30, item 3; docs/levels.md, "Portals"; src/trace/portals.h): a closed room, 4 x 3 x 4 m,
 * on a 60 x 60 m ground, lit inside only through a 1 x 1 m window in its +x wall by a sun. Without a
 * portal the sun's photons leave from a rectangle across the whole level and about one in 2,000 enters;
 * with the window tagged as a portal half of them are drawn through it. The estimate must stay the same
 * (the mixture's density weighs each photon), and the room must be lit by photons everywhere. A portal
 * with no mesh is refused, naming its node. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <lmgi.h>

#include "../src/core/qmc.h"
#include "../src/trace/lights.h"
#include "../src/trace/portals.h"
#include "edit_room.h"
#include "support.h"

/* The room (mesh 0: floor, ceiling, four walls facing in, the +x wall around its window), the window's
 * portal quad (mesh 1, its front facing out, +x) and a sun travelling along (-1, -0.6, 0): through the
 * window onto the floor near x = -0.5. `portal`: tag mesh 1 as a portal (else it is left out). `sky`:
 * extras of the root, or "". */
static const char *room(const char *name, int portal, const char *sky)
{
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, -2}, (float[3]){0, 0, 4}, (float[3]){4, 0, 0});   /* floor */
    lmt_mesh_quad(&m[0], (float[3]){-2, 3, -2}, (float[3]){4, 0, 0}, (float[3]){0, 0, 4});   /* ceiling */
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, -2}, (float[3]){0, 3, 0}, (float[3]){0, 0, 4});   /* x = -2 */
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, -2}, (float[3]){4, 0, 0}, (float[3]){0, 3, 0});   /* z = -2 */
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, 2}, (float[3]){0, 3, 0}, (float[3]){4, 0, 0});    /* z = +2 */
    lmt_mesh_quad(&m[0], (float[3]){2, 0, -2}, (float[3]){0, 0, 4}, (float[3]){0, 1, 0});    /* x = +2 below */
    lmt_mesh_quad(&m[0], (float[3]){2, 2, -2}, (float[3]){0, 0, 4}, (float[3]){0, 1, 0});    /* above */
    lmt_mesh_quad(&m[0], (float[3]){2, 1, -2}, (float[3]){0, 0, 1.5f}, (float[3]){0, 1, 0}); /* beside */
    lmt_mesh_quad(&m[0], (float[3]){2, 1, 0.5f}, (float[3]){0, 0, 1.5f}, (float[3]){0, 1, 0});
    lmt_mesh_quad(&m[0], (float[3]){-30, -0.01f, -30}, (float[3]){0, 0, 60}, (float[3]){60, 0, 0}); /* ground */
    lmt_mesh_quad(&m[1], (float[3]){2, 1, -0.5f}, (float[3]){0, 1, 0}, (float[3]){0, 0, 1}); /* the window */
    char nodes[1024], file[64];
    /* the sun's node: -Z along (-1, -0.6, 0) / 1.16619: x' = (0, 0, 1), y' = (0.6, -1, 0) / n, z' = (1, 0.6, 0) / n */
    snprintf(nodes, sizeof nodes,
             "[{\"mesh\": 0}%s, {\"matrix\": [0, 0, 1, 0, 0.514496, -0.857493, 0, 0, 0.857493, 0.514496, 0, 0, 0, 0, "
             "0, 1], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}, {\"translation\": [-1.9, 1.5, 1.9], "
             "\"rotation\": [0, -0.3827, 0, 0.9239], \"camera\": 0}]",
             portal ? ", {\"mesh\": 1, \"extras\": {\"lmgi\": {\"portal\": true}}}" : "");
    snprintf(file, sizeof file, "%s.gltf", name);
    char materials[1024];
    snprintf(materials, sizeof materials,
             "[" LMT_DIFFUSE(0.7) ", " LMT_DIFFUSE(0.7) "], %s" LMT_LIGHTS("{\"type\": \"directional\", \"intensity\": 20}")
             ", \"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 1.2, \"znear\": 0.01}}]", sky);
    return lmt_write_scene(file, m, 2, nodes, materials);
}

typedef struct {
    double aim_mean;   /* the AIM's mean radiance over the room's inside (green, area-weighted) */
    uint32_t valid, dark; /* the inside's valid AIM texels, and those exactly 0 */
    double ratio[3], rmse; /* the frame against the reference (not measured with cam NULL) */
} outcome;

static outcome bake(const char *path, const lmgi_camera *cam, uint32_t photons)
{
    lmgi_scene *sc = lmt_load(path, 4000);
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.photons = photons;
    lmgi_updater *u = NULL;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *rgba = malloc(n * sizeof *rgba);
    assert_non_null(rgba);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_AIM, rgba, n, &e), LMGI_OK);
    outcome o;
    memset(&o, 0, sizeof o);
    double area = 0.0;
    for (uint32_t i = 0; i < lmgi_texel_count(sc); i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        const float *px = rgba + 4 * ((size_t)t.y * in.atlas_width + t.x);
        if (!(px[3] > 0.0f) || t.position[1] < 0.0f || fabsf(t.position[0]) > 2.001f || fabsf(t.position[2]) > 2.001f)
            continue; /* the ground, and what is not valid */
        o.valid++;
        o.dark += px[1] == 0.0f;
        o.aim_mean += t.area * px[1];
        area += t.area;
    }
    o.aim_mean /= area > 0.0 ? area : 1.0;
    free(rgba);
    if (!cam) {
        lmgi_updater_free(u);
        lmgi_free(sc);
        lmgi_context_free(ctx);
        return o;
    }
    lmgi_reference_desc rd;
    memset(&rd, 0, sizeof rd);
    rd.target_error = 0.03f;
    lmgi_check_result c;
    assert_int_equal(lmgi_check_updater(u, cam, 48, 48, &rd, &c, &e), LMGI_OK);
    memcpy(o.ratio, c.ratio, sizeof o.ratio);
    o.rmse = c.rel_rmse;
    lmgi_check_free(&c);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
    return o;
}

/* The room at the default photons without and with its portal, and without at 16 times the photons:
 * with the portal no texel inside is left at 0, the frame is within 5% of the reference and nearer it
 * than without, and the room's AIM within 5% of the many-photon one (measured: without the portal +37%,
 * with it -3%). */
static void compare(const char *what, const char *sky)
{
    char name[64];
    lmgi_camera cam;
    lmt_look_at((const float[3]){-1.9f, 1.6f, 1.9f}, (const float[3]){1.0f, 0.6f, -1.0f}, 1.2f, &cam);
    char open[1024];
    snprintf(name, sizeof name, "%s_open", what);
    snprintf(open, sizeof open, "%s", room(name, 0, sky));
    outcome without = bake(open, &cam, 0), many = bake(open, NULL, 16 * 46080);
    snprintf(name, sizeof name, "%s_portal", what);
    outcome with = bake(room(name, 1, sky), &cam, 0);
    print_message("%s, 16 x the photons, no portal: inside, AIM mean %.5f, %u of %u valid texels 0\n", what,
                  many.aim_mean, many.dark, many.valid);
    print_message("%s without a portal: AIM mean %.5f, %u of %u valid texels 0; frame / reference %.3f %.3f %.3f, "
                  "RMSE %.3f\n", what, without.aim_mean, without.dark, without.valid, without.ratio[0],
                  without.ratio[1], without.ratio[2], without.rmse);
    print_message("%s with the window a portal: AIM mean %.5f, %u of %u valid texels 0; frame / reference %.3f %.3f "
                  "%.3f, RMSE %.3f\n", what, with.aim_mean, with.dark, with.valid, with.ratio[0], with.ratio[1],
                  with.ratio[2], with.rmse);
    assert_int_equal(with.dark, 0);
    assert_true(fabs(with.aim_mean / many.aim_mean - 1.0) < 0.05);
    for (int k = 0; k < 3; k++)
        assert_float_equal(with.ratio[k], 1.0, 0.05);
    assert_true(fabs(with.ratio[1] - 1.0) < fabs(without.ratio[1] - 1.0));
}

/* The flux that enters through the window, summed over N photons of emitter e: the same with and without
 * the portal (what the mixture's weights promise), here straight from the emitters. */
static double entering(const char *path, int e, uint32_t n, uint32_t *through)
{
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 0.5f);
    static const float window[9 * 2] = {2, 1, -0.5f, 2, 2, -0.5f, 2, 2, 0.5f, 2, 1, -0.5f, 2, 2, 0.5f, 2, 1, 0.5f};
    lm_scene probe = *p.s; /* the window as a portal, to count what crosses it */
    probe.portal_tris = (float *)window, probe.portal_tri_count = 2;
    double sum = 0.0;
    *through = 0;
    for (uint32_t i = 0; i < n; i++) {
        float u[4];
        for (int k = 0; k < 4; k++)
            u[k] = (float)lm_halton((uint32_t)k, i);
        lm_emission emi;
        lm_emitter_emit(&p.em, p.s, e, u, n, &emi);
        if (lm_portal_crossings(&probe, emi.org, emi.dir) > 0) {
            sum += emi.flux[1];
            (*through)++;
        }
    }
    lmt_pipeline_free(&p);
    return sum;
}

/* The sun's flux through the window from 65,536 photons: with the portal within 2% of 4M photons'
 * without (what the mixture's weights promise), from over 500 times the photons. */
static void test_unbiased_emission(void **state)
{
    (void)state;
    char open[1024], tagged[1024]; /* lmt_write_scene's path is its own buffer */
    snprintf(open, sizeof open, "%s", room("emit_open", 0, ""));
    snprintf(tagged, sizeof tagged, "%s", room("emit_portal", 1, ""));
    uint32_t a, b, many;
    double without = entering(open, 0, 1u << 16, &a), with = entering(tagged, 0, 1u << 16, &b);
    double truth = entering(open, 0, 1u << 22, &many);
    print_message("sun: flux through the window %.5f from %u photons without the portal, %.5f from %u with it "
                  "(%.5f from %u of 4M without)\n", without, a, with, b, truth, many);
    assert_true(b > 500 * (a > 0 ? a : 1));
    assert_true(fabs(with / truth - 1.0) < 0.02);
}

/* A portal node without a mesh: refused, naming it. */
static void test_portal_without_mesh(void **state)
{
    (void)state;
    static lmt_mesh m[1];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-1, 0, -1}, (float[3]){0, 0, 2}, (float[3]){2, 0, 0});
    const char *path = lmt_write_scene("bad_portal.gltf", m, 1,
                                       "[{\"mesh\": 0}, {\"name\": \"window\", \"extras\": {\"lmgi\": {\"portal\": true}}}]",
                                       "[" LMT_DIFFUSE(0.7) "]");
    lmgi_options o;
    lmgi_options_init(&o);
    lmgi_scene *sc = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_load(path, &o, &sc, &e), LMGI_ERR_INVALID);
    assert_null(sc);
    assert_non_null(strstr(e.message, "window"));
    assert_non_null(strstr(e.message, "portal"));
}

static void test_sun_through_a_window(void **state)
{
    (void)state;
    compare("sun", "");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_unbiased_emission),
        cmocka_unit_test(test_sun_through_a_window),
        cmocka_unit_test(test_portal_without_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
