/* The brute-force photon gather at the visible pixels (photonmap/pixel_gather.h, the updater's
 * LMGI_INDIRECT_BRUTEFORCE path): the kernel estimate of a uniform photon field is its irradiance; hits
 * from behind and the punctual lights' first hits count nothing; the radius holds n photons; and on a
 * closed room the path's frame matches the reference and the lightmap path's. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi_tools.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/photonmap/pixel_gather.h"
#include "edit_room.h"
#include "support.h"

/* Photons of flux phi on a grid of spacing s over the plane y = 0, x and z in [-1, 1], arriving from
 * above: irradiance phi / s^2 everywhere away from the border. Three visible points look at it: two
 * from above, one from below (the field is behind it). kd = pi makes the radiance kd / pi x E = E. */
static void test_uniform_field(void **state)
{
    (void)state;
    lm_photon_store ps;
    lm_error err;
    assert_int_equal(lm_photon_store_init(&ps, 1, &err), LM_OK);
    const float s = 0.01f, phi = 1e-4f; /* E = 1 */
    for (int i = 0; i <= 200; i++)
        for (int j = 0; j <= 200; j++) {
            lm_hit h;
            memset(&h, 0, sizeof h);
            h.pos[0] = -1.0f + s * (float)i, h.pos[2] = -1.0f + s * (float)j;
            h.dir[1] = -1.0f;
            h.flux[0] = h.flux[1] = h.flux[2] = phi;
            h.bounce = 1;
            assert_true(lm_photon_store_add(&ps, &h) != LM_NONE);
        }
    lm_hit lamp; /* a punctual light's first hit: the direct pass's, not the gather's */
    memset(&lamp, 0, sizeof lamp);
    lamp.dir[1] = -1.0f;
    lamp.flux[0] = lamp.flux[1] = lamp.flux[2] = 100.0f;
    lamp.source = LM_HIT_FROM_PUNCTUAL;
    assert_true(lm_photon_store_add(&ps, &lamp) != LM_NONE);

    float pos[9] = {0, 0, 0, 0.5f, 0, -0.3f, 0, 0, 0}, normal[9] = {0, 1, 0, 0, 1, 0, 0, -1, 0};
    float kd[9] = {(float)M_PI, (float)M_PI, (float)M_PI, (float)M_PI, 0.5f * (float)M_PI, 0, (float)M_PI,
                   (float)M_PI, (float)M_PI};
    lm_gbuffer g = {3, 1, pos, normal, kd};
    float out[9];
    lm_pixel_gather_bruteforce(&g, &ps, NULL, 0.1f, out); /* no scene: arrival directions stand in */
    print_message("uniform field of irradiance 1: %.4f %.4f %.4f | %.4f %.4f %.4f | from behind %g\n", out[0], out[1],
                  out[2], out[3], out[4], out[5], out[6]);
    for (int c = 0; c < 3; c++)
        assert_float_equal(out[c], 1.0f, 0.01f);
    assert_float_equal(out[3], 1.0f, 0.01f); /* kd scales it per channel */
    assert_float_equal(out[4], 0.5f, 0.005f);
    assert_true(out[5] == 0.0f);
    assert_true(out[6] == 0.0f && out[7] == 0.0f && out[8] == 0.0f);

    lm_surface surf = {.area = 4.0f};
    lm_surfaces su = {.surface_count = 1, .surfaces = &surf};
    float r = lm_pixel_gather_radius(&ps, &su, 128); /* the 201^2 grid hits, not the lamp's */
    assert_float_equal(r, sqrt(128.0 * 4.0 / (M_PI * 201.0 * 201.0)), 1e-6);
    lm_photon_store_free(&ps);
}

static const lmgi_light_desc LAMP = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f,
                                     .position = {-1.2f, 2.5f, -1.0f}};

/* Mean of each channel of a w x h x 3 picture over the pixels where mask (the reference) is lit. */
static void means(const float *rgb, const float *mask, int n, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    for (int i = 0; i < n; i++)
        if (mask[3 * i] + mask[3 * i + 1] + mask[3 * i + 2] > 0.0f)
            for (int c = 0; c < 3; c++)
                out[c] += rgb[3 * i + c];
}

/* The edit room (edit_room.h: closed, a red block, a point light) from its corner with each indirect path
 * against the reference's pixels: the brute-force frame within 3% of it per channel, as the lightmap
 * path's; then, on the brute-force path, no AIM or IIM work (the lightmap stays 0), and the same frame for
 * the same scene and settings. */
static void test_room(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmt_room_spec spec = {.lights = &LAMP, .light_count = 1};
    lmgi_scene *sc = lmt_room(&spec), *twin = lmt_room(&spec);
    lmgi_camera cam;
    lmt_corner_camera(&cam);
    lmgi_reference ref;
    lmgi_reference_desc rd = {.target_error = 0.03f, .no_cache = 1};
    lmgi_error e;
    if (lmgi_reference_pixels(sc, &rd, &cam, LMT_SIDE, LMT_SIDE, &ref, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    const int n = LMT_SIDE * LMT_SIDE;
    double want[3];
    means(ref.full, ref.full, n, want);
    float *frames[2];
    for (int path = 0; path < 2; path++) {
        lmgi_updater_desc d;
        memset(&d, 0, sizeof d);
        d.indirect = path ? LMGI_INDIRECT_BRUTEFORCE : LMGI_INDIRECT_LIGHTMAP;
        lmgi_updater *u = NULL;
        if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
            fail_msg("%s", e.message);
        lmgi_update_stats st;
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
        frames[path] = lmt_corner_frame(u);
        double got[3];
        means(frames[path], ref.full, n, got);
        print_message("%s path: frame / reference %.3f %.3f %.3f; AIM surfaces refreshed %d, texels gathered %u\n",
                      path ? "brute-force" : "lightmap", got[0] / want[0], got[1] / want[1], got[2] / want[2],
                      st.aim_surfaces_refreshed, st.texels_gathered);
        for (int c = 0; c < 3; c++)
            assert_true(fabs(got[c] / want[c] - 1.0) < 0.03);
        if (path) { /* no AIM, no IIM: the lightmap stays 0 */
            assert_int_equal(st.aim_surfaces_refreshed, 0);
            assert_int_equal(st.texels_gathered, 0);
            size_t count;
            float *iim = lmt_iim(u, sc, &count), *aim = malloc(count * sizeof *aim);
            assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_AIM, aim, count, &e), LMGI_OK);
            for (size_t i = 0; i < count; i += 4)
                for (int c = 0; c < 3; c++)
                    assert_true(iim[i + c] == 0.0f && aim[i + c] == 0.0f);
            free(iim), free(aim);
            lmgi_updater *ut = NULL;
            assert_int_equal(lmgi_updater_create(ctx, twin, &d, &ut, &e), LMGI_OK);
            assert_int_equal(lmgi_update(ut, 0.0f, 0.0f, &st, &e), LMGI_OK);
            float *again = lmt_corner_frame(ut);
            assert_memory_equal(again, frames[path], 3 * (size_t)n * sizeof *again);
            free(again);
            lmgi_updater_free(ut);
            d.indirect = (lmgi_indirect_path)7;
            lmgi_updater *bad = NULL;
            lmgi_updater_free(u);
            u = NULL;
            lmt_expect_invalid(lmgi_updater_create(ctx, twin, &d, &bad, &e), &e, "indirect 7");
        }
        lmgi_updater_free(u);
    }
    free(frames[0]), free(frames[1]);
    lmgi_reference_free(&ref);
    lmgi_free(sc);
    lmgi_free(twin);
    lmgi_context_free(ctx);
}

/* A ball of radius 0.35 on the floor of a 4 x 3 x 4 plaster room lit by LAMP, its vertex normals smooth: the
 * charts split it into surfaces of 30 degrees, each far smaller than the per-pixel gathers' disc. Their sum
 * takes the hits of a pixel's neighbouring facets (within 60 degrees of its normal), so the disc's part on
 * them must count in the coverage too: with the pixel's own surface alone, the ball read 4.5 to 14 times
 * the reference on room_lit's spheres (docs/tiled.md). */
enum { BALL_RINGS = 12, BALL_SEGMENTS = 24, BALL_VERTS = (BALL_RINGS + 1) * (BALL_SEGMENTS + 1) };
static uint32_t make_ball(float *v, float *nrm, uint32_t *idx)
{
    for (int i = 0; i <= BALL_RINGS; i++)
        for (int j = 0; j <= BALL_SEGMENTS; j++) {
            double th = M_PI * i / BALL_RINGS, ph = 2.0 * M_PI * j / BALL_SEGMENTS;
            double d[3] = {sin(th) * cos(ph), cos(th), sin(th) * sin(ph)};
            int k = i * (BALL_SEGMENTS + 1) + j;
            for (int c = 0; c < 3; c++)
                nrm[3 * k + c] = (float)d[c], v[3 * k + c] = (float)(0.35 * d[c] + (c == 1 ? 0.35 : 0.0));
        }
    int t = 0;
    for (int i = 0; i < BALL_RINGS; i++)
        for (int j = 0; j < BALL_SEGMENTS; j++) {
            uint32_t a = (uint32_t)(i * (BALL_SEGMENTS + 1) + j), b = a + 1, c = a + BALL_SEGMENTS + 1, e = c + 1;
            const uint32_t q[6] = {a, b, e, a, e, c};
            for (int m = i == 0 ? 3 : 0; m < (i == BALL_RINGS - 1 ? 3 : 6); m++) /* none of zero area at the poles */
                idx[t++] = q[m];
        }
    return (uint32_t)t / 3;
}

static void test_small_curved_surfaces(void **state)
{
    (void)state;
    static float room_v[72], ball_v[3 * BALL_VERTS], ball_n[3 * BALL_VERTS];
    static uint32_t room_i[36], ball_i[6 * BALL_RINGS * BALL_SEGMENTS];
    lmt_box((float[3]){-2, 0, -2}, (float[3]){2, 3, 2}, 1, room_v, room_i);
    uint32_t ball_tris = make_ball(ball_v, ball_n, ball_i);
    lmgi_mesh_desc meshes[2] = {
        {.name = "room", .positions = room_v, .vertex_count = 24, .indices = room_i, .triangle_count = 12},
        {.name = "ball", .positions = ball_v, .normals = ball_n, .vertex_count = BALL_VERTS, .indices = ball_i,
         .triangle_count = ball_tris, .material = 1}};
    const lmgi_material_desc mats[2] = {{.name = "plaster", .base_color = {0.7f, 0.7f, 0.7f, 1.0f}},
                                        {.name = "blue", .base_color = {0.05f, 0.4f, 0.8f, 1.0f}}};
    lmgi_scene_desc desc = {.name = "a ball in the room", .meshes = meshes, .mesh_count = 2, .materials = mats,
                            .material_count = 2, .lights = &LAMP, .light_count = 1};
    lmgi_scene *sc = lmt_load_desc(&desc, 1500, 0.0f);
    lmgi_context *ctx = lmt_context();
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.indirect = LMGI_INDIRECT_BRUTEFORCE;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, NULL, &e), LMGI_OK);
    lmgi_camera cam;
    lmt_look_at((float[3]){0.8f, 0.9f, 0.8f}, (float[3]){0.0f, 0.35f, 0.0f}, 0.9f, &cam);
    lmgi_reference_desc rd = {.target_error = 0.03f, .no_cache = 1};
    lmgi_check_result c;
    assert_int_equal(lmgi_check_updater(u, &cam, 64, 64, &rd, &c, &e), LMGI_OK);
    double got[3] = {0}, want[3] = {0};
    unsigned pixels = 0;
    for (int k = 0; k < c.surface_count; k++)
        if (c.surfaces[k].node == 1)
            for (int ch = 0; ch < 3; ch++)
                got[ch] += c.surfaces[k].frame_mean[ch] * c.surfaces[k].pixels,
                    want[ch] += c.surfaces[k].reference_mean[ch] * c.surfaces[k].pixels,
                    pixels += ch == 0 ? c.surfaces[k].pixels : 0;
    print_message("a ball of %d surfaces, brute-force path: its %u pixels / reference %.3f %.3f %.3f; frame %.3f "
                  "%.3f %.3f\n", lmgi_surface_count(sc) - 6, pixels, got[0] / want[0], got[1] / want[1],
                  got[2] / want[2], c.ratio[0], c.ratio[1], c.ratio[2]);
    assert_true(pixels > 300);
    for (int ch = 0; ch < 3; ch++)
        assert_true(fabs(got[ch] / want[ch] - 1.0) < 0.1);
    lmgi_check_free(&c);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_uniform_field),
        cmocka_unit_test(test_room),
        cmocka_unit_test(test_small_curved_surfaces),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
