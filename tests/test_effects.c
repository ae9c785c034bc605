/* update/effects: which effects a scene calls for, and the reason given. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../src/scene/flat_reflectors.h"
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
    assert_string_equal(e.reason[LM_EFFECT_REFLECTIONS], "1 glossy material on node 'CircuitBoard'; 1 flat node: "
                        "the view mirrored in its plane");
    lm_scene_free(s);
}

/* Flat reflectors (scene/flat_reflectors.h): a mirror quad is one, and stays one with a corner lifted by a
 * tenth of the tolerance; lifted by ten times it, it is not, nor is a mirror cube, a glossy quad given a
 * reflection_box, a glass quad or a diffuse one. A two-sided glossy quad (its back copies wound the other
 * way) is one, its plane y = 0.5. */
static void test_flat_reflectors(void **state)
{
    (void)state;
    static lmt_mesh m[8];
    memset(m, 0, sizeof m);
    for (int k = 0; k < 8; k++)
        lmt_mesh_quad(&m[k], (float[3]){-1, k == 7 ? 0.5f : 0.0f, 1}, (float[3]){2, 0, 0}, (float[3]){0, 0, -2});
    float diagonal = 2.0f * sqrtf(2.0f);
    m[1].pos[1] += 0.1f * LM_FLAT_TOLERANCE * diagonal;
    m[2].pos[1] += 10.0f * LM_FLAT_TOLERANCE * diagonal;
    lmt_mesh_cube(&m[3], 0.5f);
    const char *glossy = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 1, \"roughnessFactor\": 0.3}";
    char materials[2048];
    snprintf(materials, sizeof materials, "[%s, %s, %s, %s, %s}, %s, %s, %s, \"doubleSided\": true}], %s",
             LMT_MIRROR(0.9), LMT_MIRROR(0.9), LMT_MIRROR(0.9), LMT_MIRROR(0.9), glossy, LMT_GLASS, LMT_DIFFUSE(0.5), glossy,
             LMT_LIGHTS("{\"type\": \"point\", \"intensity\": 1}"));
    const char *path = lmt_write_scene("flat_reflectors.gltf", m, 8, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"mesh\": 2}, "
                                       "{\"mesh\": 3}, {\"mesh\": 4, \"extras\": {\"lmgi\": {\"reflection_box\": "
                                       "[-2, -2, -2, 2, 2, 2]}}}, {\"mesh\": 5}, {\"mesh\": 6}, {\"mesh\": 7}]",
                                       materials);
    lm_scene *s = load(path);
    const int want[8] = {1, 1, 0, 0, 0, 0, 0, 1};
    for (int n = 0; n < 8; n++)
        assert_int_equal(lm_node_is_flat_reflector(s, n), want[n]);
    float plane[4], extent, far = lm_node_reflector_plane(s, 7, plane, &extent);
    assert_true(far >= 0.0f && far < 1e-6f && fabsf(extent - diagonal) < 1e-5f);
    assert_true(fabsf(fabsf(plane[1]) - 1.0f) < 1e-6f && fabsf(plane[3] + 0.5f * plane[1]) < 1e-6f);
    lm_effects e;
    lm_effects_decide(s, &e);
    assert_non_null(strstr(e.reason[LM_EFFECT_REFLECTIONS], "; 3 flat nodes: the view mirrored in their plane"));
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
        cmocka_unit_test(test_flat_reflectors),
        cmocka_unit_test(test_switches_turn_effects_off),
        cmocka_unit_test(test_static_scene_traces_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
