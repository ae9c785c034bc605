/* Open surfaces (docs/charts.md, "Open surfaces"; src/trace/surface_need.h, sun_guide.h): what a surface's
 * texels are worth from what its points see, against the split-sphere model's closed form; a level's open
 * ground giving its texels to the rest while a closed room keeps its own to the bit; a sun's photons drawn
 * where the texels are, the light they carry unchanged. */
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
#include "../src/gpu/gather/hemicube.h"
#include "../src/trace/surface_need.h"
#include "edit_room.h"
#include "support.h"

/* Two L x L plates h apart, facing each other (the floor up, the ceiling down). */
static const char *plates(const char *name, float L, float h, int ceiling)
{
    static lmt_mesh m[1];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-L / 2, 0, -L / 2}, (float[3]){0, 0, L}, (float[3]){L, 0, 0});
    if (ceiling)
        lmt_mesh_quad(&m[0], (float[3]){-L / 2, h, -L / 2}, (float[3]){L, 0, 0}, (float[3]){0, 0, L});
    char file[64];
    snprintf(file, sizeof file, "%s.gltf", name);
    return lmt_write_scene(file, m, 1, "[{\"mesh\": 0}]", "[" LMT_DIFFUSE(0.5) "]");
}

/* Between two plates 0.1 apart and 20 wide, a cosine ray from the floor meets the ceiling at h / cos, so the
 * mean of 1 / d is E[cos] / h = 2 / (3 h) and the need per area 4 / (9 h^2) (and 0.8% more from 16 rays a
 * point: the mean of a square); nothing sees the sky. A lone plate needs nothing and sees only sky. */
static void test_need_between_plates(void **state)
{
    (void)state;
    const float h = 0.1f, L = 20.0f;
    for (int ceiling = 1; ceiling >= 0; ceiling--) {
        lmt_pipeline p;
        lmt_pipeline_load(&p, plates(ceiling ? "need_plates" : "need_plate", L, h, ceiling), 1.0f);
        double need[2] = {-1, -1}, sky[2] = {-1, -1};
        lm_error err;
        assert_int_equal(p.su.surface_count, 1 + ceiling);
        assert_int_equal(lm_surface_need(p.rt, p.s, &p.su, 0.01f, need, sky, &err), LM_OK);
        double expect = L * L * 4.0 / (9.0 * h * h);
        for (int f = 0; f < p.su.surface_count; f++) {
            print_message("%s: surface %d need %.1f (%.1f if closed), sky %.4f\n", ceiling ? "plates" : "plate", f,
                          need[f], expect, sky[f]);
            if (ceiling) {
                assert_true(fabs(need[f] / expect - 1.0) < 0.03);
                assert_true(sky[f] < 0.02);
            } else {
                assert_true(need[f] == 0.0 && sky[f] == 1.0);
            }
        }
        assert_int_equal(lm_surface_need(p.rt, p.s, &p.su, 0.0f, need, sky, &err), LM_ERR_INVALID);
        lmt_pipeline_free(&p);
    }
}

/* A 4 x 3 x 4 m closed room (inward walls) standing on a 200 x 200 m ground: mesh 0 the room, mesh 1 the
 * ground; room 0: the room alone. */
static const char *room_on_ground(const char *name, int ground)
{
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, -2}, (float[3]){0, 0, 4}, (float[3]){4, 0, 0});  /* floor */
    lmt_mesh_quad(&m[0], (float[3]){-2, 3, -2}, (float[3]){4, 0, 0}, (float[3]){0, 0, 4});  /* ceiling */
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, -2}, (float[3]){0, 3, 0}, (float[3]){0, 0, 4});  /* x = -2 */
    lmt_mesh_quad(&m[0], (float[3]){2, 0, -2}, (float[3]){0, 0, 4}, (float[3]){0, 3, 0});   /* x = +2 */
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, -2}, (float[3]){4, 0, 0}, (float[3]){0, 3, 0});  /* z = -2 */
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, 2}, (float[3]){0, 3, 0}, (float[3]){4, 0, 0});   /* z = +2 */
    lmt_mesh_quad(&m[1], (float[3]){-100, -0.01f, -100}, (float[3]){0, 0, 200}, (float[3]){200, 0, 0});
    char file[64];
    snprintf(file, sizeof file, "%s.gltf", name);
    return lmt_write_scene(file, m, ground ? 2 : 1, ground ? "[{\"mesh\": 0}, {\"mesh\": 1}]" : "[{\"mesh\": 0}]",
                           "[" LMT_DIFFUSE(0.5) ", " LMT_DIFFUSE(0.5) "]");
}

typedef struct {
    uint32_t texels, room, ground; /* in all, the room's (y in (0, 3), |x|, |z| < 2.01) and the ground's */
} split;

static split texels_of(const char *path, float open_need)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 4000;
    o.open_need = open_need;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load(path, &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    split r = {lmgi_texel_count(sc), 0, 0};
    for (uint32_t i = 0; i < r.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        if (t.position[1] < -0.005f)
            r.ground++;
        else if (fabsf(t.position[0]) < 2.01f && fabsf(t.position[2]) < 2.01f)
            r.room++;
    }
    lmgi_free(sc);
    return r;
}

/* The ground sees sky from nearly every point and holds 99.8% of the area: by area alone (the library's
 * default) it takes nearly the whole budget and the room a few texels a wall. Its texels made up to 64 times coarser, the room's inside
 * gets the budget (measured: room 30 and ground 4,096 texels by area; 3,432 and 400 with the rule). The budget
 * is met either way, within 15%. */
static void test_open_ground_gives_its_texels(void **state)
{
    (void)state;
    const char *path = room_on_ground("open_ground", 1);
    split by_area = texels_of(path, 0.0f), open = texels_of(path, 0.25f), off = texels_of(path, (float)LMGI_OFF);
    print_message("4,000 texels by area: room %u, ground %u; with the open rule: room %u, ground %u (%u in all)\n",
                  by_area.room, by_area.ground, open.room, open.ground, open.texels);
    assert_true(off.texels == by_area.texels && off.room == by_area.room); /* the library's default: off */
    assert_true(by_area.ground > 20 * by_area.room);
    assert_true(open.room > 20 * by_area.room);
    assert_true(open.ground < by_area.ground / 8);
    assert_true(open.ground > 0);
    assert_true(fabs((double)open.texels / 4000.0 - 1.0) < 0.15 && fabs((double)by_area.texels / 4000.0 - 1.0) < 0.15);
}

/* A closed room sees no sky: the rule leaves it alone, texel for texel. */
static void test_closed_room_keeps_its_texels(void **state)
{
    (void)state;
    const char *path = room_on_ground("closed_room", 0);
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 4000;
    o.open_need = 0.25f;
    lmgi_scene *a = NULL, *b = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_load(path, &o, &a, &e), LMGI_OK);
    o.open_need = (float)LMGI_OFF;
    assert_int_equal(lmgi_load(path, &o, &b, &e), LMGI_OK);
    assert_int_equal(lmgi_texel_count(a), lmgi_texel_count(b));
    for (uint32_t i = 0; i < lmgi_texel_count(a); i++) {
        lmgi_texel ta, tb;
        lmgi_get_texel(a, i, &ta);
        lmgi_get_texel(b, i, &tb);
        assert_true(ta.x == tb.x && ta.y == tb.y && !memcmp(ta.position, tb.position, sizeof ta.position));
    }
    lmgi_free(a);
    lmgi_free(b);
    o.open_need = 1.5f; /* out of range */
    assert_int_equal(lmgi_load(path, &o, &a, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "open_need"));
}

/* A 2 m cube on a 200 x 200 m ground under a sun of 20 lux travelling along (-1, -0.6, 0): the cube's +x face
 * takes E A cos = 20 x 4 x 0.857 and its top 20 x 4 x 0.514, 109.8 in all, the ground E A cos less that.
 * Drawn uniformly over the rectangle, 65,536 photons put 18 on the cube; the guide, with the ground's texels
 * coarser, hundreds of times more (measured: 4,333), and the flux that lands on each stays what it is (within
 * 0.1% on both). */
static const char *cube_on_ground(void)
{
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_cube(&m[0], 1.0f);
    lmt_mesh_quad(&m[1], (float[3]){-100, 0, -100}, (float[3]){0, 0, 200}, (float[3]){200, 0, 0});
    return lmt_write_scene(
        "guide_cube.gltf", m, 2,
        "[{\"mesh\": 0, \"translation\": [0, 1, 0]}, {\"mesh\": 1}, {\"matrix\": [0, 0, 1, 0, 0.514496, -0.857493, 0, "
        "0, 0.857493, 0.514496, 0, 0, 0, 0, 0, 1], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]",
        "[" LMT_DIFFUSE(0.5) ", " LMT_DIFFUSE(0.5) "], " LMT_LIGHTS("{\"type\": \"directional\", \"intensity\": 20}"));
}

typedef struct {
    double cube, ground;  /* flux (green) that first lands on each */
    uint32_t on_cube;     /* photons that do */
} landing;

static landing land(const lmt_pipeline *p, uint32_t n)
{
    landing l = {0, 0, 0};
    for (uint32_t i = 0; i < n; i++) {
        float u[4];
        for (int k = 0; k < 4; k++)
            u[k] = (float)lm_halton((uint32_t)k, i);
        lm_emission emi;
        lm_emitter_emit(&p->em, p->s, 0, u, n, &emi);
        lm_rt_hit h;
        if (!lm_rt_intersect(p->rt, emi.org, emi.dir, 0.0f, INFINITY, &h))
            continue;
        if (p->s->nodes[h.node].mesh == 0)
            l.cube += emi.flux[1], l.on_cube++;
        else
            l.ground += emi.flux[1];
    }
    return l;
}

static void test_sun_guide_keeps_the_light(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, cube_on_ground(), 0.0f);
    assert_int_equal(p.em.e[0].kind, LM_EMIT_DIRECTIONAL);
    /* the atlas again with what the surfaces need, as lmgi_load makes it */
    size_t n = (size_t)p.su.surface_count;
    double *need = malloc(2 * n * sizeof *need);
    assert_non_null(need);
    lm_error err;
    assert_int_equal(lm_surface_need(p.rt, p.s, &p.su, 1.0f, need, need + n, &err), LM_OK);
    lm_atlas_options ao;
    lm_atlas_options_default(&ao);
    ao.target_texels = 4000;
    ao.need = need, ao.sky = need + n, ao.open_need = 0.25f;
    lm_atlas_free(&p.atlas);
    assert_int_equal(lm_atlas_build(p.s, &p.su, &ao, &p.atlas, &err), LM_OK);
    free(need);
    assert_true(p.atlas.open_surfaces >= 1);

    const uint32_t count = 1u << 16;
    landing uniform = land(&p, count), many = land(&p, 1u << 22);
    lm_sun_guide *g = NULL;
    assert_int_equal(lm_sun_guide_make(p.rt, p.s, &p.atlas, (const float(*)[3])p.em.e[0].rect, p.em.e[0].dir, &g, &err),
                     LM_OK);
    assert_non_null(g);
    lm_emitter_set_guide(&p.em, 0, g);
    landing guided = land(&p, count);
    const double cube = 20.0 * 4.0 * (0.857493 + 0.514496), ground = 20.0 * 200.0 * 200.0 * 0.514496 - cube;
    print_message("cube %.2f, ground %.0f: uniform %.2f from %u photons (%u of 4M: %.2f), ground %.0f; guided %.2f "
                  "from %u, ground %.0f\n", cube, ground, uniform.cube, uniform.on_cube, many.on_cube, many.cube,
                  uniform.ground, guided.cube, guided.on_cube, guided.ground);
    assert_true(fabs(many.cube / cube - 1.0) < 0.02);
    assert_true(guided.on_cube > 100 * (uniform.on_cube > 0 ? uniform.on_cube : 1));
    assert_true(fabs(guided.cube / cube - 1.0) < 0.01);
    assert_true(fabs(guided.ground / ground - 1.0) < 0.01 && fabs(uniform.ground / ground - 1.0) < 0.01);
    /* moved elsewhere, the sun draws uniformly again until its guide is made anew */
    p.em.e[0].rect[0][0] += 1.0f;
    landing stale = land(&p, 1024);
    p.em.e[0].rect[0][0] -= 1.0f;
    assert_true(stale.on_cube <= 1);
    lmt_pipeline_free(&p);
}

/* Where a texel gathers from on a level whose size is its ground's (the gather's eye, gather/hemicube.h):
 * 1e-4 of the 283 m scene is 2.8 cm, more than a hundredth of the room's texels; every texel's eye lies at
 * most LM_GATHER_TEXEL_LIFT texels off its centre (truck-town's house wall read 5-18% bright, lifted 29 cm). */
static void test_gather_eye_within_a_texel(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, room_on_ground("eye_ground", 1), 0.0f);
    lm_hemicube_settings set;
    lm_hemicube_settings_default(&set);
    float most = LM_GATHER_TEXEL_LIFT * p.atlas.texel_size, worst = 0.0f;
    assert_true(set.offset * lm_scene_size(p.s) > 2.0f * most);
    for (uint32_t i = 0; i < p.atlas.texel_count; i++) {
        float eye[3], n[3], ng[3], c[3], cn[3];
        lm_gather_texel_frame(&set, p.s, &p.atlas, i, eye, n, ng);
        lm_texel_centre_normal(p.s, &p.atlas.texels[i], c, cn);
        float d = sqrtf((eye[0] - c[0]) * (eye[0] - c[0]) + (eye[1] - c[1]) * (eye[1] - c[1]) +
                        (eye[2] - c[2]) * (eye[2] - c[2]));
        worst = fmaxf(worst, d);
    }
    print_message("eye lift: at most %.4f (a hundredth of the %.3f texel; the scene's share %.4f)\n", (double)worst,
                  (double)p.atlas.texel_size, (double)(set.offset * lm_scene_size(p.s)));
    assert_true(worst <= 1.001f * most);
    lmt_pipeline_free(&p);
}

/* The command line: --open-need F turns the rule on where the library's default leaves it off (lmgi info
 * says on how many surfaces), and a value out of range is refused, naming the option. */
static void test_cli_open_need(void **state)
{
    (void)state;
    char path[1024], args[1200], out[8192];
    snprintf(path, sizeof path, "%s", room_on_ground("cli_ground", 1));
    snprintf(args, sizeof args, "info %s --texels 4000 --open-need 0.25", path);
    assert_int_equal(lmt_lmgi("", args, out, sizeof out), 0);
    assert_non_null(strstr(out, "coarser texels on 1 surfaces that see mostly open sky"));
    snprintf(args, sizeof args, "info %s --texels 4000", path);
    assert_int_equal(lmt_lmgi("", args, out, sizeof out), 0);
    assert_null(strstr(out, "coarser texels"));
    snprintf(args, sizeof args, "info %s --open-need 1.5", path);
    assert_int_not_equal(lmt_lmgi("", args, out, sizeof out), 0);
    assert_non_null(strstr(out, "--open-need"));
}

int main(void)
{
    lmt_filter_from_env();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_need_between_plates),
        cmocka_unit_test(test_open_ground_gives_its_texels),
        cmocka_unit_test(test_closed_room_keeps_its_texels),
        cmocka_unit_test(test_sun_guide_keeps_the_light),
        cmocka_unit_test(test_gather_eye_within_a_texel),
        cmocka_unit_test(test_cli_open_need),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
