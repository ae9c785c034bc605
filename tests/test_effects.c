/* update/effects: which effects a scene calls for, and the reason given. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <string.h>

#include "../src/update/effects.h"
#include "support.h"

static lm_scene *load(const char *path)
{
    lm_scene *s = NULL;
    lm_error err;
    lm_load_options o = {0};
    if (lm_scene_load_gltf(path, &o, &s, &err) != LM_OK)
        fail_msg("%s", err.msg);
    return s;
}

static void test_generated_cornell(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    lm_scene *s = load(path);
    lm_effects e;
    lm_effects_decide(s, &e);
    assert_true(e.on[LM_EFFECT_DIRECT]);
    assert_true(e.on[LM_EFFECT_SHADOWS]);
    assert_true(e.on[LM_EFFECT_INDIRECT]);
    assert_true(e.on[LM_EFFECT_CAUSTICS]);
    assert_string_equal(e.reason[LM_EFFECT_CAUSTICS], "1 mirror and 1 glass materials (the first on node 'mirror_sphere')");
    assert_true(e.on[LM_EFFECT_REFLECTIONS]);
    assert_string_equal(e.reason[LM_EFFECT_REFLECTIONS], "1 mirror and 1 glass materials (the first on node "
                        "'mirror_sphere')");
    assert_true(e.on[LM_EFFECT_PHOTON_UPDATES]);
    assert_non_null(strstr(e.reason[LM_EFFECT_PHOTON_UPDATES], "3 dynamic nodes"));
    lm_scene_free(s);
}

static void test_shared_cornell_box(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("cornell-box/CornellBox.glb"));
    lm_scene *s = load(path);
    lm_effects e;
    lm_effects_decide(s, &e);
    /* Lit only by its emissive ceiling quad: no punctual light, so no per-pixel direct pass. */
    assert_false(e.on[LM_EFFECT_DIRECT]);
    assert_false(e.on[LM_EFFECT_SHADOWS]);
    assert_true(e.on[LM_EFFECT_INDIRECT]);
    assert_non_null(strstr(e.reason[LM_EFFECT_INDIRECT], "1 emissive material"));
    assert_false(e.on[LM_EFFECT_CAUSTICS]);
    assert_string_equal(e.reason[LM_EFFECT_CAUSTICS], "no mirror or glass material");
    assert_false(e.on[LM_EFFECT_REFLECTIONS]);
    assert_false(e.on[LM_EFFECT_PHOTON_UPDATES]);
    lm_scene_free(s);
}

/* A glossy metal reflects (gpu/frame/reflections.h) but focuses no caustic. */
static void test_glossy_reflects(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("depth-of-field/DepthOfFieldExample.glb"));
    lm_scene *s = load(path);
    lm_effects e;
    lm_effects_decide(s, &e);
    assert_false(e.on[LM_EFFECT_CAUSTICS]);
    assert_true(e.on[LM_EFFECT_REFLECTIONS]);
    assert_string_equal(e.reason[LM_EFFECT_REFLECTIONS], "1 glossy material on node 'CircuitBoard'");
    lm_scene_free(s);
}

static void test_switches_turn_effects_off(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    lm_scene *s = load(path);
    /* Switching caustics off on every node (as extras "caustics": false would) turns the pass off. */
    for (int n = 0; n < s->node_count; n++)
        s->nodes[n].settings.caustics = 0;
    lm_effects e;
    lm_effects_decide(s, &e);
    assert_false(e.on[LM_EFFECT_CAUSTICS]);
    assert_non_null(strstr(e.reason[LM_EFFECT_CAUSTICS], "caustics switched off"));
    assert_true(e.on[LM_EFFECT_REFLECTIONS]); /* the mirror still reflects */
    /* No lights and no emitters: nothing to bounce, nothing to update. */
    s->light_count = 0;
    lm_effects_decide(s, &e);
    assert_false(e.on[LM_EFFECT_DIRECT]);
    assert_false(e.on[LM_EFFECT_INDIRECT]);
    assert_false(e.on[LM_EFFECT_PHOTON_UPDATES]);
    assert_string_equal(e.reason[LM_EFFECT_INDIRECT], "no light, no emissive material and no sky (--sky)");
    lm_scene_free(s);
}

static void test_static_scene_traces_once(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("many_rooms.glb"));
    lm_scene *s = load(path);
    lm_effects e;
    lm_effects_decide(s, &e);
    assert_true(e.on[LM_EFFECT_INDIRECT]);
    assert_false(e.on[LM_EFFECT_PHOTON_UPDATES]);
    assert_non_null(strstr(e.reason[LM_EFFECT_PHOTON_UPDATES], "nothing moves"));
    /* Half the vases have caustics switched off; the others still call for the pass. */
    assert_true(e.on[LM_EFFECT_CAUSTICS]);
    assert_non_null(strstr(e.reason[LM_EFFECT_CAUSTICS], "glass"));
    lm_scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_generated_cornell),
        cmocka_unit_test(test_shared_cornell_box),
        cmocka_unit_test(test_glossy_reflects),
        cmocka_unit_test(test_switches_turn_effects_off),
        cmocka_unit_test(test_static_scene_traces_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
