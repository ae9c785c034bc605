/* Edits staged until one commit (update/edits.h): a light, material, sky or switch edit is checked when it
 * is made and kept aside, so it never waits for the photon work an update left running; reads see it at
 * once; the scene model takes a whole batch at the next update or lmgi_commit, with one BVH rebuild for
 * any number of dynamic switches; and the photon stage re-traces only what the commit says changed (an
 * edit that changes nothing re-traces nothing). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/api/lmgi_scene.h"
#include "edit_room.h"
#include "support.h"

static lmgi_scene *load_room(void)
{
    static const lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f,
                                         .position = {-1.2f, 2.5f, -1.0f}};
    lmt_room_spec spec = {.lights = &lamp, .light_count = 1, .stool = 1};
    return lmt_room(&spec);
}

/* Invalid photon groups re-traced by the updates until none has been for 3 of them (an edit's re-trace is
 * spread over updates, and an update's photon work is reported by the next one when it runs on past it);
 * the lights those updates scaled (changed in power alone) into *scaled (may be NULL). */
static uint32_t retraced_until_still(lmgi_updater *u, int *scaled)
{
    uint32_t sum = 0;
    if (scaled)
        *scaled = 0;
    for (int k = 0, quiet = 0; quiet < 3; k++) {
        assert_true(k < 400);
        lmgi_update_stats st;
        lmgi_error e;
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
        sum += st.groups_retraced;
        if (scaled)
            *scaled += st.lights_scaled;
        quiet = st.groups_retraced ? 0 : quiet + 1;
    }
    return sum;
}

static void test_light_edits_wait_for_nothing(void **state)
{
    (void)state;
    lmgi_scene *sc = load_room();
    lmgi_context *ctx = lmt_context();
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    assert_int_equal(retraced_until_still(u, NULL), 0); /* nothing moves, nothing edited */
    assert_true(lm_frame_loop_busy(sc->loop));   /* the last update's photon work runs on past it */
    lmgi_error e;
    lmgi_light l;
    assert_int_equal(lmgi_get_light(sc, 0, &l, &e), LMGI_OK);
    l.intensity = 8.0f;
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
    assert_true(lm_frame_loop_busy(sc->loop));               /* the edit did not wait for it */
    assert_float_equal(sc->scene->lights[0].intensity, 4.0f, 0.0); /* staged: the scene model as it was */
    lmgi_light back;
    assert_int_equal(lmgi_get_light(sc, 0, &back, &e), LMGI_OK); /* reads see the edit at once */
    assert_float_equal(back.intensity, 8.0f, 0.0);
    int scaled = 0;
    uint32_t groups = retraced_until_still(u, &scaled);
    assert_float_equal(sc->scene->lights[0].intensity, 8.0f, 0.0); /* committed by the update */
    assert_int_equal(groups, 0); /* in power alone: its photons' hits scaled, none re-traced */
    assert_int_equal(scaled, 1);
    assert_int_equal(lmgi_set_light(sc, 0, &back, &e), LMGI_OK); /* the same values: nothing changes */
    assert_int_equal(retraced_until_still(u, &scaled), 0);
    assert_int_equal(scaled, 0);
    back.enabled = 0; /* switched off: its light gone at once with its hits (a dark light emits no photon:
                       * nothing left to re-trace) */
    assert_int_equal(lmgi_set_light(sc, 0, &back, &e), LMGI_OK);
    assert_int_equal(retraced_until_still(u, &scaled), 0);
    assert_int_equal(scaled, 1);
    back.enabled = 1; /* on again: nothing to scale; every group of it traced in the edit's update (no time
                       * budget), none left for the re-trace queue */
    assert_int_equal(lmgi_set_light(sc, 0, &back, &e), LMGI_OK);
    lmgi_update_stats on_again;
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &on_again, &e), LMGI_OK);
    assert_int_equal(on_again.lights_lit, 1);
    assert_int_equal(on_again.lights_scaled, 0);
    assert_int_equal(retraced_until_still(u, &scaled), 0);
    assert_int_equal(scaled, 0);

    /* added and removed: ids and counts at once, the scene model at the commit */
    lmgi_light lamp = {.type = LMGI_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 2.0f, .enabled = 1,
                       .position = {1.0f, 2.0f, 1.0f}, .direction = {0, -1, 0}};
    int a = -1, b = -1;
    assert_int_equal(lmgi_add_light(sc, &lamp, &a, &e), LMGI_OK);
    assert_int_equal(lmgi_add_light(sc, &lamp, &b, &e), LMGI_OK);
    assert_int_equal(a, 1);
    assert_int_equal(b, 2);
    assert_int_equal(lmgi_light_count(sc), 3);
    assert_int_equal(sc->scene->light_count, 1);
    assert_int_equal(lmgi_remove_light(sc, a, &e), LMGI_OK);
    assert_true(lmgi_light_is_removed(sc, a));
    lmt_expect_invalid(lmgi_set_light(sc, a, &lamp, &e), &e, "removed");
    lmt_expect_invalid(lmgi_set_light(sc, 3, &lamp, &e), &e, "out of range");
    lmgi_effect on;
    lmgi_get_effect(sc, 0, &on); /* a read of what the scene calls for commits what is staged */
    assert_int_equal(sc->scene->light_count, 3);
    assert_true(sc->scene->lights[a].removed && !sc->scene->lights[b].removed);
    assert_true(sc->scene->lights[b].added && sc->scene->lights[b].intensity == 2.0f);
    assert_false(lm_edits_pending(&sc->edits));
    lmgi_updater_free(u);
    lmgi_context_free(ctx);
    lmgi_free(sc);
}

static void test_materials_sky_and_switches_commit_once(void **state)
{
    (void)state;
    lmgi_scene *sc = load_room();
    lm_scene *s = sc->scene;
    lmgi_error e;
    int m = -1;
    for (int k = 0; k < lmgi_material_count(sc); k++)
        if (s->materials[k].cls == LM_MAT_DIFFUSE && s->materials[k].lightmapped)
            m = k;
    assert_true(m >= 0);
    lmgi_material mat;
    assert_int_equal(lmgi_get_material(sc, m, &mat, &e), LMGI_OK);
    float was = mat.base_color[1];
    mat.base_color[1] = 0.25f * was;
    assert_int_equal(lmgi_set_material(sc, m, &mat, &e), LMGI_OK);
    lmgi_material back;
    assert_int_equal(lmgi_get_material(sc, m, &back, &e), LMGI_OK);
    assert_float_equal(back.base_color[1], 0.25f * was, 0.0);
    assert_float_equal(s->materials[m].base_color[1], was, 0.0);

    const float blue[3] = {0.1f, 0.2f, 0.9f};
    assert_int_equal(lmgi_set_environment(sc, blue, &e), LMGI_OK);
    float sky[3];
    assert_true(lmgi_get_environment(sc, sky));
    assert_float_equal(sky[2], 0.9f, 0.0);
    assert_false(s->has_sky);

    int block = lmgi_find_node(sc, "block"), stool = lmgi_find_node(sc, "stool");
    assert_true(block >= 0 && stool >= 0);
    lmgi_node_effects fx = {.shadows = 0, .indirect = 1, .reflections = 1, .caustics = 1};
    assert_int_equal(lmgi_set_node_effects(sc, block, &fx, &e), LMGI_OK);
    fx.shadows = 1, fx.indirect = 0;
    assert_int_equal(lmgi_set_node_effects(sc, stool, &fx, &e), LMGI_OK);
    lmgi_node_effects got;
    assert_int_equal(lmgi_get_node_effects(sc, block, &got, &e), LMGI_OK);
    assert_int_equal(got.shadows, 0);
    assert_int_equal(lmgi_get_node_effects(sc, stool, &got, &e), LMGI_OK);
    assert_int_equal(got.indirect, 0);
    assert_int_not_equal(s->nodes[block].settings.shadows, 0);

    /* two switches between dynamic and static: one rebuild */
    assert_false(lmgi_node_is_dynamic(sc, block));
    assert_int_equal(lmgi_set_node_dynamic(sc, block, 1, &e), LMGI_OK);
    assert_int_equal(lmgi_set_node_dynamic(sc, stool, 0, &e), LMGI_OK);
    assert_true(lmgi_node_is_dynamic(sc, block) && !lmgi_node_is_dynamic(sc, stool));
    assert_true(!s->nodes[block].dynamic && s->nodes[stool].dynamic);
    uint64_t rebuilds = lm_rt_rebuilds(sc->rt);
    uint32_t passes = s->pass_version;

    assert_int_equal(lmgi_commit(sc, &e), LMGI_OK);
    assert_true(lm_rt_rebuilds(sc->rt) == rebuilds + 1);
    assert_float_equal(s->materials[m].base_color[1], 0.25f * was, 0.0);
    assert_true(s->has_sky && s->sky[2] == 0.9f);
    assert_int_equal(s->nodes[block].settings.shadows, 0);
    assert_int_equal(s->nodes[stool].settings.indirect, 0);
    assert_true(s->nodes[block].dynamic && !s->nodes[stool].dynamic);
    assert_true(s->pass_version > passes);

    /* the change list: the material and the sky, nothing else; an edit to the same values adds nothing */
    const lm_edit_changes *ch = lm_edits_changes(&sc->edits);
    assert_int_equal(ch->materials_changed, 1);
    assert_true(ch->materials[m]);
    assert_int_equal(ch->lights_changed, 0);
    assert_true(ch->sky && ch->moved);
    lm_edits_clear_changes(&sc->edits);
    assert_int_equal(lmgi_set_material(sc, m, &back, &e), LMGI_OK);
    assert_int_equal(lmgi_set_environment(sc, blue, &e), LMGI_OK);
    assert_int_equal(lmgi_commit(sc, &e), LMGI_OK);
    assert_int_equal(ch->materials_changed, 0);
    assert_false(ch->sky);
    assert_true(lm_rt_rebuilds(sc->rt) == rebuilds + 1);

    /* refused edits stage nothing */
    back.base_color[0] = 2.0f;
    lmt_expect_invalid(lmgi_set_material(sc, m, &back, &e), &e, "base colour");
    assert_false(lm_edits_pending(&sc->edits));
    lmgi_free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_light_edits_wait_for_nothing),
        cmocka_unit_test(test_materials_sky_and_switches_commit_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
