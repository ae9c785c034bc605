/* cli/view_maps: the viewer's views of the lighting on the scene and of the atlas. The texel each pixel
 * shows is where the pixel looks (its world position projects back onto the pixel); the IIM view is the
 * lightmap read back at those texels; the error view shows what an edit left to come and goes dark once
 * the lighting caught up; the atlas view marks the texels still to move and the surfaces an update
 * changed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cli/view_maps.h"
#include "edit_room.h"

static const lmgi_light_desc LAMP = {.name = "lamp", .type = LMGI_LIGHT_POINT, .color = {1.0f, 0.9f, 0.8f},
                                     .intensity = 4.0f, .position = {-1.0f, 2.5f, -1.0f}};

static lmgi_scene *room(void)
{
    lmt_room_spec spec = {.lights = &LAMP, .light_count = 1};
    return lmt_room(&spec);
}

/* The world ray through the centre of pixel (x, y) of a w x h picture from cam (GL conventions). */
static void pixel_ray(const lmgi_camera *cam, int x, int y, int w, int h, double o[3], double d[3])
{
    const float *v = cam->view, *p = cam->proj;
    double c[3] = {(2.0 * (x + 0.5) / w - 1.0) / p[0], (1.0 - 2.0 * (y + 0.5) / h) / p[5], -1.0}, len = 0.0;
    for (int k = 0; k < 3; k++) {
        o[k] = -(v[4 * k] * v[12] + v[4 * k + 1] * v[13] + v[4 * k + 2] * v[14]);
        d[k] = v[4 * k] * c[0] + v[4 * k + 1] * c[1] + v[4 * k + 2] * c[2];
        len += d[k] * d[k];
    }
    for (int k = 0; k < 3; k++)
        d[k] /= sqrt(len);
}

/* From the room's corner every pixel sees the room or the block, so 95% and more of them find a texel; and
 * the texel found lies on the pixel's ray: the ray passes within a texel's side (the square root of its
 * area) of its centre, for 99% of the pixels (the rest where a texel's centre is around a corner). */
static void test_texels_are_where_pixels_look(void **state)
{
    (void)state;
    lmgi_scene *sc = room();
    int *texel_of = lmt_texel_ids(sc);
    lmgi_camera cam;
    lmt_corner_camera(&cam);
    int w = LMT_SIDE, h = LMT_SIDE, seen = 0, near = 0;
    int *px = malloc(sizeof *px * (size_t)w * (size_t)h);
    assert_non_null(px);
    lm_view_map_texels(sc, &cam, w, h, px);
    double worst = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int a = px[y * w + x];
            if (a < 0)
                continue;
            seen++;
            lmgi_texel t;
            lmgi_get_texel(sc, (uint32_t)texel_of[a], &t);
            double o[3], d[3], q[3], along = 0.0, off = 0.0;
            pixel_ray(&cam, x, y, w, h, o, d);
            for (int k = 0; k < 3; k++)
                q[k] = t.position[k] - o[k], along += q[k] * d[k];
            for (int k = 0; k < 3; k++)
                off += (q[k] - along * d[k]) * (q[k] - along * d[k]);
            double sides = sqrt(off) / sqrt((double)t.area);
            worst = fmax(worst, sides);
            near += sides <= 1.0;
        }
    print_message("%d of %d pixels see a texel, %d of them one the ray passes within a texel's side of (farthest "
                  "%.2f sides)\n", seen, w * h, near, worst);
    assert_true(seen >= w * h * 95 / 100);
    assert_true(near >= seen * 99 / 100);
    free(px);
    free(texel_of);
    lmgi_free(sc);
}

/* Whether pixel p of an error view is the ramp's zero (dark blue). */
static int dark(const float *p) { return p[0] == 0.0f && p[1] == 0.0f && p[2] > 0.0f; }

/* The IIM view holds the lightmap's texels as lmgi_get_lightmap reads them. The lamp dimmed to a quarter:
 * after one update with few texels gathered, the error view shows texels still to come (not the ramp's
 * zero) and the atlas view marks texels red or surfaces yellow; once baked, the error view is dark
 * everywhere and the atlas view marks no texel red. */
static void test_iim_error_and_atlas_views(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = room();
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    lmt_updates(u, 2);
    lmgi_camera cam;
    lmt_corner_camera(&cam);
    int w = LMT_SIDE, h = LMT_SIDE;
    float *rgb = malloc(3 * sizeof *rgb * (size_t)w * (size_t)h);
    lm_view_maps m;
    memset(&m, 0, sizeof m);
    lmgi_error e;
    assert_non_null(rgb);
    assert_true(lm_view_maps_draw(&m, u, sc, LM_VIEW_IIM, &cam, w, h, rgb, &e));
    size_t n;
    float *iim = lmt_iim(u, sc, &n);
    for (int p = 0; p < w * h; p++)
        if (m.texel[p] >= 0)
            assert_memory_equal(rgb + 3 * p, iim + 4 * (size_t)m.texel[p], 3 * sizeof(float));
    free(iim);

    lmgi_light l;
    assert_int_equal(lmgi_get_light(sc, 0, &l, &e), LMGI_OK);
    l.intensity *= 0.25f;
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
    lm_view_maps_edited(&m);
    lmt_updates(u, 1);
    assert_true(lm_view_maps_draw(&m, u, sc, LM_VIEW_ERROR, &cam, w, h, rgb, &e));
    int waiting = 0;
    for (int p = 0; p < w * h; p++)
        waiting += m.texel[p] >= 0 && !dark(rgb + 3 * p);
    assert_true(lm_view_maps_draw(&m, u, sc, LM_VIEW_ATLAS, &cam, w, h, rgb, &e));
    int marked = 0;
    for (int p = 0; p < w * h; p++)
        marked += rgb[3 * p] >= 0.9f && rgb[3 * p + 2] < 0.5f * rgb[3 * p];
    print_message("the lamp dimmed, one update on: %d pixels of the error view show light still to come, %d of the "
                  "atlas view are marked\n", waiting, marked);
    assert_true(waiting > w * h / 10);
    assert_true(marked > 0);

    lmgi_bake_report r;
    lmt_bake(u, &r);
    lmt_updates(u, 60); /* the blend brought in */
    assert_true(lm_view_maps_draw(&m, u, sc, LM_VIEW_ERROR, &cam, w, h, rgb, &e));
    int left = 0;
    for (int p = 0; p < w * h; p++)
        left += m.texel[p] >= 0 && !dark(rgb + 3 * p);
    assert_true(lm_view_maps_draw(&m, u, sc, LM_VIEW_ATLAS, &cam, w, h, rgb, &e));
    int red = 0;
    for (int p = 0; p < w * h; p++)
        red += rgb[3 * p] >= 0.9f && rgb[3 * p + 1] < 0.5f * rgb[3 * p];
    print_message("baked: %d pixels of the error view still lit, %d red in the atlas view\n", left, red);
    assert_int_equal(left, 0);
    assert_int_equal(red, 0);
    lm_view_maps_free(&m);
    free(rgb);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_texels_are_where_pixels_look),
        cmocka_unit_test(test_iim_error_and_atlas_views),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
