/* lmgi_export_gltf: the glTF copy an engine loads. Every exported triangle's TEXCOORD_1 leads to lightmap
 * texels of its own surface at its own place, the lightmap file holds what lmgi_get_lightmap gives, the
 * copy re-loads with --use-uv1 and lights the same, and bad exports are refused without writing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <cjson/cJSON.h>
#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../src/api/lmgi_scene.h"
#include "../src/core/image.h"
#include "../src/core/vecmath.h"
#include "edit_room.h"
#include "support.h"

static lmgi_scene *load(const char *path, int use_uv1)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 2000;
    o.use_file_uv1 = use_uv1;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load(path, &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return sc;
}

static lmgi_updater *bake(lmgi_context *ctx, lmgi_scene *sc)
{
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.photons.count = 20000;
    d.gather.resolution = 16;
    d.gather.rim_samples = 16;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

/* Per node (by name), the mean of the lightmap's valid texels' irradiance (R + G + B), and their count. */
static void node_means(const lmgi_scene *sc, const float *rgba, const char *name, double *mean, int *count)
{
    const lm_scene *s = sc->scene;
    int node = lmgi_find_node(sc, name);
    double sum = 0.0;
    *count = 0;
    for (uint32_t i = 0; i < sc->atlas.texel_count; i++) {
        const lm_texel *t = &sc->atlas.texels[i];
        const float *p = rgba + 4 * ((size_t)t->y * (size_t)sc->atlas.width + (size_t)t->x);
        if ((int)s->tri_node[t->tri] != node || p[3] < 0.5f)
            continue;
        sum += p[0] + p[1] + p[2];
        ++*count;
    }
    *mean = *count ? sum / *count : 0.0;
}

static float *lightmap(lmgi_updater *u, const lmgi_scene *sc)
{
    size_t n = 4 * (size_t)sc->atlas.width * (size_t)sc->atlas.height;
    float *rgba = malloc(n * sizeof *rgba);
    lmgi_error e;
    assert_non_null(rgba);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, rgba, n, &e), LMGI_OK);
    return rgba;
}

/* The lightmap page the exported document's material m samples: the P of its LMGI_lightmap image's
 * NAME_lightmap_pageP_rgbd.png. */
static int material_page(const cJSON *doc, int m)
{
    const cJSON *mat = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "materials"), m);
    const cJSON *ext = cJSON_GetObjectItem(cJSON_GetObjectItem(mat, "extensions"), "LMGI_lightmap");
    assert_non_null(ext);
    int tex = cJSON_GetObjectItem(cJSON_GetObjectItem(ext, "lightmapTexture"), "index")->valueint;
    int img = cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "textures"), tex), "source")->valueint;
    const char *uri = cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "images"), img), "uri")->valuestring;
    const char *at = strstr(uri, "_lightmap_page");
    assert_non_null(at);
    return atoi(at + strlen("_lightmap_page"));
}

/* Each re-loaded triangle's TEXCOORD_1 centroid falls on a texel of the original atlas that belongs to a
 * surface of the same node and lies on the triangle (within its size and two texels): the UVs, their v
 * direction and the node matrices all agree with the lightmap file. With several pages (doc, the copy's
 * document, not NULL) the UVs are over the page the triangle's material samples. Returns the share that
 * does. */
static double uv1_hits(const lmgi_scene *orig, const lm_scene *copy, const cJSON *doc)
{
    const lm_atlas *a = &orig->atlas;
    int hits = 0, total = 0;
    for (uint32_t t = 0; t < copy->tri_count; t++) {
        const lm_node *nd = &copy->nodes[copy->tri_node[t]];
        int on = lmgi_find_node(orig, nd->name);
        const uint32_t *v = copy->tris + 3 * t;
        float u = 0, w = 0;
        lm_vec3 c = {0, 0, 0}, p[3];
        for (int k = 0; k < 3; k++) {
            u += copy->uv1[2 * v[k]] / 3, w += copy->uv1[2 * v[k] + 1] / 3;
            const float *q = copy->positions + 3 * v[k];
            p[k] = lm_mat4_point(nd->world, lm_v3(q[0], q[1], q[2]));
            c = lm_add(c, lm_scale(p[k], 1.0f / 3));
        }
        if (u == 0.0f && w == 0.0f)
            continue; /* mirror and glass: no lightmap */
        total++;
        int r[4] = {0, 0, a->width, a->height};
        if (doc)
            assert_int_equal(lmgi_page_rect(orig, material_page(doc, copy->tri_material[t]), r), 1);
        int x = (int)(r[0] + u * r[2]), y = (int)(r[1] + w * r[3]);
        if (x < 0 || y < 0 || x >= a->width || y >= a->height)
            continue;
        int ti = a->texel_index[(size_t)y * a->width + x];
        if (ti < 0 || (int)orig->scene->tri_node[a->texels[ti].tri] != on)
            continue;
        float reach = 2.0f * a->texel_size;
        for (int k = 0; k < 3; k++)
            reach = fmaxf(reach, lm_length(lm_sub(p[k], c)) + 2.0f * a->texel_size);
        const float *tp = a->texels[ti].pos;
        hits += lm_length(lm_sub(lm_v3(tp[0], tp[1], tp[2]), c)) <= reach;
    }
    assert_true(total > 1000);
    return (double)hits / total;
}

/* The RGBD image the glTF's LMGI_lightmap names, decoded with the scale the material gives, holds the
 * lightmap within RGBD's steps (core/image.h): 0.7% of the texel's brightest channel, or of half the
 * scale where that is darker; and 99% of the valid texels are stored with d = 1. */
static void rgbd_holds_the_lightmap(const char *dir, const char *name, const float *lightmap, int w, int h)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s.gltf", dir, name);
    size_t size;
    char *json = (char *)lmt_read_file(path, &size, 1);
    json[size] = '\0';
    const char *ext = strstr(json, "\"LMGI_lightmap\":{\"lightmapTexture\":{\"index\":");
    assert_non_null(ext);
    const char *sc = strstr(ext, "\"scale\":");
    assert_non_null(sc);
    float scale = strtof(sc + strlen("\"scale\":"), NULL);
    snprintf(path, sizeof path, "%s/%s_lightmap_rgbd.png\"", dir, name);
    assert_non_null(strstr(json, strrchr(path, '/') + 1)); /* the image the document names */
    free(json);
    path[strlen(path) - 1] = '\0';
    int pw, ph;
    uint8_t *rgbd = NULL;
    lm_error le;
    assert_int_equal(lm_read_image8(path, &pw, &ph, &rgbd, &le), LM_OK);
    assert_int_equal(pw, w);
    assert_int_equal(ph, h);
    double worst = 0.0;
    int valid = 0, unit_d = 0;
    for (int p = 0; p < w * h; p++) {
        const float *e = lightmap + 4 * (size_t)p;
        if (e[3] < 0.5f)
            continue;
        float got[3], m = fmaxf(e[0], fmaxf(e[1], e[2]));
        lm_decode_rgbd(rgbd + 4 * (size_t)p, scale, got);
        for (int c = 0; c < 3; c++)
            worst = fmax(worst, fabs(got[c] - e[c]) / fmax(m, 0.5 * scale));
        valid++;
        unit_d += rgbd[4 * p + 3] == 255;
    }
    print_message("RGBD lightmap (scale %g): worst error %.4f of the texel's brightest channel, %.1f%% of %d valid "
                  "texels with d = 1\n", (double)scale, worst, 100.0 * unit_d / valid, valid);
    assert_true(worst < 0.007);
    assert_true(unit_d >= 0.985 * valid);
    free(rgbd);
}

static void test_export_and_reload(void **state)
{
    (void)state;
    const char *dir = lmt_tmpdir();
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_scene *sc = load(lmt_project_scene("cornell.glb"), 0);
    lmgi_updater *u = bake(ctx, sc);
    lmgi_export_desc d = {.name = "box"};
    assert_int_equal(lmgi_export_gltf(u, dir, &d, &e), LMGI_OK);
    char path[1200];
    snprintf(path, sizeof path, "%s/box_lightmap.png", dir);
    assert_int_equal(access(path, R_OK), 0);

    float *mine = lightmap(u, sc), *file = NULL; /* the file holds what the updater shows */
    int w, h;
    lm_error le;
    snprintf(path, sizeof path, "%s/box_lightmap.exr", dir);
    assert_int_equal(lm_read_exr(path, &w, &h, &file, &le), LM_OK);
    assert_int_equal(w, sc->atlas.width);
    assert_int_equal(h, sc->atlas.height);
    assert_memory_equal(mine, file, 4 * sizeof(float) * (size_t)w * h);
    free(file);
    rgbd_holds_the_lightmap(dir, "box", mine, w, h);

    snprintf(path, sizeof path, "%s/box.gltf", dir);
    lm_load_options lo = {.strict = 0};
    lm_scene *copy = NULL;
    assert_int_equal(lm_scene_load_gltf(path, &lo, &copy, &le), LM_OK);
    assert_int_equal(copy->tri_count, sc->scene->tri_count);
    assert_int_equal(copy->light_count, 1);
    assert_int_equal(copy->camera_count, sc->scene->camera_count);
    for (int i = 0; i < sc->scene->node_count; i++) {
        const lm_node *a = &sc->scene->nodes[i], *b = &copy->nodes[i];
        assert_string_equal(a->name, b->name);
        assert_int_equal(a->dynamic, b->dynamic); /* kept in the node's lmgi extras */
        for (int k = 0; k < 16; k++)
            assert_float_equal(a->world[k], b->world[k], 1e-6);
    }
    double share = uv1_hits(sc, copy, NULL);
    print_message("export: %.2f%% of the copy's triangles find their own texels through TEXCOORD_1\n", 100.0 * share);
    assert_true(share > 0.97);
    lm_scene_free(copy);

    /* The copy, charted from its TEXCOORD_1, lit again: each node as bright as in the original. */
    lmgi_scene *again = load(path, 1);
    lmgi_updater *u2 = bake(ctx, again);
    float *theirs = lightmap(u2, again);
    static const char *const nodes[] = {"cornell_box", "tall_block", "dynamic_cube"};
    for (int k = 0; k < 3; k++) {
        double m1, m2;
        int n1, n2;
        node_means(sc, mine, nodes[k], &m1, &n1);
        node_means(again, theirs, nodes[k], &m2, &n2);
        print_message("  %-12s mean E %.4f over %d texels, re-loaded %.4f over %d (%.2f%%)\n", nodes[k], m1, n1, m2, n2,
                      100.0 * (m2 / m1 - 1.0));
        assert_true(n1 > 20 && n2 > 20);
        assert_float_equal(m2, m1, 0.05 * m1);
    }
    free(mine);
    free(theirs);
    lmgi_updater_free(u2);
    lmgi_free(again);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A level of several pages (the Cornell box at 6,000 texels on pages of 64): each page's three images hold
 * what lmgi_get_lightmap_page gives (the EXR bit for bit), no single-page file is written, a material on
 * several pages is written once per page (copies under its name), and each re-loaded triangle's
 * TEXCOORD_1 leads, on the page its material samples, to texels of its own node at its own place. */
static void test_export_pages(void **state)
{
    (void)state;
    const char *dir = lmt_tmpdir();
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_scene *sc = lmt_paged_cornell();
    lmgi_info in;
    lmgi_get_info(sc, &in);
    lmgi_updater *u = bake(ctx, sc);
    lmgi_export_desc d = {.name = "paged"};
    assert_int_equal(lmgi_export_gltf(u, dir, &d, &e), LMGI_OK);
    size_t n = 4 * (size_t)in.page_width * in.page_height;
    float *mine = malloc(n * sizeof *mine);
    assert_non_null(mine);
    char path[1200];
    for (int p = 0; p < in.pages; p++) {
        assert_int_equal(lmgi_get_lightmap_page(u, LMGI_LIGHTMAP_IIM, p, mine, n, &e), LMGI_OK);
        float *file = NULL;
        int w, h;
        lm_error le;
        snprintf(path, sizeof path, "%s/paged_lightmap_page%d.exr", dir, p);
        assert_int_equal(lm_read_exr(path, &w, &h, &file, &le), LM_OK);
        assert_true(w == in.page_width && h == in.page_height);
        assert_memory_equal(mine, file, n * sizeof *mine);
        free(file);
        uint8_t *px = NULL;
        snprintf(path, sizeof path, "%s/paged_lightmap_page%d_rgbd.png", dir, p);
        assert_int_equal(lm_read_image8(path, &w, &h, &px, &le), LM_OK);
        assert_true(w == in.page_width && h == in.page_height);
        free(px);
        snprintf(path, sizeof path, "%s/paged_lightmap_page%d.png", dir, p);
        assert_int_equal(access(path, R_OK), 0);
    }
    free(mine);
    snprintf(path, sizeof path, "%s/paged_lightmap.exr", dir);
    assert_int_not_equal(access(path, F_OK), 0);

    snprintf(path, sizeof path, "%s/paged.gltf", dir);
    size_t size;
    char *json = (char *)lmt_read_file(path, &size, 1);
    json[size] = '\0';
    cJSON *doc = cJSON_Parse(json);
    free(json);
    assert_non_null(doc);
    int materials = cJSON_GetArraySize(cJSON_GetObjectItem(doc, "materials"));
    print_message("paged export: %d pages, %d materials written for the scene's %d\n", in.pages, materials,
                  in.materials);
    assert_true(materials > in.materials);
    for (int m = in.materials; m < materials; m++) { /* a copy: a material of the scene's on a further page */
        const char *name = cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "materials"), m), "name")->valuestring;
        int same = 0;
        for (int k = 0; k < in.materials; k++)
            same += !strcmp(name, cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "materials"), k),
                                                      "name")->valuestring);
        assert_int_equal(same, 1);
    }
    lm_load_options lo = {.strict = 0};
    lm_scene *copy = NULL;
    lm_error le;
    assert_int_equal(lm_scene_load_gltf(path, &lo, &copy, &le), LM_OK);
    assert_int_equal(copy->tri_count, sc->scene->tri_count);
    assert_int_equal(copy->material_count, materials);
    double share = uv1_hits(sc, copy, doc);
    print_message("paged export: %.2f%% of the copy's triangles find their own texels on their page\n", 100.0 * share);
    assert_true(share > 0.97);
    lm_scene_free(copy);
    cJSON_Delete(doc);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A name that is not a plain file name, or one that would replace the scene's own file, writes nothing. */
static void test_bad_exports(void **state)
{
    (void)state;
    const char *dir = lmt_tmpdir();
    char scene[1200];
    snprintf(scene, sizeof scene, "%s/room.gltf", dir); /* binary glTF under a .gltf name: read by its magic */
    size_t size = 0;
    unsigned char *bytes = lmt_read_file(lmt_project_scene("cornell.glb"), &size, 0);
    lmt_write_file(scene, bytes, size);
    free(bytes);
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_scene *sc = load(scene, 0);
    lmgi_updater *u = bake(ctx, sc);
    lmgi_export_desc d = {.name = "../up"};
    assert_int_equal(lmgi_export_gltf(u, dir, &d, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "name '../up'"));
    d.name = "room";
    d.force = 1;
    assert_int_equal(lmgi_export_gltf(u, dir, &d, &e), LMGI_ERR_IO); /* forced, and still never over the input */
    assert_non_null(strstr(e.message, "room.gltf: is this command's input"));
    assert_int_equal(lmgi_export_gltf(NULL, dir, &d, &e), LMGI_ERR_INVALID);
    assert_int_equal(lmgi_export_gltf(u, NULL, &d, &e), LMGI_ERR_INVALID);
    d.name = "copy";
    d.force = 0;
    assert_int_equal(lmgi_export_gltf(u, dir, &d, &e), LMGI_ERR_IO); /* the directory holds the user's room.gltf */
    char path[1300];
    snprintf(path, sizeof path, "%s/copy.gltf", dir);
    assert_int_not_equal(access(path, F_OK), 0);
    bytes = lmt_read_file(scene, &size, 0);
    assert_true(size > 1000); /* untouched */
    free(bytes);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* What the copy says of materials and lights is what lmgi had: emission below 1 and above it (factor and
 * KHR_materials_emissive_strength), base colours, a coloured spot light's colour, intensity and cones. */
static void test_materials_and_lights_round_trip(void **state)
{
    (void)state;
    static const float floor_pos[12] = {-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2};
    static const float dim_pos[12] = {-2, 1, -2, -1, 1, -2, -1, 2, -2, -2, 2, -2};
    static const float hot_pos[12] = {1, 1, -2, 2, 1, -2, 2, 2, -2, 1, 2, -2};
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    lmgi_mesh_desc meshes[3] = {
        {.name = "floor", .positions = floor_pos, .vertex_count = 4, .indices = idx, .triangle_count = 2, .material = 0},
        {.name = "dim", .positions = dim_pos, .vertex_count = 4, .indices = idx, .triangle_count = 2, .material = 1},
        {.name = "hot", .positions = hot_pos, .vertex_count = 4, .indices = idx, .triangle_count = 2, .material = 2}};
    lmgi_material_desc mats[3] = {{.name = "grey", .base_color = {0.6f, 0.5f, 0.4f, 1.0f}},
                                  {.name = "dim", .emissive = {0.2f, 0.1f, 0.05f}},
                                  {.name = "hot", .emissive = {5.0f, 2.5f, 1.0f}}};
    lmgi_light_desc spot = {.name = "spot", .type = LMGI_LIGHT_SPOT, .color = {1.0f, 0.5f, 0.25f}, .intensity = 7.0f,
                            .inner_cone = 0.3f, .outer_cone = 0.6f, .position = {0, 3, 0}, .direction = {0, -1, 0}};
    lmgi_scene_desc sd = {.name = "emitters", .meshes = meshes, .mesh_count = 3, .materials = mats,
                          .material_count = 3, .lights = &spot, .light_count = 1};
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 800;
    lmgi_scene *sc = NULL;
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_load_desc(&sd, &o, &sc, &e), LMGI_OK);
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater *u = bake(ctx, sc);
    /* a lamp added by an edit: a node of its own, and nothing else (it was also written into the cameras
     * and materials arrays: three errors under the Khronos validator, Blender refused the file) */
    lmgi_light lamp = {.type = LMGI_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 3.0f, .enabled = 1,
                       .position = {0.5f, 2.0f, 0.25f}, .direction = {0, -1, 0}};
    int lamp_id;
    assert_int_equal(lmgi_add_light(sc, &lamp, &lamp_id, &e), LMGI_OK);
    const char *dir = lmt_tmpdir();
    lmgi_export_desc d = {.name = "emitters"};
    assert_int_equal(lmgi_export_gltf(u, dir, &d, &e), LMGI_OK);
    char path[1200];
    snprintf(path, sizeof path, "%s/emitters.gltf", dir);
    lm_load_options lo = {.strict = 0};
    lm_scene *copy = NULL;
    lm_error le;
    assert_int_equal(lm_scene_load_gltf(path, &lo, &copy, &le), LM_OK);
    const lm_scene *s = sc->scene;
    for (int m = 0; m < s->material_count; m++) {
        const lm_material *a = &s->materials[m], *b = NULL;
        for (int k = 0; k < copy->material_count; k++)
            if (!strcmp(copy->materials[k].name, a->name))
                b = &copy->materials[k];
        assert_non_null(b);
        for (int k = 0; k < 3; k++) /* the desc's emission, through lmgi_load_desc's glTF */
            for (int c = 0; c < 3 && !strcmp(mats[k].name, a->name); c++)
                assert_float_equal(a->emissive[c], mats[k].emissive[c], 1e-6 * (1.0 + mats[k].emissive[c]));
        for (int c = 0; c < 3; c++) {
            assert_float_equal(b->emissive[c], a->emissive[c], 1e-6 * (1.0 + a->emissive[c]));
            assert_float_equal(b->base_color[c], a->base_color[c], 1e-6);
        }
        assert_int_equal(b->cls, a->cls);
    }
    assert_int_equal(copy->material_count, s->material_count);
    assert_int_equal(copy->camera_count, s->camera_count);
    assert_int_equal(copy->light_count, 2);
    float pos[3], dir3[3];
    lm_light_place(copy, &copy->lights[1], pos, dir3);
    for (int k = 0; k < 3; k++)
        assert_float_equal(pos[k] + copy->origin[k], lamp.position[k], 1e-5);
    const lm_light *la = &s->lights[0], *lb = &copy->lights[0];
    assert_int_equal(lb->type, la->type);
    assert_float_equal(lb->intensity, la->intensity, 1e-6);
    assert_float_equal(lb->outer_cone, la->outer_cone, 1e-6);
    for (int c = 0; c < 3; c++)
        assert_float_equal(lb->color[c], la->color[c], 1e-6);
    lm_scene_free(copy);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_export_and_reload),
        cmocka_unit_test(test_export_pages),
        cmocka_unit_test(test_bad_exports),
        cmocka_unit_test(test_materials_and_lights_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
