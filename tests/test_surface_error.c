/* cli/surface_error: the per-channel criterion that `lmgi check`'s summary and `make bench`'s scene table
 * report (issue 33: every surface of 100+ pixels within 5% in every channel), on a hand-made check result
 * over the generated Cornell box's materials. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cli/surface_error.h"

static void set(lmgi_check_surface *f, int material, uint32_t pixels, const double ref[3], const double frame[3])
{
    f->material = material;
    f->pixels = pixels;
    for (int k = 0; k < 3; k++) {
        f->reference_mean[k] = ref[k];
        f->frame_mean[k] = frame[k];
        f->ratio[k] = frame[k] / ref[k];
    }
}

static void test_channels(void **state)
{
    (void)state;
    lmgi_options o;
    lmgi_options_init(&o);
    lmgi_scene *sc = NULL;
    lmgi_error err;
    assert_int_equal(lmgi_load("scenes/cornell.glb", &o, &sc, &err), LMGI_OK);
    int lit = -1; /* a material that is not an emitter */
    for (int m = 0; lit < 0 && m < lmgi_material_count(sc); m++) {
        lmgi_material mat;
        assert_int_equal(lmgi_get_material(sc, m, &mat, &err), LMGI_OK);
        if (mat.cls != LMGI_MATERIAL_EMITTER)
            lit = m;
    }
    assert_true(lit >= 0);
    lmgi_check_surface s[4];
    memset(s, 0, sizeof s);
    /* R +3%, G +2%; B reads +25% of a channel at 2% of the surface's brightest: judged against 5% of it
     * (0.005 / 0.05 = 10%), so this surface is off */
    set(&s[0], lit, 150, (double[3]){1.0, 0.5, 0.02}, (double[3]){1.03, 0.51, 0.025});
    /* far off, but 99 pixels: not judged */
    set(&s[1], lit, 99, (double[3]){0.2, 0.2, 0.2}, (double[3]){0.4, 0.4, 0.4});
    /* G +12%: the furthest */
    set(&s[2], lit, 200, (double[3]){0.2, 0.2, 0.2}, (double[3]){0.2, 0.224, 0.2});
    /* within: every channel under 5%, its weak channel's 40% read against the floor (0.0004 / 0.05) */
    set(&s[3], lit, 300, (double[3]){1.0, 1.0, 0.001}, (double[3]){1.04, 0.97, 0.0014});
    lmgi_check_result c;
    memset(&c, 0, sizeof c);
    c.surface_count = 4;
    c.surfaces = s;
    lm_cli_channel_check ch;
    lm_cli_surface_channels(sc, &c, 0.05, &ch);
    assert_int_equal(ch.surfaces, 3);
    assert_int_equal(ch.within, 1);
    assert_int_equal(ch.worst_surface, 2);
    assert_int_equal(ch.worst_channel, 1);
    assert_true(fabs(ch.worst - 0.12) < 1e-9 && fabs(ch.worst_ratio - 0.12) < 1e-9);
    lm_cli_surface_channels(sc, &c, 0.15, &ch); /* a looser bound: all three within */
    assert_int_equal(ch.within, 3);
    c.surface_count = 2; /* only one judged surface, off by its weak channel against the floor */
    lm_cli_surface_channels(sc, &c, 0.05, &ch);
    assert_int_equal(ch.surfaces, 1);
    assert_int_equal(ch.within, 0);
    assert_int_equal(ch.worst_channel, 2);
    assert_true(fabs(ch.worst - 0.1) < 1e-9 && fabs(ch.worst_ratio - 0.25) < 1e-9);
    lmgi_free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_channels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
