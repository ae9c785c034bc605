/* An incremental bake against a fresh one (issue 32, item 5): lmgi_bake on an updater that followed
 * edits gives the lightmap a fresh updater's bake of the edited scene gives, within float summation
 * order (the gathers run on several threads), where the edits leave the photons' plan as a fresh
 * updater's: a light edited and restored, and any sequence of material edits. A refresh under way when
 * the bake starts is done again in full (iim_schedule.h, lm_iim_sched_restart): its first texels saw AIMs
 * the bake's photons have changed since, and a light made 100 times brighter for 10 updates and then
 * restored left 180 texels of the two rooms about 67 times too bright.
 *
 * Not yet held here (issue 32): after a light's power changes or lights are added, the photons' shares
 * follow the luminance of creation, so the bake differs from a fresh one by photon noise (up to 29% a
 * texel); after lights are removed, surfaces regathered before the AIMs they see caught up can keep
 * light that is gone (lm_delta_i_widen_to_viewers' 16 texel pairs miss them); after node moves one texel
 * in 2,048 differs by 0.11% (the store's slot order after partial re-traces). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "edit_room.h"
#include "support.h"

typedef struct {
    lmgi_context *ctx;
    lmgi_scene *sc;
    size_t n; /* floats in the atlas's RGBA lightmap */
} rig;

static void rig_load(rig *r)
{
    r->ctx = lmt_context();
    r->sc = lmt_load(lmt_project_scene("two_rooms.glb"), 2000);
    lmgi_info in;
    lmgi_get_info(r->sc, &in);
    r->n = 4 * (size_t)in.atlas_width * in.atlas_height;
}

static float *bake(lmgi_updater *u, size_t n)
{
    lmgi_bake_desc d;
    memset(&d, 0, sizeof d);
    lmgi_bake_report rep;
    lmgi_error e;
    if (lmgi_bake(u, &d, &rep, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    float *iim = malloc(n * sizeof *iim);
    assert_non_null(iim);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, iim, n, &e), LMGI_OK);
    return iim;
}

static void updates(lmgi_updater *u, int n)
{
    lmgi_error e;
    for (int k = 0; k < n; k++)
        if (lmgi_update(u, 0.0f, 0.0f, NULL, &e) != LMGI_OK)
            fail_msg("%s", e.message);
}

/* The texels of the incremental bake more than 0.1% of the lightmap's mean away from the fresh bake's
 * (the valid ones; the gathers' threads sum in any order); the worst, relative to the fresh texel. */
static int compare_with_fresh(rig *r, const float *incremental, const char *what)
{
    lmgi_updater *fresh = lmt_updater(r->ctx, r->sc);
    float *want = bake(fresh, r->n);
    lmgi_updater_free(fresh);
    double mean = 0.0;
    int valid = 0;
    for (size_t i = 0; i < r->n; i += 4)
        if (want[i + 3] > 0.0f)
            mean += want[i] + want[i + 1] + want[i + 2], valid++;
    mean /= valid > 0 ? valid : 1;
    int bad = 0;
    double worst = 0.0;
    for (size_t i = 0; i < r->n; i += 4) {
        if (!(want[i + 3] > 0.0f))
            continue;
        double a = incremental[i] + incremental[i + 1] + incremental[i + 2], b = want[i] + want[i + 1] + want[i + 2];
        bad += fabs(a - b) > 1e-3 * mean;
        worst = fmax(worst, fabs(a - b) / fmax(b, 1e-3 * mean));
    }
    printf("%s: %d of %d texels differ from a fresh bake by more than 0.1%% of the mean (worst %.2g of the "
           "texel)\n", what, bad, valid, worst);
    free(want);
    return bad;
}

static void test_light_edited_and_restored(void **state)
{
    (void)state;
    rig r;
    rig_load(&r);
    lmgi_updater *u = lmt_updater(r.ctx, r.sc);
    lmgi_error e;
    lmgi_light l;
    assert_int_equal(lmgi_get_light(r.sc, 0, &l, &e), LMGI_OK);
    float was = l.intensity;
    l.intensity = 100.0f * was;
    assert_int_equal(lmgi_set_light(r.sc, 0, &l, &e), LMGI_OK);
    updates(u, 10);
    l.intensity = was;
    assert_int_equal(lmgi_set_light(r.sc, 0, &l, &e), LMGI_OK);
    float *iim = bake(u, r.n);
    lmgi_updater_free(u);
    assert_int_equal(compare_with_fresh(&r, iim, "light x100 for 10 updates, restored"), 0);
    free(iim);
    lmgi_free(r.sc);
    lmgi_context_free(r.ctx);
}

/* One material recoloured at random (xorshift state s). */
static void random_material_edit(lmgi_scene *sc, uint32_t *s)
{
    lmgi_error e;
    float k = 0.1f + (float)(lmt_xorshift(s) % 1000) / 100.0f; /* 0.1 to 10 */
    int m = (int)(lmt_xorshift(s) % (uint32_t)lmgi_material_count(sc));
    lmgi_material mat;
    assert_int_equal(lmgi_get_material(sc, m, &mat, &e), LMGI_OK);
    mat.base_color[lmt_xorshift(s) % 3] = fminf(0.05f * k + 0.05f, 1.0f);
    assert_int_equal(lmgi_set_material(sc, m, &mat, &e), LMGI_OK);
}

static void test_random_material_sequences(void **state)
{
    (void)state;
    for (uint32_t seed = 1; seed <= 3; seed++) {
        rig r;
        rig_load(&r);
        lmgi_updater *u = lmt_updater(r.ctx, r.sc);
        uint32_t s = 0x9e3779b9u * seed;
        for (int k = 0; k < 10; k++) {
            random_material_edit(r.sc, &s);
            updates(u, 1 + (int)(lmt_xorshift(&s) % 6));
        }
        float *iim = bake(u, r.n);
        lmgi_updater_free(u);
        char what[64];
        snprintf(what, sizeof what, "10 random material edits, seed %u", seed);
        assert_int_equal(compare_with_fresh(&r, iim, what), 0);
        free(iim);
        lmgi_free(r.sc);
        lmgi_context_free(r.ctx);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_light_edited_and_restored),
        cmocka_unit_test(test_random_material_sequences),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
