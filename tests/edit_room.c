/* The edit tests' room (edit_room.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "edit_room.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

static int all_zero(const float *v, int n)
{
    for (int i = 0; i < n; i++)
        if (v[i] != 0.0f)
            return 0;
    return 1;
}

lmgi_context *lmt_context(void)
{
    lmgi_context *ctx = NULL;
    lmgi_error e;
    if (lmgi_context_create(NULL, &ctx, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return ctx;
}

lmgi_scene *lmt_load_desc_with(const lmgi_scene_desc *d, const lmgi_options *o)
{
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load_desc(d, o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return sc;
}

static lmgi_scene *load_desc(const lmgi_scene_desc *d, int target_texels, float texel_size)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = target_texels;
    o.texel_size = texel_size;
    return lmt_load_desc_with(d, &o);
}

lmgi_scene *lmt_room(const lmt_room_spec *spec)
{
    static const float default_lo[3] = {-0.4f, 0.0f, -0.4f}, default_hi[3] = {0.4f, 1.0f, 0.4f};
    const float *lo = spec->block_lo, *hi = spec->block_hi;
    if (all_zero(lo, 3) && all_zero(hi, 3))
        lo = default_lo, hi = default_hi;
    float room_v[72], block_v[72], stool_v[72];
    uint32_t outward[36], inward[36];
    lmt_box((const float[3]){-2, 0, -2}, (const float[3]){2, 3, 2}, 1, room_v, inward);
    lmt_box(lo, hi, 0, block_v, outward);
    lmt_box((const float[3]){1.6f, 0, -1.9f}, (const float[3]){1.9f, 0.3f, -1.6f}, 0, stool_v, outward);
    lmgi_mesh_desc meshes[3] = {
        {.name = "room", .positions = room_v, .vertex_count = 24, .indices = inward, .triangle_count = 12},
        {.name = "block", .positions = block_v, .vertex_count = 24, .indices = outward, .triangle_count = 12,
         .material = 1, .dynamic = spec->block_dynamic},
        {.name = "stool", .positions = stool_v, .vertex_count = 24, .indices = outward, .triangle_count = 12,
         .dynamic = 1}};
    lmgi_material_desc mats[2] = {{.name = "plaster", .base_color = {0.7f, 0.7f, 0.7f, 1.0f}},
                                  {.name = "red", .base_color = {0.8f, 0.2f, 0.1f, 1.0f}}};
    if (spec->block)
        mats[1] = *spec->block;
    lmgi_scene_desc d = {.name = "room", .meshes = meshes, .mesh_count = spec->stool ? 3 : 2, .materials = mats,
                         .material_count = 2, .lights = spec->lights, .light_count = spec->light_count};
    return load_desc(&d, 1500, spec->texel_size);
}

void lmt_box(const float lo[3], const float hi[3], int inward, float *pos, uint32_t *idx)
{
    /* corners of each face (bit k of a corner index: the upper end along axis k), wound to look out */
    static const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int f = 0; f < 6; f++) {
        for (int c = 0; c < 4; c++)
            for (int k = 0; k < 3; k++)
                pos[3 * (4 * f + c) + k] = (faces[f][c] >> k) & 1 ? hi[k] : lo[k];
        const uint32_t q = 4 * (uint32_t)f, out[6] = {q, q + 1, q + 2, q, q + 2, q + 3};
        for (int i = 0; i < 6; i++)
            idx[6 * f + i] = inward ? out[i % 3 == 1 ? i + 1 : i % 3 == 2 ? i - 1 : i] : out[i];
    }
}

lmgi_scene *lmt_load_desc(const lmgi_scene_desc *d, int target_texels, float texel_size)
{
    return load_desc(d, target_texels, texel_size);
}

lmgi_scene *lmt_load(const char *path, int target_texels) { return lmt_load_paged(path, target_texels, 0); }

int *lmt_texel_ids(const lmgi_scene *sc)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = (size_t)in.atlas_width * (size_t)in.atlas_height;
    int *ids = malloc(sizeof *ids * (n ? n : 1));
    assert_non_null(ids);
    for (size_t i = 0; i < n; i++)
        ids[i] = -1;
    for (uint32_t i = 0; i < lmgi_texel_count(sc); i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        ids[(size_t)t.y * (size_t)in.atlas_width + (size_t)t.x] = (int)i;
    }
    return ids;
}

lmgi_scene *lmt_paged_cornell(void)
{
    lmgi_scene *sc = lmt_load_paged(lmt_project_scene("cornell.glb"), 6000, 64);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    assert_true(in.pages > 1);
    return sc;
}

lmgi_scene *lmt_load_paged(const char *path, int target_texels, int side)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = target_texels;
    if (side)
        o.max_atlas_size = side;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load(path, &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return sc;
}

uint32_t lmt_uv_sphere(float r, const float c[3], int seg, int rings, float *pos, float *nrm, uint32_t *idx,
                       uint32_t *vertices)
{
    uint32_t v = 0, t = 0;
    for (int j = 0; j <= rings; j++)
        for (int i = 0; i <= seg; i++, v++) {
            double th = M_PI * j / rings, ph = 2 * M_PI * i / seg;
            double n[3] = {sin(th) * cos(ph), cos(th), sin(th) * sin(ph)};
            for (int k = 0; k < 3; k++)
                nrm[3 * v + k] = (float)n[k], pos[3 * v + k] = c[k] + r * (float)n[k];
        }
    for (int j = 0; j < rings; j++)
        for (int i = 0; i < seg; i++) {
            uint32_t a = (uint32_t)(j * (seg + 1) + i), b = a + 1, cc = a + (uint32_t)seg + 1, d = cc + 1;
            const uint32_t q[6] = {a, b, d, a, d, cc};
            if (j > 0)
                memcpy(idx + 3 * t++, q, 3 * sizeof *q);
            if (j < rings - 1)
                memcpy(idx + 3 * t++, q + 3, 3 * sizeof *q);
        }
    *vertices = v;
    return t;
}

lmgi_updater *lmt_room_updater(lmgi_context *ctx, lmgi_scene *sc) { return lmt_room_updater_without(ctx, sc, 0); }

void lmt_room_desc(lmgi_updater_desc *d)
{
    memset(d, 0, sizeof *d);
    d->photons.per_group = 100;
    d->gather.resolution = 16;
    d->gather.rim_samples = 16;
}

lmgi_updater *lmt_room_updater_without(lmgi_context *ctx, lmgi_scene *sc, unsigned effects_off)
{
    lmgi_updater_desc d;
    lmt_room_desc(&d);
    d.effects_off = effects_off;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

float *lmt_iim(lmgi_updater *u, const lmgi_scene *sc, size_t *n)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    *n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *rgba = malloc(*n * sizeof *rgba);
    lmgi_error e;
    assert_non_null(rgba);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, rgba, *n, &e), LMGI_OK);
    return rgba;
}

void lmt_updates(lmgi_updater *u, int n)
{
    for (int k = 0; k < n; k++)
        lmt_update(u);
}

lmgi_update_stats lmt_update(lmgi_updater *u)
{
    lmgi_update_stats st;
    lmgi_error e;
    if (lmgi_update(u, 0.0f, 0.0f, &st, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return st;
}

void lmt_bake(lmgi_updater *u, lmgi_bake_report *r)
{
    lmgi_error e;
    if (lmgi_bake(u, NULL, r, &e) != LMGI_OK)
        fail_msg("%s", e.message);
}

void lmt_look_at(const float eye[3], const float at[3], float fov, lmgi_camera *cam)
{
    float f[3], l = 0.0f;
    for (int k = 0; k < 3; k++)
        f[k] = at[k] - eye[k], l += f[k] * f[k];
    for (int k = 0; k < 3; k++)
        f[k] /= sqrtf(l);
    float r[3] = {-f[2], 0.0f, f[0]}, m = sqrtf(f[0] * f[0] + f[2] * f[2]); /* f x (0, 1, 0) */
    r[0] /= m, r[2] /= m;
    float up[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    memset(cam, 0, sizeof *cam);
    for (int k = 0; k < 3; k++) {
        cam->view[4 * k] = r[k], cam->view[4 * k + 1] = up[k], cam->view[4 * k + 2] = -f[k];
        cam->view[12] -= r[k] * eye[k], cam->view[13] -= up[k] * eye[k], cam->view[14] += f[k] * eye[k];
    }
    cam->view[15] = 1.0f;
    const float n = 0.05f, fa = 30.0f, t = 1.0f / tanf(0.5f * fov);
    cam->proj[0] = cam->proj[5] = t;
    cam->proj[10] = -(fa + n) / (fa - n), cam->proj[11] = -1.0f, cam->proj[14] = -2.0f * fa * n / (fa - n);
}

void lmt_corner_camera(lmgi_camera *out)
{
    const float eye[3] = {1.9f, 2.0f, 1.9f}, at[3] = {-1.0f, 0.5f, -1.0f};
    lmt_look_at(eye, at, 0.5f * (float)M_PI, out);
}

float *lmt_corner_frame(lmgi_updater *u)
{
    lmgi_camera cam;
    lmt_corner_camera(&cam);
    float *rgb = malloc(3 * LMT_SIDE * LMT_SIDE * sizeof *rgb);
    lmgi_error e;
    assert_non_null(rgb);
    if (lmgi_render(u, &cam, LMT_SIDE, LMT_SIDE, rgb, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return rgb;
}

double lmt_relative_l1(const float *a, const float *b, size_t n)
{
    double d = 0.0, s = 0.0;
    for (size_t i = 0; i < n; i++)
        d += fabs((double)a[i] - b[i]), s += fabs((double)b[i]);
    return s > 0.0 ? d / s : d;
}

double lmt_worst_surface(const lmgi_scene *sc, const float *shown, const float *want)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    int S = in.surfaces;
    double *d = calloc(3 * (size_t)(S ? S : 1), sizeof *d), worst = 0.0;
    assert_non_null(d);
    for (uint32_t t = 0; t < lmgi_texel_count(sc); t++) {
        lmgi_texel tx;
        lmgi_get_texel(sc, t, &tx);
        size_t k = 4 * ((size_t)tx.y * in.atlas_width + tx.x);
        if (tx.surface < 0 || !(want[k + 3] > 0.0f) || !(shown[k + 3] > 0.0f))
            continue;
        for (int c = 0; c < 3; c++)
            d[3 * tx.surface] += fabs(shown[k + c] - want[k + c]), d[3 * tx.surface + 1] += fabs(want[k + c]);
        d[3 * tx.surface + 2] += 1.0;
    }
    for (int j = 0; j < S; j++)
        if (d[3 * j + 2] >= 16 && d[3 * j + 1] > 0.0)
            worst = fmax(worst, d[3 * j] / d[3 * j + 1]);
    free(d);
    return worst;
}

int lmt_worst_surface_lag(lmgi_updater *u, const lmgi_scene *sc, const float *want, int updates, double *first,
                          double *last)
{
    int within = -1;
    for (int f = 0; f < updates; f++) {
        lmt_updates(u, 1);
        size_t n;
        float *shown = lmt_iim(u, sc, &n);
        *last = lmt_worst_surface(sc, shown, want);
        *first = f ? *first : *last;
        within = *last < 0.05 ? (within < 0 ? f + 1 : within) : -1;
        free(shown);
    }
    return within;
}

void lmt_triangles_stats(const lmgi_scene *sc, const float *iim, uint32_t first, uint32_t count, double *mean,
                         double *top)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    double sum = 0.0;
    int n = 0;
    *top = 0.0;
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        const float *p = iim + 4 * ((size_t)t.y * in.atlas_width + t.x);
        if (p[3] < 0.5f || t.triangle < first || t.triangle >= first + count)
            continue;
        double e = (double)p[0] + p[1] + p[2];
        sum += e, n++;
        *top = e > *top ? e : *top;
    }
    assert_true(n > 20);
    *mean = sum / n;
}

double lmt_node_mean(const lmgi_scene *sc, const float *iim, const char *node)
{
    static const char *const names[3] = {"room", "block", "stool"}; /* 12 triangles each, in this order */
    for (uint32_t k = 0; k < 3; k++)
        if (!strcmp(names[k], node)) {
            double mean, top;
            lmt_triangles_stats(sc, iim, 12 * k, 12, &mean, &top);
            return mean;
        }
    fail_msg("no node '%s' in the room", node);
    return 0.0;
}

lmgi_updater *lmt_updater(lmgi_context *ctx, lmgi_scene *sc)
{
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

lmgi_scene *lmt_export_reload(lmgi_updater *u, const char *name, int target_texels)
{
    char dir[64], path[600];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    lmgi_export_desc d = {.name = name, .force = 1};
    lmgi_error e;
    if (lmgi_export_gltf(u, dir, &d, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    snprintf(path, sizeof path, "%s/%s.gltf", dir, name);
    return lmt_load(path, target_texels);
}

int lmt_texel_mean(const float *rgba, size_t n, double mean[3])
{
    int texels = 0;
    mean[0] = mean[1] = mean[2] = 0.0;
    for (size_t i = 0; i < n / 4; i++)
        if (rgba[4 * i + 3] > 0.0f) {
            for (int c = 0; c < 3; c++)
                mean[c] += rgba[4 * i + c];
            texels++;
        }
    assert_true(texels > 0);
    for (int c = 0; c < 3; c++)
        mean[c] /= texels;
    return texels;
}

void lmt_reference_pixels(lmgi_scene *sc, const lmgi_camera *cam, int side, float target_error, lmgi_reference *ref)
{
    lmgi_reference_desc d = {.target_error = target_error, .no_cache = 1};
    lmgi_error e;
    if (lmgi_reference_pixels(sc, &d, cam, side, side, ref, &e) != LMGI_OK)
        fail_msg("%s", e.message);
}

int lmt_reference_mean(lmgi_scene *sc, float target_error, double mean[3])
{
    lmgi_reference_desc d;
    memset(&d, 0, sizeof d);
    d.target_error = target_error;
    d.no_cache = 1;
    lmgi_reference r;
    lmgi_error e;
    if (lmgi_reference_texels(sc, &d, &r, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    int texels = 0;
    mean[0] = mean[1] = mean[2] = 0.0;
    for (int i = 0; i < r.width * r.height; i++)
        if (r.full[3 * i] != 0.0f || r.full[3 * i + 1] != 0.0f) {
            for (int c = 0; c < 3; c++)
                mean[c] += r.full[3 * i + c];
            texels++;
        }
    lmgi_reference_free(&r);
    assert_true(texels > 0);
    for (int c = 0; c < 3; c++)
        mean[c] /= texels;
    return texels;
}

void lmt_expect_invalid(lmgi_status st, const lmgi_error *e, const char *words)
{
    assert_int_equal(st, LMGI_ERR_INVALID);
    if (!strstr(e->message, words))
        fail_msg("'%s' does not name '%s'", e->message, words);
}

int lmt_light_on_node(const lmgi_scene *sc, const char *name)
{
    for (int l = 0; l < lmgi_light_count(sc); l++) {
        lmgi_light li;
        lmgi_error e;
        assert_int_equal(lmgi_get_light(sc, l, &li, &e), LMGI_OK);
        const char *node = lmgi_node_name(sc, li.node);
        if (node && !strcmp(node, name))
            return l;
    }
    fail_msg("no light on node '%s'", name);
    return -1;
}

int lmt_material_named(const lmgi_scene *sc, const char *name)
{
    for (int m = 0; m < lmgi_material_count(sc); m++)
        if (!strcmp(lmgi_material_name(sc, m), name))
            return m;
    fail_msg("no material '%s'", name);
    return -1;
}
