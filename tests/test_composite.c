/* The frame's indirect texture (gpu/frame/composite.h): the display IIM premultiplied by each texel's
 * validity, and the holes filled. Two floor quads of 20 x 20 texels, each lit uniformly (E = pi and
 * 5 pi), with texels made invalid by hand: a valid texel keeps its own value at full weight; an invalid one
 * within LM_COMPOSITE_FILL_REACH (|dx| + |dy|) of a valid texel of its surface gets that surface's light
 * at a weight of 1/1024, never the other surface's where the two touch in the atlas; the centre of a hole
 * wider than that stays empty. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/gpu/frame/composite.h"
#include "../src/gpu/gl/gl_api.h"
#include "../src/gpu/gl/offscreen.h"
#include "support.h"

#define HOLE 9 /* side of the square hole in quad 0's middle: its centre lies 5 steps from a valid texel */
_Static_assert(HOLE / 2 == LM_COMPOSITE_FILL_REACH, "only the hole's centre lies beyond the fill's reach");

static float surface_e(int surface) { return surface == 0 ? (float)M_PI : 5.0f * (float)M_PI; }

static void test_holes_filled_within_their_surface(void **state)
{
    (void)state;
    lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){0, 0, 20}, (float[3]){20, 0, 0}, (float[3]){0, 0, -20});
    lmt_mesh_quad(&m[1], (float[3]){30, 0, 20}, (float[3]){20, 0, 0}, (float[3]){0, 0, -20});
    const char *path = lmt_write_scene("two_floors.gltf", m, 2, "[{\"mesh\": 0}, {\"mesh\": 1}]",
                                       "[" LMT_DIFFUSE(0.5) ", " LMT_DIFFUSE(0.5) "]");
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 1.0f);
    assert_int_equal(p.su.surface_count, 2);
    const lm_atlas *a = &p.atlas;
    const int W = a->width, H = a->height;
    int *surface = malloc(sizeof *surface * (size_t)W * H);
    float *iim = calloc(4 * (size_t)W * H, sizeof *iim);
    assert_non_null(surface);
    assert_non_null(iim);
    for (int i = 0; i < W * H; i++)
        surface[i] = -1;
    int lo[2] = {W, H}, hi[2] = {0, 0}; /* quad 0's texels' bounding box */
    for (uint32_t t = 0; t < a->texel_count; t++)
        if (a->texels[t].surface == 0) {
            const int at[2] = {a->texels[t].x, a->texels[t].y};
            for (int k = 0; k < 2; k++)
                lo[k] = at[k] < lo[k] ? at[k] : lo[k], hi[k] = at[k] > hi[k] ? at[k] : hi[k];
        }
    /* the packer leaves the charts apart: quad 0's last column is handed to surface 1, so that two
     * surfaces touch in the atlas as they may in a tight one */
    for (uint32_t t = 0; t < a->texel_count; t++)
        if (a->texels[t].surface == 0 && a->texels[t].x == hi[0])
            p.atlas.texels[t].surface = 1;
    for (uint32_t t = 0; t < a->texel_count; t++) {
        const lm_texel *x = &a->texels[t];
        surface[x->y * W + x->x] = x->surface;
        for (int c = 0; c < 3; c++)
            iim[4 * (x->y * W + x->x) + c] = surface_e(x->surface);
    }
    /* invalid (alpha over the limit): a HOLE x HOLE square in quad 0's middle, and every texel of quad 0
     * beside a texel of quad 1 in the atlas */
    const int cx = (lo[0] + hi[0]) / 2, cy = (lo[1] + hi[1]) / 2;
    int touching = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            if (surface[y * W + x] != 0)
                continue;
            int beside = 0;
            for (int d = 0; d < 4; d++) {
                int xx = x + (d == 0) - (d == 1), yy = y + (d == 2) - (d == 3);
                beside |= xx >= 0 && yy >= 0 && xx < W && yy < H && surface[yy * W + xx] == 1;
            }
            touching += beside;
            if (beside || (abs(x - cx) <= HOLE / 2 && abs(y - cy) <= HOLE / 2))
                iim[4 * (y * W + x) + 3] = 1.0f;
        }
    print_message("atlas %d x %d, quad 0's texels at (%d..%d, %d..%d), %d of them beside surface 1's\n", W, H,
                  lo[0], hi[0], lo[1], hi[1], touching);
    assert_true(hi[0] - lo[0] >= HOLE + 4 && hi[1] - lo[1] >= HOLE + 4);
    assert_true(touching >= hi[1] - lo[1]);

    GLuint tex = lm_float_texture(W, H, iim);
    lm_composite *comp = NULL;
    lm_error err;
    unsigned lit = 0;
    if (lm_composite_create(p.s, a, 0.1f, &comp, &err) != LM_OK ||
        lm_composite_indirect(comp, tex, &lit, &err) != LM_OK)
        fail_msg("%s", err.msg);
    float *out = malloc(sizeof *out * 4 * (size_t)W * H);
    assert_non_null(out);
    glBindTexture(GL_TEXTURE_2D, lit);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, out);

    int filled = 0, empty = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const float *o = out + 4 * (y * W + x);
            int s = surface[y * W + x];
            if (s < 0) { /* no texel: nothing */
                assert_true(o[3] == 0.0f);
                continue;
            }
            double want = surface_e(s) / M_PI;
            if (iim[4 * (y * W + x) + 3] == 0.0f) { /* valid: its own value, full weight */
                assert_true(fabs(o[3] - 1.0) < 1e-6);
                for (int c = 0; c < 3; c++)
                    assert_true(fabs(o[c] / o[3] - want) < 1e-5 * want);
                continue;
            }
            /* a texel of the hole lies |dx| + |dy| = 5 - max(|dx|, |dy|) from the nearest valid texels
             * around it, so only its centre is farther than the reach of 4 */
            if (s == 0 && x == cx && y == cy) {
                assert_true(o[3] == 0.0f);
                empty++;
                continue;
            }
            assert_true(fabs(o[3] - 1.0 / 1024.0) < 1e-9);
            for (int c = 0; c < 3; c++)
                assert_true(fabs(o[c] / o[3] - want) < 1e-5 * want); /* its own surface's light */
            filled++;
        }
    print_message("%d invalid texels filled, %d left empty at the hole's centre\n", filled, empty);
    assert_int_equal(empty, 1);
    assert_true(filled >= HOLE * HOLE - 1);
    free(out);
    free(iim);
    free(surface);
    glDeleteTextures(1, &tex);
    lm_composite_free(comp);
    lmt_pipeline_free(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_holes_filled_within_their_surface),
    };
    return cmocka_run_group_tests(tests, lmt_gl_setup, lmt_gl_teardown);
}
