/* Scene model and glTF loader tests: the shared scenes' counts, material classes, animation evaluation,
 * lmgi extras, world transforms, textures, and the loader's errors on bad input. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>

#include <cmocka.h>
#include <stb/stb_image_write.h>

#include "../src/core/log.h"
#include "../src/core/timing.h"
#include "../src/scene/scene.h"
#include "support.h"

#define EPS 1e-5

/* ---- helpers ---- */

static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

static void write_text(const char *dir, const char *name, const char *text, char *path_out, size_t cap)
{
    snprintf(path_out, cap, "%s/%s", dir, name);
    write_bytes(path_out, text, strlen(text));
}

static lm_scene *load_ok(const char *path, int strict)
{
    lm_scene *s = NULL;
    lm_error err;
    lm_load_options opt = {.strict = strict};
    lm_status st = lm_scene_load_gltf(path, &opt, &s, &err);
    if (st != LM_OK)
        print_error("load failed: %s\n", err.msg);
    assert_int_equal(st, LM_OK);
    assert_non_null(s);
    return s;
}

/* Loads a file that must fail with `want`; the message must name the file and contain `word`. */
static void load_fails(const char *path, int strict, lm_status want, const char *word)
{
    lm_scene *s = (lm_scene *)1;
    lm_error err;
    lm_load_options opt = {.strict = strict};
    lm_status st = lm_scene_load_gltf(path, &opt, &s, &err);
    if (st != want || !strstr(err.msg, path) || !strstr(err.msg, word))
        print_error("status %d (want %d), message: %s\n", st, want, err.msg);
    assert_int_equal(st, want);
    assert_null(s);
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, word));
}

static int count_class(const lm_scene *s, lm_material_class c)
{
    int n = 0;
    for (int i = 0; i < s->material_count; i++)
        n += s->materials[i].cls == c;
    return n;
}

static int material_named(const lm_scene *s, const char *name)
{
    for (int i = 0; i < s->material_count; i++)
        if (strcmp(s->materials[i].name, name) == 0)
            return i;
    fail_msg("no material %s", name);
    return -1;
}

/* ---- shared scenes ----
 * Expected counts were computed independently of lmgi with a Python script reading each file's JSON:
 * triangles = sum over nodes with a mesh, over that mesh's primitives, of (index accessor count, or
 * POSITION count when unindexed) / 3 for mode 4 (every primitive in these files is mode 4), so a mesh
 * used by two nodes counts twice; lights = nodes carrying KHR_lights_punctual; classes = the rule of
 * docs/materials.md applied to the JSON factors, times the mean of a metallicRoughnessTexture's B channel
 * (the chair's "wood Brown" leaves metallicFactor at its default 1; its texture says wood, not metal). */
typedef struct {
    const char *file;
    int nodes, meshes;
    uint32_t tris, back_tris; /* the file's triangles; the back sides of its open double-sided surfaces */
    int lights, materials, diffuse, glossy, emitter, textures, has_uv1;
} scene_expect;

static const scene_expect k_scenes[] = {
    /* the Cornell box's walls and lamp (its boxes are closed), the mixed-lighting floor (its sphere is
     * closed), the whole open room, the depth-of-field scene's ground; the Suzanne box is single-sided */
    {"cornell-box/CornellBox.glb", 4, 4, 36, 12, 0, 5, 4, 0, 1, 0, 1},
    {"mixed-lighting/MixedLightingExample.gltf", 7, 6, 40898, 2, 1, 8, 5, 3, 0, 4, 1},
    {"room/IrradianceVolumeExample.glb", 2, 1, 32, 32, 0, 4, 4, 0, 0, 0, 0},
    {"depth-of-field/DepthOfFieldExample.glb", 17, 16, 10610, 2, 1, 3, 1, 1, 1, 3, 1},
    {"cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf", 17, 12, 4410, 0, 0, 13, 10, 2, 1, 2, 1},
};

static void check_scene(const scene_expect *e)
{
    LMT_REQUIRE_SCENE(path, lmt_shared_scene(e->file));
    lm_scene *s = load_ok(path, 0);
    assert_int_equal(s->node_count, e->nodes);
    assert_int_equal(s->mesh_count, e->meshes);
    assert_int_equal(s->file_tri_count, e->tris);
    assert_int_equal(s->tri_count, e->tris + e->back_tris);
    assert_int_equal(s->light_count, e->lights);
    assert_int_equal(s->material_count, e->materials);
    assert_int_equal(count_class(s, LM_MAT_DIFFUSE), e->diffuse);
    assert_int_equal(count_class(s, LM_MAT_GLOSSY), e->glossy);
    assert_int_equal(count_class(s, LM_MAT_EMITTER), e->emitter);
    assert_int_equal(count_class(s, LM_MAT_MIRROR) + count_class(s, LM_MAT_GLASS), 0);
    assert_int_equal(s->texture_count, e->textures);
    assert_int_equal(s->uv1 != NULL, e->has_uv1);
    assert_string_equal(s->path, path);
    assert_true(lm_scene_size(s) > 0.0f);
    /* node triangle ranges tile the triangle array in order */
    uint32_t next = 0;
    for (int i = 0; i < s->node_count; i++) {
        assert_int_equal(s->nodes[i].first_tri, next);
        next += s->nodes[i].tri_count;
        for (uint32_t t = s->nodes[i].first_tri; t < next; t++)
            assert_int_equal(s->tri_node[t], i);
    }
    assert_int_equal(next, s->tri_count);
    for (uint32_t v = 0; v < 3 * s->tri_count; v++)
        assert_true(s->tris[v] < s->vertex_count);
    lm_scene_free(s);
}

static void test_cornell_box(void **st) { (void)st; check_scene(&k_scenes[0]); }
static void test_mixed_lighting(void **st) { (void)st; check_scene(&k_scenes[1]); }
static void test_room(void **st) { (void)st; check_scene(&k_scenes[2]); }
static void test_depth_of_field(void **st) { (void)st; check_scene(&k_scenes[3]); }
static void test_cornell_suzanne(void **st) { (void)st; check_scene(&k_scenes[4]); }

static void test_known_materials(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(cb, lmt_shared_scene("cornell-box/CornellBox.glb"));
    lm_scene *s = load_ok(cb, 0);
    const lm_material *em = &s->materials[material_named(s, "Emitter_Light_temp")];
    assert_int_equal(em->cls, LM_MAT_EMITTER);
    assert_float_equal(em->emissive[0], 100.0f, EPS); /* emissive 1 x emissive_strength 100 */
    assert_int_equal(s->materials[material_named(s, "cbox.red.002")].cls, LM_MAT_DIFFUSE);
    assert_int_equal(s->materials[material_named(s, "cbox.green.002")].cls, LM_MAT_DIFFUSE);
    lm_scene_free(s);

    LMT_REQUIRE_SCENE(dof, lmt_shared_scene("depth-of-field/DepthOfFieldExample.glb"));
    s = load_ok(dof, 0);
    const lm_material *board = &s->materials[material_named(s, "CircuitBoard")];
    assert_int_equal(board->cls, LM_MAT_GLOSSY);
    assert_float_equal(board->metallic, 0.8912387f, 1e-6); /* from the file JSON */
    assert_float_equal(board->roughness, 0.1540785f, 1e-6);
    assert_int_equal(s->materials[material_named(s, "Lava")].cls, LM_MAT_EMITTER);
    assert_int_equal(s->lights[0].type, LM_LIGHT_DIRECTIONAL);
    lm_scene_free(s);

    LMT_REQUIRE_SCENE(cs, lmt_shared_scene("cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf"));
    s = load_ok(cs, 0);
    assert_int_equal(s->materials[material_named(s, "suzanne.000")].cls, LM_MAT_GLOSSY);
    assert_int_equal(s->materials[material_named(s, "light.000")].cls, LM_MAT_EMITTER);
    lm_scene_free(s);

    LMT_REQUIRE_SCENE(ml, lmt_shared_scene("mixed-lighting/MixedLightingExample.gltf"));
    s = load_ok(ml, 0);
    assert_int_equal(s->lights[0].type, LM_LIGHT_DIRECTIONAL);
    assert_float_equal(s->lights[0].intensity, 2049.0f, EPS);
    assert_string_equal(lm_light_type_name(s->lights[0].type), "directional");
    lm_scene_free(s);
}

static lm_material plain_material(void)
{
    lm_material m;
    memset(&m, 0, sizeof m);
    m.base_color[0] = m.base_color[1] = m.base_color[2] = m.base_color[3] = 1.0f;
    m.base_color_tex = m.emissive_tex = -1;
    m.uv_scale[0] = m.uv_scale[1] = 1.0f;
    m.roughness = 0.5f;
    m.ior = 1.5f;
    return m;
}

static void test_classify_rule(void **state)
{
    (void)state;
    lm_material m = plain_material();
    assert_int_equal(lm_material_classify(&m), LM_MAT_DIFFUSE);
    m.transmission = 1.0f, m.roughness = 0.0f; /* glass */
    assert_int_equal(lm_material_classify(&m), LM_MAT_GLASS);
    assert_int_equal(m.cls, LM_MAT_GLASS);
    m = plain_material();
    m.metallic = 1.0f, m.roughness = 0.05f; /* mirror */
    assert_int_equal(lm_material_classify(&m), LM_MAT_MIRROR);
    m.roughness = 0.1f; /* the mirror threshold is strict */
    assert_int_equal(lm_material_classify(&m), LM_MAT_GLOSSY);
    m = plain_material();
    m.roughness = 0.15f; /* smooth dielectric */
    assert_int_equal(lm_material_classify(&m), LM_MAT_GLOSSY);
    m.roughness = 0.2f;
    assert_int_equal(lm_material_classify(&m), LM_MAT_DIFFUSE);
    m.emissive[2] = 0.01f; /* any emission wins, even over glass */
    m.transmission = 1.0f;
    assert_int_equal(lm_material_classify(&m), LM_MAT_EMITTER);
    m.emissive[2] = 0.0f, m.transmission = 0.49f;
    assert_int_equal(lm_material_classify(&m), LM_MAT_DIFFUSE);
    assert_string_equal(lm_material_class_name(LM_MAT_MIRROR), "mirror");
    assert_string_equal(lm_material_class_name(LM_MAT_GLASS), "glass");
}

/* ---- a small hand-written file: animations, extras, hierarchy ---- */

/* Binary buffer layout (little-endian floats unless noted):
 *   0  times3   [0, 1, 2]
 *  12  linear translation keys (0,0,0) (2,0,0) (2,4,0)
 *  48  times2   [0, 2]
 *  56  cubic translation: key0 (in 0,0,0)(v 0,0,0)(out 3,0,0), key1 (in 0,0,6)(v 1,2,0)(out 0,0,0)
 * 128  rotation keys: identity, 90 deg about z, 180 deg about z
 * 176  triangle positions (1,0,0) (1,1,0) (1,0,1)
 * 212  indices u16 0 1 2 (+2 pad) */
static void write_anim_bin(const char *path)
{
    const float s = 0.70710678f;
    float f[53] = {0, 1, 2, 0, 0, 0, 2, 0, 0, 2, 4, 0, 0, 2, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0, 0, 6, 1, 2, 0, 0, 0, 0,
                   0, 0, 0, 1, 0, 0, s, s, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 1, 0, 1};
    unsigned char b[220];
    memcpy(b, f, sizeof f);
    uint16_t idx[4] = {0, 1, 2, 0};
    memcpy(b + 212, idx, sizeof idx);
    write_bytes(path, b, sizeof b);
}

static const char *k_anim_gltf =
    "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2,3,4,6,8]}],\n"
    "\"nodes\":[\n"
    " {\"name\":\"lin\"},{\"name\":\"step\"},{\"name\":\"cubic\"},{\"name\":\"rot\"},\n"
    " {\"name\":\"root\",\"extras\":{\"lmgi\":{\"dynamic\":true,\"caustics\":false}},\"children\":[5]},\n"
    " {\"name\":\"child\"},\n"
    " {\"name\":\"static\",\"extras\":{\"lmgi\":{\"shadows\":false,\"indirect\":false}},\"children\":[7]},\n"
    " {\"name\":\"grand\",\"extras\":{\"lmgi\":{\"indirect\":true}}},\n"
    " {\"name\":\"parent\",\"translation\":[10,0,0],\"rotation\":[0,0,0.70710678,0.70710678],\"children\":[9]},\n"
    " {\"name\":\"kid\",\"translation\":[1,0,0],\"mesh\":0,\"children\":[10]},\n"
    " {\"name\":\"matrix\",\"matrix\":[2,0,0,0, 0,2,0,0, 0,0,2,0, 0,0,3,1],\"mesh\":0}],\n"
    "\"meshes\":[{\"name\":\"tri\",\"primitives\":[{\"attributes\":{\"POSITION\":5},\"indices\":6}]}],\n"
    "\"animations\":[{\"name\":\"a\",\"samplers\":[\n"
    "  {\"input\":0,\"output\":1},{\"input\":0,\"output\":1,\"interpolation\":\"STEP\"},\n"
    "  {\"input\":2,\"output\":3,\"interpolation\":\"CUBICSPLINE\"},{\"input\":0,\"output\":4}],\n"
    " \"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}},\n"
    "  {\"sampler\":1,\"target\":{\"node\":1,\"path\":\"translation\"}},\n"
    "  {\"sampler\":2,\"target\":{\"node\":2,\"path\":\"translation\"}},\n"
    "  {\"sampler\":3,\"target\":{\"node\":3,\"path\":\"rotation\"}},\n"
    "  {\"sampler\":0,\"target\":{\"node\":0,\"path\":\"weights\"}}]}],\n"
    "\"buffers\":[{\"uri\":\"anim.bin\",\"byteLength\":220}],\n"
    "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":212},{\"buffer\":0,\"byteOffset\":212,\"byteLength\":6}],\n"
    "\"accessors\":[\n"
    " {\"bufferView\":0,\"byteOffset\":0,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\"},\n"
    " {\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},\n"
    " {\"bufferView\":0,\"byteOffset\":48,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"},\n"
    " {\"bufferView\":0,\"byteOffset\":56,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"},\n"
    " {\"bufferView\":0,\"byteOffset\":128,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},\n"
    " {\"bufferView\":0,\"byteOffset\":176,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},\n"
    " {\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}\n";

static lm_scene *load_anim_scene(void)
{
    const char *dir = lmt_tmpdir();
    char bin[512], path[512];
    snprintf(bin, sizeof bin, "%s/anim.bin", dir);
    write_anim_bin(bin);
    write_text(dir, "anim.gltf", k_anim_gltf, path, sizeof path);
    return load_ok(path, 0);
}

static void assert_vec3(const float *v, float x, float y, float z)
{
    assert_float_equal(v[0], x, EPS);
    assert_float_equal(v[1], y, EPS);
    assert_float_equal(v[2], z, EPS);
}

static void test_animation_eval(void **state)
{
    (void)state;
    int w0 = lm_log_warning_count();
    lm_scene *s = load_anim_scene();
    assert_true(lm_log_warning_count() > w0); /* the weights channel was warned about */
    assert_int_equal(s->animation_count, 1);
    assert_int_equal(s->animations[0].channel_count, 4);
    assert_float_equal(lm_scene_animation_duration(s), 2.0f, EPS);

    lm_scene_eval_animation(s, 0, 0.5f);
    assert_vec3(s->nodes[0].translation, 1, 0, 0);            /* linear: halfway to (2,0,0) */
    assert_vec3(s->nodes[1].translation, 0, 0, 0);            /* step holds key 0 */
    assert_vec3(s->nodes[2].translation, 1.0f, 0.3125f, -0.5625f); /* Hermite at u = 1/4, dt = 2 */
    const float *q = s->nodes[3].rotation;                     /* slerp: 45 degrees about z */
    assert_float_equal(q[0], 0, EPS);
    assert_float_equal(q[1], 0, EPS);
    assert_float_equal(q[2], 0.38268343f, EPS);
    assert_float_equal(q[3], 0.92387953f, EPS);

    lm_scene_eval_animation(s, 0, 1.5f);
    assert_vec3(s->nodes[0].translation, 2, 2, 0);
    assert_vec3(s->nodes[1].translation, 2, 0, 0);
    lm_scene_eval_animation(s, -1, 1.0f);
    assert_vec3(s->nodes[1].translation, 2, 0, 0); /* step switches exactly at the key */
    assert_vec3(s->nodes[2].translation, 1.25f, 1.0f, -1.5f); /* u = 1/2 */
    assert_float_equal(s->nodes[3].rotation[2], 0.70710678f, EPS);

    lm_scene_eval_animation(s, 0, -3.0f); /* clamped to the start */
    assert_vec3(s->nodes[0].translation, 0, 0, 0);
    assert_vec3(s->nodes[2].translation, 0, 0, 0);
    lm_scene_eval_animation(s, 0, 7.0f); /* clamped to the end */
    assert_vec3(s->nodes[0].translation, 2, 4, 0);
    assert_vec3(s->nodes[1].translation, 2, 4, 0);
    assert_vec3(s->nodes[2].translation, 1, 2, 0);
    assert_float_equal(s->nodes[3].rotation[2], 1.0f, EPS);
    /* the world matrix follows: node 0 is a root, so its world translation is its translation */
    assert_vec3(s->nodes[0].world + 12, 2, 4, 0);
    lm_scene_free(s);
}

static void test_extras(void **state)
{
    (void)state;
    lm_scene *s = load_anim_scene();
    const lm_node *n = s->nodes;
    /* animated nodes are dynamic; the others only if their extras say so or a parent is dynamic */
    for (int i = 0; i < 4; i++)
        assert_int_equal(n[i].dynamic, 1);
    assert_int_equal(n[4].dynamic, 1);
    assert_int_equal(n[4].settings.caustics, 0);
    assert_int_equal(n[4].settings.indirect, 1);
    assert_int_equal(n[5].dynamic, 1);         /* child of a dynamic node */
    assert_int_equal(n[5].settings.dynamic, 1);
    assert_int_equal(n[5].settings.caustics, 0); /* inherited */
    assert_int_equal(n[5].settings.shadows, 1);
    assert_int_equal(n[6].dynamic, 0);
    assert_int_equal(n[6].settings.shadows, 0);
    assert_int_equal(n[6].settings.indirect, 0);
    assert_int_equal(n[7].settings.shadows, 0);  /* inherited */
    assert_int_equal(n[7].settings.indirect, 1); /* own setting wins */
    assert_int_equal(n[7].settings.caustics, 1); /* default on */
    assert_int_equal(n[8].dynamic, 0);
    lm_scene_free(s);
}

static void test_world_transforms(void **state)
{
    (void)state;
    lm_scene *s = load_anim_scene();
    /* parent: T(10,0,0) R(90 deg about z); kid: T(1,0,0) -> kid origin at (10,1,0) */
    assert_int_equal(s->nodes[9].parent, 8);
    assert_vec3(s->nodes[9].world + 12, 10, 1, 0);
    /* the mesh is used by two nodes: each gets its own copy, contiguous */
    assert_int_equal(s->tri_count, 2);
    assert_int_equal(s->nodes[9].tri_count, 1);
    assert_int_equal(s->nodes[10].tri_count, 1);
    assert_int_equal(s->nodes[10].first_tri, 1);
    float p[3];
    lm_scene_vertex_world(s, s->tris[0], p); /* local (1,0,0) in kid -> rotated (0,2,0) + (10,0,0) */
    assert_vec3(p, 10, 2, 0);
    /* node 10: matrix scale 2, translation z 3, below kid */
    lm_scene_vertex_world(s, s->tris[3], p); /* local (1,0,0) -> (2,0,3) in kid -> (3,0,3) -> (10,3,3) */
    assert_vec3(p, 10, 3, 3);
    assert_float_equal(s->nodes[10].scale[0], 2.0f, EPS); /* matrix decomposed into TRS */
    assert_float_equal(s->nodes[10].translation[2], 3.0f, EPS);
    /* generated normals: the triangle (1,0,0) (1,1,0) (1,0,1) faces +x locally -> +y in the world */
    float nw[3];
    lm_scene_normal_world(s, s->tris[0], nw);
    assert_vec3(nw, 0, 1, 0);
    assert_float_equal(lm_scene_tri_area_world(s, 0), 0.5f, EPS);
    assert_float_equal(lm_scene_tri_area_world(s, 1), 2.0f, EPS); /* scaled by 2 in both directions */
    /* bounds cover both copies; size is the diagonal */
    assert_vec3(s->bounds_min, 8, 2, 0);
    assert_vec3(s->bounds_max, 10, 3, 5);
    assert_float_equal(lm_scene_size(s), sqrtf(4 + 1 + 25), EPS);
    /* moving the parent moves everything below */
    s->nodes[8].translation[0] = 0.0f;
    lm_scene_update_world(s);
    lm_scene_update_bounds(s);
    assert_vec3(s->nodes[9].world + 12, 0, 1, 0);
    assert_float_equal(s->bounds_min[0], -2.0f, EPS);
    /* the primitive had no material: a default grey diffuse one was appended */
    assert_int_equal(s->material_count, 1);
    assert_int_equal(s->tri_material[0], 0);
    assert_float_equal(s->materials[0].base_color[1], 0.8f, EPS);
    assert_int_equal(s->materials[0].cls, LM_MAT_DIFFUSE);
    lm_scene_free(s);
}

/* ---- a triangle file with variants for the error cases ---- */

/* tri bin: indices u16 at 0 (6 bytes + 2 pad), positions at 8 (36 bytes) */
static void write_tri_bin(const char *path, const float pos[9], const uint16_t idx[3])
{
    unsigned char b[44] = {0};
    memcpy(b, idx, 6);
    memcpy(b + 8, pos, 36);
    write_bytes(path, b, sizeof b);
}

static const float k_tri_pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
static const uint16_t k_tri_idx[3] = {0, 1, 2};

typedef struct {
    const char *ext;       /* extensionsUsed / extensionsRequired block, ending in a comma, or "" */
    int mode;
    const char *uri;
    int pos_view_len;
    int pos_count;
    const char *material;  /* materials block or "" */
} tri_opts;

static void write_tri_gltf(const char *path, const tri_opts *o)
{
    char json[4096];
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},%s%s\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
             "\"nodes\":[{\"name\":\"tri\",\"mesh\":0}],"
             "\"meshes\":[{\"name\":\"trimesh\",\"primitives\":[{\"attributes\":{\"POSITION\":1},\"indices\":0,"
             "\"mode\":%d%s}]}],"
             "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":44}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":6},"
             "{\"buffer\":0,\"byteOffset\":8,\"byteLength\":%d}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"}]}",
             o->ext, o->material, o->mode, o->material[0] ? ",\"material\":0" : "", o->uri, o->pos_view_len,
             o->pos_count);
    write_bytes(path, json, strlen(json));
}

static tri_opts tri_defaults(void)
{
    tri_opts o = {"", 4, "tri.bin", 36, 3, ""};
    return o;
}

static void tri_case(const char *dir, const char *name, const tri_opts *o, char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s", dir, name);
    write_tri_gltf(path, o);
}

/* A fresh directory holding tri.bin (the one-triangle buffer), with warnings silenced. */
static const char *tri_setup(void)
{
    lm_log_set_level(LM_LOG_ERROR);
    const char *dir = lmt_tmpdir();
    char bin[512];
    snprintf(bin, sizeof bin, "%s/tri.bin", dir);
    write_tri_bin(bin, k_tri_pos, k_tri_idx);
    return dir;
}

static void test_bad_input(void **state)
{
    (void)state;
    const char *dir = tri_setup();
    char p[512], bin[512];
    tri_opts o = tri_defaults();

    tri_case(dir, "good.gltf", &o, p, sizeof p);
    lm_scene *s = load_ok(p, 1);
    assert_int_equal(s->tri_count, 1);
    lm_scene_free(s);

    snprintf(p, sizeof p, "%s/missing.gltf", dir);
    load_fails(p, 0, LM_ERR_IO, "missing.gltf");

    write_text(dir, "bad-json.gltf", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"name\":", p, sizeof p);
    load_fails(p, 0, LM_ERR_FORMAT, "bad-json.gltf");

    o = tri_defaults();
    o.pos_count = 100; /* 1200 bytes of positions in a 36-byte bufferView */
    tri_case(dir, "accessor.gltf", &o, p, sizeof p);
    load_fails(p, 0, LM_ERR_FORMAT, "accessor");

    o = tri_defaults();
    o.pos_view_len = 4000; /* bufferView past the end of the 44-byte buffer */
    tri_case(dir, "bufferview.gltf", &o, p, sizeof p);
    load_fails(p, 0, LM_ERR_FORMAT, "bufferView");

    static const uint16_t bad_idx[3] = {0, 1, 7};
    snprintf(bin, sizeof bin, "%s/badidx.bin", dir);
    write_tri_bin(bin, k_tri_pos, bad_idx);
    o = tri_defaults();
    o.uri = "badidx.bin";
    tri_case(dir, "index.gltf", &o, p, sizeof p);
    load_fails(p, 0, LM_ERR_FORMAT, "index 7");

    float nan_pos[9];
    memcpy(nan_pos, k_tri_pos, sizeof nan_pos);
    nan_pos[4] = NAN;
    nan_pos[6] = INFINITY;
    snprintf(bin, sizeof bin, "%s/nan.bin", dir);
    write_tri_bin(bin, nan_pos, k_tri_idx);
    o.uri = "nan.bin";
    tri_case(dir, "nan.gltf", &o, p, sizeof p);
    load_fails(p, 0, LM_ERR_INVALID, "non-finite");

    o = tri_defaults();
    /* a required extension lmgi does not read (KTX2 textures); Draco, once the example here, is decoded now */
    o.ext = "\"extensionsUsed\":[\"KHR_texture_basisu\"],\"extensionsRequired\":[\"KHR_texture_basisu\"],";
    tri_case(dir, "required.gltf", &o, p, sizeof p);
    load_fails(p, 0, LM_ERR_UNSUPPORTED, "KHR_texture_basisu");

    o.ext = "\"extensionsUsed\":[\"KHR_materials_sheen\",\"KHR_materials_variants\",\"KHR_lights_punctual\"],"
            "\"extensionsRequired\":[\"KHR_lights_punctual\"],";
    tri_case(dir, "optional.gltf", &o, p, sizeof p);
    s = load_ok(p, 1);
    lm_scene_free(s);

    static const float degenerate[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
    snprintf(bin, sizeof bin, "%s/degen.bin", dir);
    write_tri_bin(bin, degenerate, k_tri_idx);
    o = tri_defaults();
    o.uri = "degen.bin";
    tri_case(dir, "degenerate.gltf", &o, p, sizeof p);
    s = load_ok(p, 0); /* kept when not strict: the charts stage drops them */
    assert_int_equal(s->tri_count, 1);
    lm_scene_free(s);
    load_fails(p, 1, LM_ERR_INVALID, "trimesh");

    write_text(dir, "cycle.gltf",
               "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"name\":\"a\",\"children\":[1]},{\"name\":\"b\",\"children\":[0]}]}",
               p, sizeof p);
    load_fails(p, 0, LM_ERR_FORMAT, "cycle");

    write_text(dir, "self.gltf", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"name\":\"a\",\"children\":[0]}]}", p,
               sizeof p);
    load_fails(p, 0, LM_ERR_FORMAT, "self.gltf");

    LMT_REQUIRE_SCENE(cb, lmt_shared_scene("cornell-box/CornellBox.glb"));
    FILE *f = fopen(cb, "rb");
    assert_non_null(f);
    unsigned char glb[20000];
    size_t n = fread(glb, 1, sizeof glb, f);
    fclose(f);
    snprintf(p, sizeof p, "%s/truncated.glb", dir);
    write_bytes(p, glb, n / 2);
    load_fails(p, 0, LM_ERR_FORMAT, "truncated");
    write_bytes(p, glb, 12);
    load_fails(p, 0, LM_ERR_FORMAT, "truncated");
    lm_log_set_level(LM_LOG_WARN);
}

/* Inputs that once gave an unclear message or none (issue 16): each is now an error naming what is wrong. */
static void test_clear_errors(void **state)
{
    (void)state;
    const char *dir = tri_setup();
    char p[512];
    tri_opts o = tri_defaults();

    /* a buffer of byteLength 0 gave tinygltf's "vector::_M_range_check" */
    static const char *empty_buffer =
        "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"name\":\"geometry\",\"uri\":\"tri.bin\",\"byteLength\":0}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":6}]}";
    write_text(dir, "zero-buffer.gltf", empty_buffer, p, sizeof p);
    load_fails(p, 0, LM_ERR_FORMAT, "buffer 0 (\"geometry\"): byteLength 0");

    /* a light of colour 1e38 overflowed its photon power to infinity and failed only in 'run' */
    static const char *bright =
        "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
        "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"name\":\"sun\",\"type\":\"point\","
        "\"color\":[1e38,1,1]}]}},\"nodes\":[{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}]}";
    write_text(dir, "bright.gltf", bright, p, sizeof p);
    load_fails(p, 0, LM_ERR_INVALID, "light 0 (\"sun\"): colour 1e+38 must be in [0, 1000]");

    o.ext = "\"extensionsUsed\":[\"KHR_materials_emissive_strength\"],";
    o.material = "\"materials\":[{\"name\":\"lava\",\"emissiveFactor\":[1,1,1],\"extensions\":"
                 "{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":1e30}}}],";
    tri_case(dir, "emission.gltf", &o, p, sizeof p);
    load_fails(p, 0, LM_ERR_INVALID, "material 0 (\"lava\"): emission 1e+30");

    /* a texture coordinate of 3e38 (finite) overflowed when interpolated: the frame had a NaN pixel */
    float uv_pos[9] = {0, 3e38f, 0, 1, 0, 0, 0, 1, 0};
    char bin[600];
    snprintf(bin, sizeof bin, "%s/uv.bin", dir);
    write_tri_bin(bin, uv_pos, k_tri_idx);
    static const char *huge_uv =
        "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":"
        "{\"POSITION\":1,\"TEXCOORD_0\":2},\"indices\":0}]}],\"buffers\":[{\"uri\":\"uv.bin\",\"byteLength\":44}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":6},{\"buffer\":0,\"byteOffset\":8,\"byteLength\":36}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"},"
        "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
        "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}]}";
    write_text(dir, "huge-uv.gltf", huge_uv, p, sizeof p);
    load_fails(p, 0, LM_ERR_INVALID, "TEXCOORD_0 value 3e+38");

    /* a directory read as "read error"; a device would be read forever */
    snprintf(p, sizeof p, "%s/scene.gltf", dir);
    assert_int_equal(mkdir(p, 0777), 0);
    load_fails(p, 0, LM_ERR_IO, "is a directory");
    if (access("/dev/zero", R_OK) == 0)
        load_fails("/dev/zero", 0, LM_ERR_FORMAT, "device or pipe");
    lm_log_set_level(LM_LOG_WARN);
}

static void test_non_triangle_modes(void **state)
{
    (void)state;
    const char *dir = tri_setup();
    char p[512];
    tri_opts o = tri_defaults();
    o.mode = 1; /* lines: warned and skipped */
    tri_case(dir, "lines.gltf", &o, p, sizeof p);
    int w0 = lm_log_warning_count();
    lm_scene *s = load_ok(p, 0);
    assert_int_equal(lm_log_warning_count(), w0 + 1);
    assert_int_equal(s->tri_count, 0);
    assert_int_equal(s->node_count, 1);
    lm_scene_free(s);
    o.mode = 6; /* a fan of 3 indices is one triangle */
    tri_case(dir, "fan.gltf", &o, p, sizeof p);
    s = load_ok(p, 0);
    assert_int_equal(s->tri_count, 1);
    lm_scene_free(s);
    lm_log_set_level(LM_LOG_WARN);
}

/* Embedded (data: URI) buffer, an external PNG base colour texture with KHR_texture_transform,
 * emissive strength, transmission and ior, and a spot light. */
static void test_material_and_texture(void **state)
{
    (void)state;
    const char *dir = lmt_tmpdir();
    char path[512], png[512], b64[128], json[4096];
    /* 2x1 texture: left texel sRGB 188 (linear ~0.5), right texel sRGB 255 */
    unsigned char px[8] = {188, 188, 188, 255, 255, 255, 255, 255};
    snprintf(png, sizeof png, "%s/tex.png", dir);
    assert_true(stbi_write_png(png, 2, 1, 4, px, 8) != 0);
    unsigned char b[44] = {0};
    memcpy(b, k_tri_idx, 6);
    memcpy(b + 8, k_tri_pos, 36);
    lmt_base64(b, sizeof b, b64);
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},"
             "\"extensionsUsed\":[\"KHR_texture_transform\",\"KHR_materials_emissive_strength\","
             "\"KHR_materials_transmission\",\"KHR_materials_ior\",\"KHR_lights_punctual\"],"
             "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"name\":\"spot\",\"type\":\"spot\",\"intensity\":5,"
             "\"color\":[1,0.5,0.25],\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.5}}]}},"
             "\"nodes\":[{\"name\":\"tri\",\"mesh\":0},{\"name\":\"lamp\",\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
             "\"meshes\":[{\"name\":\"m\",\"primitives\":[{\"attributes\":{\"POSITION\":1},\"indices\":0,\"material\":0},"
             "{\"attributes\":{\"POSITION\":1},\"indices\":0,\"material\":1}]}],"
             "\"materials\":[{\"name\":\"textured\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0.5,1,1],"
             "\"baseColorTexture\":{\"index\":0,\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0.5,0],"
             "\"scale\":[2,1],\"rotation\":0}}}}},"
             "{\"name\":\"glass\",\"emissiveFactor\":[0,0,0],\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0},"
             "\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},\"KHR_materials_ior\":{\"ior\":1.33}}},"
             "{\"name\":\"lamp\",\"emissiveFactor\":[1,0.5,0],\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4}}}],"
             "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"tex.png\"}],"
             "\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,%s\",\"byteLength\":44}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":6},{\"buffer\":0,\"byteOffset\":8,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}",
             b64);
    write_text(dir, "mat.gltf", json, path, sizeof path);
    lm_scene *s = load_ok(path, 0);
    assert_int_equal(s->tri_count, 2);
    assert_int_equal(s->material_count, 3);
    assert_int_equal(s->texture_count, 1);
    const lm_texture *t = &s->textures[0];
    assert_int_equal(t->width, 2);
    assert_float_equal(t->rgba[0], 0.50289f, 1e-4); /* sRGB 188 -> linear */
    assert_float_equal(t->rgba[4], 1.0f, EPS);
    const lm_material *m = &s->materials[0];
    assert_float_equal(m->uv_offset[0], 0.5f, EPS);
    assert_float_equal(m->uv_scale[0], 2.0f, EPS);
    float a[3];
    /* u' = 2 * 0.125 + 0.5 = 0.75: the right texel's centre */
    lm_material_albedo(s, m, 0.125f, 0.5f, a);
    assert_float_equal(a[0], 1.0f, 1e-4);
    assert_float_equal(a[1], 0.5f, 1e-4); /* times the factor */
    /* u = -0.125 -> u' = 0.25: left texel centre */
    lm_material_albedo(s, m, -0.125f, 0.5f, a);
    assert_float_equal(a[0], 0.50289f, 1e-4);
    /* halfway between texel centres (u' = 0.5) blends, and repeat wraps u' = 1.5 to the same point */
    float mid[3], wrapped[3];
    lm_material_albedo(s, m, 0.0f, 0.5f, mid);
    lm_material_albedo(s, m, 0.5f, 0.5f, wrapped);
    assert_float_equal(mid[0], 0.5f * (0.50289f + 1.0f), 1e-4);
    assert_float_equal(wrapped[0], mid[0], 1e-4);
    assert_int_equal(s->materials[1].cls, LM_MAT_GLASS);
    assert_float_equal(s->materials[1].ior, 1.33f, EPS);
    assert_int_equal(s->materials[2].cls, LM_MAT_EMITTER);
    assert_vec3(s->materials[2].emissive, 4, 2, 0);
    assert_int_equal(s->light_count, 1);
    assert_int_equal(s->lights[0].type, LM_LIGHT_SPOT);
    assert_int_equal(s->lights[0].node, 1);
    assert_int_equal(s->nodes[1].light, 0);
    assert_float_equal(s->lights[0].outer_cone, 0.5f, EPS);
    assert_vec3(s->lights[0].color, 1, 0.5f, 0.25f);
    lm_scene_free(s);
}

/* The KHR_texture_transform example: offset (0,1), rotation 90 deg, scale 0.5 shows the lower-left
 * quadrant of the image, so uv (1,1) lands at (0.5, 0.5) and (0,0) at (0, 1). */
static void test_texture_transform_rotation(void **state)
{
    (void)state;
    float px[4 * 4 * 4];
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++)
            for (int c = 0; c < 4; c++)
                px[(y * 4 + x) * 4 + c] = (float)(c == 0 ? x : y); /* R = column, G = row */
    lm_texture tex = {4, 4, px};
    lm_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.texture_count = 1;
    sc.textures = &tex;
    lm_material m = plain_material();
    m.base_color_tex = 0;
    m.uv_offset[1] = 1.0f, m.uv_scale[0] = m.uv_scale[1] = 0.5f, m.uv_rotation = 1.5707963f;
    float a[3];
    lm_material_albedo(&sc, &m, 0.25f, 0.25f, a); /* -> (0.125, 0.875): texel (0.5 - 0.5, 3.5 - 0.5) */
    assert_float_equal(a[0], 0.0f, 1e-4);
    assert_float_equal(a[1], 3.0f, 1e-4);
    lm_material_albedo(&sc, &m, 0.75f, 0.75f, a); /* -> (0.375, 0.625): texel (1, 2) */
    assert_float_equal(a[0], 1.0f, 1e-4);
    assert_float_equal(a[1], 2.0f, 1e-4);
}

/* A 50,000-node parent chain (issue 16: world matrices walked up each node's chain took 53 s, and the
 * recursive resolution of node settings would overflow the stack on deeper chains): loads in well under
 * a second now, the deepest node at the sum of the translations. The bound is 50x what it takes. */
static void test_deep_hierarchy(void **state)
{
    (void)state;
    enum { DEPTH = 50000 };
    lmt_mesh m;
    memset(&m, 0, sizeof m);
    lmt_mesh_quad(&m, (float[3]){0, 0, 0}, (float[3]){1, 0, 0}, (float[3]){0, 0, -1});
    size_t cap = (size_t)DEPTH * 64 + 64;
    char *nodes = malloc(cap);
    assert_non_null(nodes);
    size_t at = 0;
    at += (size_t)snprintf(nodes + at, cap - at, "[");
    for (int i = 0; i < DEPTH; i++) /* node i's child is i + 1; the last holds the mesh */
        at += (size_t)(i + 1 < DEPTH ? snprintf(nodes + at, cap - at, "{\"children\": [%d], \"translation\": [0.001, 0, 0]},", i + 1)
                                      : snprintf(nodes + at, cap - at, "{\"mesh\": 0, \"translation\": [0.001, 0, 0]}"));
    snprintf(nodes + at, cap - at, "]");
    char path[1024];
    snprintf(path, sizeof path, "%s/deep.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, &m, 1, nodes, NULL, 0, ""), 0); /* no material: the default */
    free(nodes);
    double t0 = lm_now();
    lm_scene *s = load_ok(path, 0);
    double seconds = lm_now() - t0;
    print_message("%d-node chain loaded in %.3f s; deepest node at x = %.4f (want %.4f)\n", DEPTH, seconds,
                  (double)s->nodes[DEPTH - 1].world[12], DEPTH * 0.001);
    assert_int_equal(s->node_count, DEPTH);
    assert_float_equal(s->nodes[DEPTH - 1].world[12], DEPTH * 0.001f, 0.05f);
    assert_true(seconds < 10.0);
    lm_scene_free(s);
}

/* The scene's bounds after nodes move are those of every triangle corner transformed again, to the bit,
 * though only the moved nodes' corners are (lm_scene_keep_bounds' cache): on scenes/cornell.glb, each node
 * moved in turn, then all back. */
static void test_bounds_follow_moved_nodes(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    lm_scene *s = load_ok(path, 0);
    assert_non_null(s->node_bounds); /* the loader keeps the cache */
    float *was = malloc(sizeof(float) * 16 * (size_t)s->node_count);
    assert_non_null(was);
    for (int n = 0; n < s->node_count; n++)
        memcpy(was + 16 * n, s->nodes[n].world, sizeof s->nodes[n].world);
    int moved = 0;
    for (int step = 0; step <= s->node_count; step++) {
        if (step < s->node_count && s->nodes[step].tri_count > 0) { /* node `step` moved and turned */
            float w[16];
            memcpy(w, s->nodes[step].world, sizeof w);
            w[12] += 0.5f + 0.25f * (float)step, w[13] -= 0.3f, w[0] *= 0.5f;
            assert_true(lm_scene_set_node_world(s, step, w));
            moved++;
        } else if (step == s->node_count) { /* every node back where it was */
            for (int n = 0; n < s->node_count; n++)
                memcpy(s->nodes[n].world, was + 16 * n, sizeof s->nodes[n].world);
        }
        lm_scene_update_bounds(s);
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (uint32_t t = 0; t < 3 * s->tri_count; t++) {
            float p[3];
            lm_scene_vertex_world(s, s->tris[t], p);
            for (int k = 0; k < 3; k++)
                lo[k] = fminf(lo[k], p[k]), hi[k] = fmaxf(hi[k], p[k]);
        }
        assert_memory_equal(lo, s->bounds_min, sizeof lo);
        assert_memory_equal(hi, s->bounds_max, sizeof hi);
    }
    assert_true(moved > 3);
    free(was);
    lm_scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell_box),
        cmocka_unit_test(test_mixed_lighting),
        cmocka_unit_test(test_room),
        cmocka_unit_test(test_depth_of_field),
        cmocka_unit_test(test_cornell_suzanne),
        cmocka_unit_test(test_known_materials),
        cmocka_unit_test(test_classify_rule),
        cmocka_unit_test(test_animation_eval),
        cmocka_unit_test(test_extras),
        cmocka_unit_test(test_world_transforms),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_clear_errors),
        cmocka_unit_test(test_non_triangle_modes),
        cmocka_unit_test(test_material_and_texture),
        cmocka_unit_test(test_texture_transform_rotation),
        cmocka_unit_test(test_deep_hierarchy),
        cmocka_unit_test(test_bounds_follow_moved_nodes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
