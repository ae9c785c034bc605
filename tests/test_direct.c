/* gpu/frame/direct: direct light per pixel with shadow maps. A point light over a plane against
 * rho/pi I cos/d^2, a box's shadow (umbra black, outside lit; also beyond each of a point light's six
 * cube faces, with PCF radius 0 and 1), a grazing directional light without
 * acne (and with acne when the bias is off), a spot light's cone falloff against lm_spot_attenuation,
 * a contact shadow, the glossy lobe against lm_bsdf_eval, the base colour texture against
 * lm_material_albedo, determinism, and the persistent lm_direct's caches (after a node, the light or
 * its power changes, it renders what a fresh one-shot render of the same state renders; with nothing
 * changed, nothing is re-rendered), and environment faces drawn from simplified triangles against the
 * full scene's. Orthographic camera looking straight down at a 4 x 4 patch of the plane, 64 x 64 pixels. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/core/vecmath.h"
#include "../src/gpu/frame/direct.h"
#include "../src/gpu/frame/direct_mesh.h"
#include "../src/gpu/gl/gl_api.h"
#include "../src/gpu/gl/gl_context.h"
#include "../src/trace/bsdf.h"
#include "../src/trace/lights.h"
#include "support.h"

#define PI 3.14159265358979323846
#define W 64
#define HALF 2.0f   /* the camera sees x, z in [-HALF, HALF] */
#define RHO 0.8     /* the default material's albedo */


/* Looking down -Y from y = 5: image x = world x, image up = world -z. */
static void top_view(lm_view *v)
{
    memset(v, 0, sizeof *v);
    lm_mat4_look_at(v->view, lm_v3(0, 5, 0), lm_v3(0, 0, 0), lm_v3(0, 0, -1));
    lm_mat4_identity(v->proj);
    v->proj[0] = v->proj[5] = 1.0f / HALF;
    v->proj[10] = -2.0f / 9.9f;
    v->proj[14] = -10.1f / 9.9f; /* near 0.1, far 10 */
    v->eye[1] = 5.0f;
}

/* World x, z of pixel (i, row r from the top). */
static void pixel_xz(int i, int r, double *x, double *z)
{
    *x = (-1.0 + (2.0 * i + 1.0) / W) * HALF;
    *z = (1.0 - (2.0 * r + 1.0) / W) * HALF * -1.0;
}

/* Changes the scene after loading (NULL: none). */
typedef void (*scene_edit)(lm_scene *s);

static float *render_edit(const char *path, const lm_direct_settings *set, scene_edit edit)
{
    lm_scene *s = NULL;
    lm_emitters em;
    lm_error err;
    lm_load_options opt = {0};
    assert_int_equal(lm_scene_load_gltf(path, &opt, &s, &err), LM_OK);
    if (edit)
        edit(s);
    assert_int_equal(lm_emitters_build(s, &em, &err), LM_OK);
    lm_emitters_update(&em, s);
    lm_view v;
    top_view(&v);
    float *rgb = malloc(sizeof(float) * 3 * W * W);
    assert_non_null(rgb);
    lm_status st = lm_render_direct(s, &em, &v, W, W, set, rgb, &err);
    if (st != LM_OK)
        fail_msg("render: %s", err.msg);
    lm_emitters_free(&em);
    lm_scene_free(s);
    return rgb;
}

static float *render_with(const char *path, const lm_direct_settings *set)
{
    return render_edit(path, set, NULL);
}

static float *render(const char *path) { return render_with(path, NULL); }

static const char *scene_box_at(const char *name, int box, float box_y, const char *light_node,
                                const char *light);
static const char *scene_plane_box(const char *name, float plane_half, int box, float box_y, const char *light_node,
                                   const char *light);

/* The plane of lmt_plane_scene, an optional box and one light (node json, light json). */
static const char *scene_with(const char *name, int box, const char *light_node, const char *light)
{
    return scene_box_at(name, box, 1.0f, light_node, light);
}

/* As scene_with, the box centred at (0.5, box_y, 0). */
static const char *scene_box_at(const char *name, int box, float box_y, const char *light_node, const char *light)
{
    return scene_plane_box(name, 10.0f, box, box_y, light_node, light);
}

/* As scene_box_at, the plane 2 plane_half wide. */
static const char *scene_plane_box(const char *name, float plane_half, int box, float box_y, const char *light_node,
                                   const char *light)
{
    static char path[512];
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    float h = plane_half;
    lmt_mesh_quad(&m[0], (float[3]){-h, 0, h}, (float[3]){2 * h, 0, 0}, (float[3]){0, 0, -2 * h});
    lmt_mesh_cube(&m[1], 0.25f);
    char nodes[1024], ext[512], box_node[128];
    snprintf(box_node, sizeof box_node, ", {\"mesh\": 1, \"translation\": [0.5, %.6f, 0]}", box_y);
    snprintf(nodes, sizeof nodes, "[{\"children\": [1, 2%s]}, {\"mesh\": 0}, %s%s]", box ? ", 3" : "", light_node,
             box ? box_node : "");
    snprintf(ext, sizeof ext,
             "\"extensionsUsed\": [\"KHR_lights_punctual\"],"
             " \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [%s]}},", light);
    snprintf(path, sizeof path, "%s/%s.gltf", lmt_tmpdir(), name);
    if (lmt_write_gltf(path, m, box ? 2 : 1, nodes, NULL, 0, ext) != 0)
        fail_msg("cannot write %s", path);
    return path;
}

static double lum(const float *p) { return (p[0] + p[1] + p[2]) / 3.0; }

static double rel(double got, double want) { return fabs(got - want) / want; }

/* (a) rho/pi I h / d^3 under a point light of I = 10 at height 2. */
static void test_point_plane(void **state)
{
    (void)state;
    float *rgb = render(lmt_plane_scene());
    double worst = 0.0, centre = 0.0;
    for (int i = W / 2; i < W; i += 3) {
        double x, z;
        pixel_xz(i, W / 2, &x, &z);
        double d2 = x * x + z * z + 4.0, want = RHO / PI * 10.0 * 2.0 / (d2 * sqrt(d2));
        double e = rel(lum(rgb + 3 * (W / 2 * W + i)), want);
        if (i == W / 2)
            centre = e;
        worst = fmax(worst, e);
    }
    print_message("point light: centre error %.2e, worst along the line %.2e\n", centre, worst);
    assert_true(centre < 0.02);
    assert_true(worst < 0.03);
    free(rgb);
}

/* KHR_lights_punctual range 3 on the same light: rho/pi I h / d^3 x clamp(1 - (d / 3)^4, 0, 1) over the
 * whole picture; the corners (d = 3.46) get no light at all. */
static void test_point_plane_range(void **state)
{
    (void)state;
    float *rgb = render(lmt_plane_scene_with("{\"type\": \"point\", \"intensity\": 10, \"range\": 3}"));
    double worst = 0.0, dark = 0.0;
    for (int r = 0; r < W; r++)
        for (int i = 0; i < W; i++) {
            double x, z;
            pixel_xz(i, r, &x, &z);
            double d2 = x * x + z * z + 4.0, q = d2 / 9.0, window = fmax(0.0, 1.0 - q * q);
            double want = RHO / PI * 10.0 * 2.0 / (d2 * sqrt(d2)) * window, got = lum(rgb + 3 * (r * W + i));
            if (window == 0.0)
                dark = fmax(dark, got);
            else if (window > 0.1)
                worst = fmax(worst, rel(got, want));
        }
    print_message("point light, range 3: worst where lit %.2e, brightest beyond the range %.2e\n", worst, dark);
    assert_true(worst < 0.03);
    assert_true(dark == 0.0);
    free(rgb);
}

/* Does the segment from plane point (x, 0, z) to the light (0, 2, 0) pass through the box centred at
 * (0.5, 1, box_z) with half-size h? (slab test) */
static int hits_box(double x, double z, double box_z, double h)
{
    double o[3] = {x, 0, z}, d[3] = {-x, 2, -z}, c[3] = {0.5, 1, box_z}, t0 = 0, t1 = 1;
    for (int k = 0; k < 3; k++) {
        if (fabs(d[k]) < 1e-12) {
            if (fabs(o[k] - c[k]) > h)
                return 0;
            continue;
        }
        double a = (c[k] - h - o[k]) / d[k], b = (c[k] + h - o[k]) / d[k];
        t0 = fmax(t0, fmin(a, b));
        t1 = fmin(t1, fmax(a, b));
    }
    return t0 <= t1;
}

static const char *box_scene(void)
{
    return scene_with("box", 1, "{\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}",
                      "{\"type\": \"point\", \"intensity\": 10}");
}

/* The umbra of box_scene's box (centred at (0.5, 1, box_z)) in a top view of the plane: the umbra
 * pixels' worst fraction of the unshadowed radiance and the lit pixels' worst error; the box's own
 * footprint (seen from above: its top) is skipped. Asserts enough of each. */
/* What a shadow test saw: pixels in the umbra and their worst against the lit value, lit pixels and their
 * worst relative error. */
typedef struct {
    int umbra, lit;
    double worst_umbra, worst_lit;
} shadow_tally;

static void tally_add(shadow_tally *t, int in_umbra, double got, double want)
{
    if (in_umbra) {
        t->umbra++;
        t->worst_umbra = fmax(t->worst_umbra, got / want);
    } else {
        t->lit++;
        t->worst_lit = fmax(t->worst_lit, rel(got, want));
    }
}

/* Enough of each, the umbra at most 1% of lit, the lit within lit_tol. */
static void tally_check(const shadow_tally *t, const char *what, int min_umbra, int min_lit, double lit_tol)
{
    print_message("%s: %d umbra pixels, worst %.2e of lit; %d lit pixels, worst error %.2e\n", what, t->umbra,
                  t->worst_umbra, t->lit, t->worst_lit);
    assert_true(t->umbra > min_umbra && t->lit > min_lit);
    assert_true(t->worst_umbra <= 0.01);
    assert_true(t->worst_lit < lit_tol);
}

static void check_box_shadow(const char *what, const float *rgb, double box_z)
{
    shadow_tally t = {0};
    for (int r = 0; r < W; r++)
        for (int i = 0; i < W; i++) {
            double x, z;
            pixel_xz(i, r, &x, &z);
            if (fabs(x - 0.5) < 0.35 && fabs(z - box_z) < 0.35)
                continue; /* the box top */
            double d2 = x * x + z * z + 4.0, want = RHO / PI * 20.0 / (d2 * sqrt(d2));
            if (hits_box(x, z, box_z, 0.2) || !hits_box(x, z, box_z, 0.3))
                tally_add(&t, hits_box(x, z, box_z, 0.2), lum(rgb + 3 * (r * W + i)), want);
        }
    tally_check(&t, what, 50, 1000, 0.03);
}

/* (b) The umbra of a box between the light and the plane. */
static void test_box_shadow(void **state)
{
    (void)state;
    float *rgb = render(box_scene());
    check_box_shadow("box shadow", rgb, 0.0);
    free(rgb);
}

/* (b') The same light, box and plane turned as a whole so that the plane lies beyond each of the point
 * light's six cube faces in turn, seen by a camera turned with them; the box is off the light's axis in
 * both directions across the face, so a face whose image were mirrored, turned or taken from another
 * tile would put the umbra elsewhere. With one bilinear tap and with PCF radius 1 (4 taps). */
static void test_box_shadow_every_face(void **state)
{
    (void)state;
    const float h = 0.70710678f; /* rotations taking local -Y (light to plane) to +X, -X, +Y, -Y, +Z, -Z */
    static const float turns[6][4] = {{0, 0, h, h}, {0, 0, -h, h}, {1, 0, 0, 0}, {0, 0, 0, 1}, {-h, 0, 0, h}, {h, 0, 0, h}};
    static const char *names[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
    const double box_z = 0.3;
    lm_load_options opt = {0};
    lm_error err;
    lm_direct_settings set;
    lm_direct_settings_default(&set);
    for (int k = 0; k < 12; k++) {
        int f = k % 6;
        set.pcf_radius = k / 6;
        lm_scene *s = NULL;
        assert_int_equal(lm_scene_load_gltf(box_scene(), &opt, &s, &err), LM_OK);
        memcpy(s->nodes[0].rotation, turns[f], sizeof turns[f]); /* the root: plane, light, box */
        s->nodes[3].translation[2] = (float)box_z;
        lm_scene_update_world(s);
        lm_scene_update_bounds(s);
        lm_emitters em;
        assert_int_equal(lm_emitters_build(s, &em, &err), LM_OK);
        lm_emitters_update(&em, s);
        lm_view v;
        top_view(&v);
        float to_local[16], eye[3] = {0, 5, 0};
        assert_true(lm_mat4_invert_affine(to_local, s->nodes[0].world));
        lm_mat4_mul(v.view, v.view, to_local);
        lm_v3_store(v.eye, lm_mat4_point(s->nodes[0].world, lm_v3_load(eye)));
        float *rgb = malloc(sizeof(float) * 3 * W * W);
        assert_non_null(rgb);
        if (lm_render_direct(s, &em, &v, W, W, &set, rgb, &err) != LM_OK)
            fail_msg("render: %s", err.msg);
        char what[64];
        snprintf(what, sizeof what, "box shadow beyond %s, PCF radius %d", names[f], set.pcf_radius);
        check_box_shadow(what, rgb, box_z);
        free(rgb);
        lm_emitters_free(&em);
        lm_scene_free(s);
    }
}

/* The plane under a directional light at 80 degrees from its normal. */
static const char *grazing_scene(void)
{
    /* Rotation about x by -10 degrees turns -Z into (0, -cos 80, -sin 80). */
    char node[256];
    snprintf(node, sizeof node,
             "{\"rotation\": [%.9f, 0, 0, %.9f], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}",
             sin(-5.0 * PI / 180.0), cos(-5.0 * PI / 180.0));
    return scene_with("grazing", 0, node, "{\"type\": \"directional\", \"intensity\": 1}");
}

static double grazing_worst(const lm_direct_settings *set)
{
    float *rgb = render_with(grazing_scene(), set);
    double want = RHO / PI * cos(80.0 * PI / 180.0), worst = 0.0;
    for (int p = 0; p < W * W; p++)
        worst = fmax(worst, rel(lum(rgb + 3 * p), want));
    free(rgb);
    return worst;
}

/* (c) Every pixel rho/pi E cos 80: no acne. Without the bias the same scene shows acne, so the test
 * can see it. */
static void test_grazing(void **state)
{
    (void)state;
    lm_direct_settings none;
    lm_direct_settings_default(&none);
    none.normal_offset = none.slope_bias = none.const_bias = 0.0f;
    double worst = grazing_worst(NULL), unbiased = grazing_worst(&none);
    print_message("grazing directional light: worst pixel error %.2e (without bias: %.3f)\n", worst, unbiased);
    assert_true(worst < 0.02);
    assert_true(unbiased > 0.1);
}

/* (f) Contact: a box resting on the plane; the plane right beside it on the side away from the light
 * (its shadow there spans x in [0.75, 1]) stays dark: the bias does not detach the shadow. */
static void test_contact(void **state)
{
    (void)state;
    float *rgb = render(scene_box_at("contact", 1, 0.25f,
                                     "{\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}",
                                     "{\"type\": \"point\", \"intensity\": 10}"));
    double worst = 0.0;
    int n = 0;
    for (int r = 0; r < W; r++)
        for (int i = 0; i < W; i++) {
            double x, z;
            pixel_xz(i, r, &x, &z);
            if (x < 0.76 || x > 0.95 || fabs(z) > 0.15)
                continue;
            double d2 = x * x + z * z + 4.0, lit = RHO / PI * 20.0 / (d2 * sqrt(d2));
            worst = fmax(worst, lum(rgb + 3 * (r * W + i)) / lit);
            n++;
        }
    print_message("contact: %d pixels within 0.01..0.2 of the box, worst %.2e of lit\n", n, worst);
    assert_true(n > 10 && worst <= 0.01);
    free(rgb);
}

/* (d) A spot light pointing down from height 2: zero outside the outer cone, rho/pi I/d^2 on the axis,
 * the glTF falloff (lm_spot_attenuation) in between. */
static void test_spot(void **state)
{
    (void)state;
    const char *node = "{\"translation\": [0, 2, 0], \"rotation\": [-0.70710678, 0, 0, 0.70710678],"
                       " \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}";
    float *rgb = render(scene_with("spot", 0, node,
                                   "{\"type\": \"spot\", \"intensity\": 10,"
                                   " \"spot\": {\"innerConeAngle\": 0.3, \"outerConeAngle\": 0.5}}"));
    lm_light l = {.type = LM_LIGHT_SPOT, .inner_cone = 0.3f, .outer_cone = 0.5f};
    double outside = 0.0, axis = 1.0, ramp = 0.0;
    int ramp_n = 0;
    for (int r = 0; r < W; r++)
        for (int i = 0; i < W; i++) {
            double x, z;
            pixel_xz(i, r, &x, &z);
            double d2 = x * x + z * z + 4.0, c = 2.0 / sqrt(d2), theta = acos(c);
            double want = RHO / PI * 10.0 * c / d2 * lm_spot_attenuation(&l, (float)c);
            double got = lum(rgb + 3 * (r * W + i));
            if (theta > 0.51)
                outside = fmax(outside, got);
            else if (theta < 0.03)
                axis = fmin(axis, rel(got, RHO / PI * 10.0 / d2) < 0.02 ? 0.0 : 1.0);
            else if (theta > 0.32 && theta < 0.48) {
                ramp = fmax(ramp, rel(got, want));
                ramp_n++;
            }
        }
    print_message("spot: max outside %.3g, axis %s, %d ramp pixels worst error %.2e\n", outside,
                  axis == 0.0 ? "within 2%" : "off", ramp_n, ramp);
    assert_true(outside == 0.0);
    assert_true(axis == 0.0);
    assert_true(ramp_n > 50 && ramp < 0.03);
    free(rgb);
}

#define GLOSSY_BASE {0.9f, 0.6f, 0.3f, 1.0f}

/* The plane's material becomes a rough metal: glossy, Phong exponent 30. */
static void make_glossy(lm_scene *s)
{
    lm_material *m = &s->materials[s->tri_material[0]];
    const float base[4] = GLOSSY_BASE;
    memcpy(m->base_color, base, sizeof base);
    m->metallic = 1.0f;
    m->roughness = 0.5f;
    assert_int_equal(lm_material_classify(m), LM_MAT_GLOSSY);
}

/* (g) The glossy lobe against bsdf.c: every pixel f(l -> v) I cos / d^2 with f from lm_bsdf_eval
 * (reciprocal: eval(-v, l) = f cos(ns, l)). The camera is orthographic, v = +y everywhere. */
static void test_glossy(void **state)
{
    (void)state;
    float *rgb = render_edit(lmt_plane_scene(), NULL, make_glossy);
    lm_material m = {.base_color = GLOSSY_BASE, .metallic = 1.0f, .roughness = 0.5f};
    lm_material_classify(&m);
    lm_shading sh = {.ng = {0, 1, 0}, .ns = {0, 1, 0}, .albedo = {0.9f, 0.6f, 0.3f}, .material = &m};
    const float wi[3] = {0, -1, 0};
    double worst = 0.0, peak = 0.0;
    for (int r = 0; r < W; r++)
        for (int i = 0; i < W; i++) {
            double x, z;
            pixel_xz(i, r, &x, &z);
            double d2 = x * x + z * z + 4.0, d = sqrt(d2);
            float l[3] = {(float)(-x / d), (float)(2.0 / d), (float)(-z / d)}, f[3];
            lm_bsdf_eval(&sh, wi, l, f);
            for (int c = 0; c < 3; c++) {
                double want = f[c] * 10.0 / d2;
                worst = fmax(worst, rel(rgb[3 * (r * W + i) + c], want));
                peak = fmax(peak, want);
            }
        }
    print_message("glossy (n = %.0f): worst pixel error %.2e against lm_bsdf_eval, peak radiance %.3f\n",
                  lm_phong_exponent(0.5f), worst, peak);
    assert_true(worst < 0.01);
    free(rgb);
}

/* The plane's material gets a 2 x 2 base colour texture (rows differ) and a uv offset that puts the
 * plane's uv (0, 0) at the centre of texel (0, 0), the top-left one. */
static void add_texture(lm_scene *s)
{
    static const float texels[16] = {0.9f, 0.5f, 0.2f, 1, 0.1f, 0.1f, 0.1f, 1, 0.3f, 0.3f, 0.3f, 1, 0.2f, 0.2f, 0.2f, 1};
    lm_texture *t = realloc(s->textures, sizeof *t * (size_t)(s->texture_count + 1));
    assert_non_null(t);
    s->textures = t;
    t = &s->textures[s->texture_count];
    t->width = t->height = 2;
    t->rgba = malloc(sizeof texels);
    assert_non_null(t->rgba);
    memcpy(t->rgba, texels, sizeof texels);
    lm_material *m = &s->materials[s->tri_material[0]];
    m->base_color_tex = s->texture_count++;
    m->base_color_uv = 0;
    m->uv_offset[0] = m->uv_offset[1] = 0.25f;
}

/* (h) The base colour texture: the plane's albedo is factor x texel (0, 0), as lm_material_albedo. */
static void test_texture(void **state)
{
    (void)state;
    lm_scene *s = NULL;
    lm_error err;
    lm_load_options opt = {0};
    assert_int_equal(lm_scene_load_gltf(lmt_plane_scene(), &opt, &s, &err), LM_OK);
    add_texture(s);
    float albedo[3];
    lm_material_albedo(s, &s->materials[s->tri_material[0]], s->uv0[0], s->uv0[1], albedo);
    lm_scene_free(s);
    float *rgb = render_edit(lmt_plane_scene(), NULL, add_texture);
    double worst = 0.0;
    for (int c = 0; c < 3; c++) {
        double x, z;
        pixel_xz(W / 2, W / 2, &x, &z);
        double d2 = x * x + z * z + 4.0, want = albedo[c] / PI * 20.0 / (d2 * sqrt(d2));
        worst = fmax(worst, rel(rgb[3 * (W / 2 * W + W / 2) + c], want));
    }
    print_message("texture: albedo (%.3f, %.3f, %.3f), worst channel error %.2e\n", albedo[0], albedo[1],
                  albedo[2], worst);
    assert_true(fabs(albedo[0] - 0.8f * 0.9f) < 1e-5f); /* the CPU lookup hit texel (0, 0) */
    assert_true(worst < 0.01);
    free(rgb);
}

/* (e) Two renders are bit-identical. */
static void test_deterministic(void **state)
{
    (void)state;
    const char *path = box_scene();
    float *a = render(path), *b = render(path);
    assert_memory_equal(a, b, sizeof(float) * 3 * W * W);
    free(a);
    free(b);
}

/* A loaded scene with its emitters, for the cache tests: node 1 the plane, 2 the light, 3 the box. */
typedef struct {
    lm_scene *s;
    lm_emitters em;
    lm_view v;
} live_scene;

/* dynamic_node: the node marked dynamic (it and the other caster then sit in different layers). */
static void live_load(live_scene *l, const char *path, int dynamic_node)
{
    lm_error err;
    lm_load_options opt = {0};
    assert_int_equal(lm_scene_load_gltf(path, &opt, &l->s, &err), LM_OK);
    assert_int_equal(l->s->node_count, 4);
    l->s->nodes[dynamic_node].dynamic = 1; /* the static / dynamic caster split is exercised */
    assert_int_equal(lm_emitters_build(l->s, &l->em, &err), LM_OK);
    lm_emitters_update(&l->em, l->s);
    lm_scene_update_bounds(l->s);
    top_view(&l->v);
}

/* After editing the scene: world matrices, bounds and emitters current, as the frame loop keeps them. */
static void live_update(live_scene *l)
{
    lm_scene_update_world(l->s);
    lm_scene_update_bounds(l->s);
    lm_emitters_update(&l->em, l->s);
}

static void live_free(live_scene *l)
{
    lm_emitters_free(&l->em);
    lm_scene_free(l->s);
}

/* The persistent object's render of the current state, checked against a fresh one-shot render. */
static float *render_both(lm_direct *d, live_scene *l, const char *what)
{
    lm_error err;
    float *a = malloc(sizeof(float) * 3 * W * W), *b = malloc(sizeof(float) * 3 * W * W);
    assert_non_null(a);
    assert_non_null(b);
    if (lm_direct_render(d, l->s, &l->em, &l->v, W, W, a, &err) != LM_OK ||
        lm_render_direct(l->s, &l->em, &l->v, W, W, NULL, b, &err) != LM_OK)
        fail_msg("%s: %s", what, err.msg);
    size_t differ = 0;
    for (int i = 0; i < 3 * W * W; i++)
        differ += a[i] != b[i];
    if (differ)
        fail_msg("%s: the persistent render differs from a fresh one in %zu values (a stale cache)", what, differ);
    free(b);
    return a;
}

static int differs(const float *a, const float *b)
{
    return memcmp(a, b, sizeof(float) * 3 * W * W) != 0;
}

/* (i) A persistent lm_direct after each change renders what a fresh render renders, and the change shows.
 * dynamic_node 3: the box is dynamic; 1: the plane is, and the box is a static caster that moves without
 * changing the scene bounds (so only the static-layer bookkeeping can notice). */
static void check_cache_follows(const char *path, int dynamic_node)
{
    live_scene l;
    live_load(&l, path, dynamic_node);
    lm_direct *d = NULL;
    lm_error err;
    assert_int_equal(lm_direct_create(l.s, NULL, NULL, &d, &err), LM_OK);
    float *first = render_both(d, &l, "first render");
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 1);

    l.s->nodes[3].translation[0] -= 0.4f; /* the box moves: its shadow moves */
    live_update(&l);
    float *moved = render_both(d, &l, "box moved");
    assert_true(differs(first, moved));
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 2);

    l.s->nodes[2].translation[2] += 0.3f; /* the light moves */
    live_update(&l);
    float *light = render_both(d, &l, "light moved");
    assert_true(differs(moved, light));
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 3);

    for (int c = 0; c < 3; c++) /* more power: the image changes, the shadow map does not */
        l.em.e[0].radiant[c] *= 2.0f;
    float *power = render_both(d, &l, "power changed");
    assert_true(differs(light, power));
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 3);

    l.s->nodes[1].translation[1] -= 0.1f; /* the plane moves */
    live_update(&l);
    float *plane = render_both(d, &l, "plane moved");
    assert_true(differs(power, plane));
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 4);

    print_message("cache (%s, node %d dynamic): 4 changes, each identical to a fresh render; 4 maps rendered\n",
                  path, dynamic_node);

    assert_int_equal(lm_direct_shadow_maps_held(d), 1); /* the light removed: its map given back */
    l.s->lights[0].removed = 1;
    live_update(&l);
    free(render_both(d, &l, "light removed"));
    assert_int_equal(lm_direct_shadow_maps_held(d), 0);
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 4);
    lm_direct_free(d);
    live_free(&l);
    free(first);
    free(moved);
    free(light);
    free(power);
    free(plane);
}

static void test_cache_follows_changes(void **state)
{
    (void)state;
    check_cache_follows(box_scene(), 3);
    const char *spot = "{\"translation\": [0, 2, 0], \"rotation\": [-0.70710678, 0, 0, 0.70710678],"
                       " \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}";
    check_cache_follows(scene_with("spot_box", 1, spot,
                                   "{\"type\": \"spot\", \"intensity\": 10,"
                                   " \"spot\": {\"innerConeAngle\": 0.6, \"outerConeAngle\": 0.9}}"),
                        1);
}

/* The box scene (node 3, the box, dynamic) loaded live with a persistent lm_direct, and its first render
 * checked against a fresh one (caller frees). */
static float *live_start(live_scene *l, lm_direct **d)
{
    lm_error err;
    live_load(l, box_scene(), 3);
    assert_int_equal(lm_direct_create(l->s, NULL, NULL, d, &err), LM_OK);
    return render_both(*d, l, "first render");
}

/* (k) A point light's cube map skips the faces its dynamic casters neither reach nor reached: the box
 * leaves the face under the light (whose old shadow must then be cleared), stays out of it (the face is
 * skipped) and comes back; each render equals a fresh one, which draws every face. */
static void test_cube_faces_follow_casters(void **state)
{
    (void)state;
    live_scene l;
    lm_direct *d = NULL;
    float *under = live_start(&l, &d); /* the box under the light */
    const float xs[3] = {3.0f, 3.5f, 0.5f}; /* beside the light (+x face only), further, back under it */
    const char *what[3] = {"box beside the light", "box further aside", "box back under the light"};
    float *prev = NULL;
    for (int k = 0; k < 3; k++) {
        l.s->nodes[3].translation[0] = xs[k];
        live_update(&l);
        float *now = render_both(d, &l, what[k]);
        if (k == 0)
            assert_true(differs(under, now)); /* the shadow left the picture */
        if (k == 1)
            assert_memory_equal(prev, now, sizeof(float) * 3 * W * W);
        if (k == 2)
            assert_memory_equal(under, now, sizeof(float) * 3 * W * W);
        free(prev);
        prev = now;
    }
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 4);
    print_message("cube faces follow the dynamic casters: 3 moves, each identical to a fresh render\n");
    free(prev);
    free(under);
    lm_direct_free(d);
    live_free(&l);
}

/* (j) Nothing changed: the second render is identical and renders no shadow map; nor does a point light
 * that only turns. */
static void test_cache_nothing_moved(void **state)
{
    (void)state;
    live_scene l;
    lm_direct *d = NULL;
    lm_error err;
    float *a = live_start(&l, &d);
    live_update(&l); /* recomputing the same matrices is not a change */
    float *b = malloc(sizeof(float) * 3 * W * W);
    assert_non_null(b);
    assert_int_equal(lm_direct_render(d, l.s, &l.em, &l.v, W, W, b, &err), LM_OK);
    assert_memory_equal(a, b, sizeof(float) * 3 * W * W);
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 1);
    l.s->nodes[2].rotation[0] = 0.6f; /* a point light turning changes neither its light nor its cube map */
    l.s->nodes[2].rotation[3] = 0.8f;
    live_update(&l);
    float *turned = render_both(d, &l, "point light turned");
    assert_memory_equal(a, turned, sizeof(float) * 3 * W * W);
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 1);
    free(turned);
    print_message("nothing moved (or a point light turned): renders identical, shadow maps rendered %ld\n",
                  lm_direct_shadow_maps_rendered(d));
    lm_direct_free(d);
    live_free(&l);
    free(a);
    free(b);
}

/* A class edit that makes the plane glossy (lm_scene.pass_version moves, as lmgi's material edit moves it)
 * gives a persistent lm_direct the glossy lobe, whose programs a scene without a glossy material leaves
 * out (direct.c, light_program); the edit undone takes it away again: each render equals a fresh one, the
 * last the first to the bit. */
static void test_class_edit_glossy(void **state)
{
    (void)state;
    live_scene l;
    lm_direct *d = NULL;
    float *diffuse = live_start(&l, &d);
    lm_material *m = &l.s->materials[l.s->tri_material[0]], was = *m;
    make_glossy(l.s);
    l.s->pass_version++;
    float *glossy = render_both(d, &l, "plane made glossy");
    assert_true(differs(diffuse, glossy));
    *m = was;
    l.s->pass_version++;
    float *back = render_both(d, &l, "plane diffuse again");
    assert_memory_equal(diffuse, back, sizeof(float) * 3 * W * W);
    print_message("class edits: glossy and back, each as a fresh render\n");
    lm_direct_free(d);
    live_free(&l);
    free(diffuse);
    free(glossy);
    free(back);
}

/* The box scene's plane and box (node 4, dynamic) under two point lights: node 2 right above the box, node
 * 3 far off to the side; their emitters 0 and 1. */
static void two_lights_load(live_scene *l)
{
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-10, 0, 10}, (float[3]){20, 0, 0}, (float[3]){0, 0, -20});
    lmt_mesh_cube(&m[1], 0.25f);
    const char *nodes = "[{\"children\": [1, 2, 3, 4]}, {\"mesh\": 0},"
                        " {\"translation\": [0.5, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
                        " {\"translation\": [-8, 3, 8], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
                        " {\"mesh\": 1, \"translation\": [0.5, 1, 0]}]";
    const char *ext = "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\":"
                      " {\"lights\": [{\"type\": \"point\", \"intensity\": 10}]}},";
    char path[512];
    snprintf(path, sizeof path, "%s/two_lights.gltf", lmt_tmpdir());
    if (lmt_write_gltf(path, m, 2, nodes, NULL, 0, ext) != 0)
        fail_msg("cannot write %s", path);
    lm_error err;
    lm_load_options opt = {0};
    assert_int_equal(lm_scene_load_gltf(path, &opt, &l->s, &err), LM_OK);
    assert_int_equal(l->s->node_count, 5);
    l->s->nodes[4].dynamic = 1;
    assert_int_equal(lm_emitters_build(l->s, &l->em, &err), LM_OK);
    assert_int_equal(l->em.count, 2);
    lm_emitters_update(&l->em, l->s);
    lm_scene_update_bounds(l->s);
    top_view(&l->v);
}

/* One update's render with a budget of `maps` shadow maps. */
static void budget_render(lm_direct *d, live_scene *l, int maps, float *rgb)
{
    lm_error err;
    lm_direct_begin_update(d, maps);
    if (lm_direct_render(d, l->s, &l->em, &l->v, W, W, rgb, &err) != LM_OK)
        fail_msg("budget render: %s", err.msg);
    lm_direct_end_update(d);
}

/* (l) The shadow maps' budget per update: maps never made are drawn whatever the budget; after the box
 * moves, one map an update, the near light's first, the far light's at the next update, and then the
 * picture is a fresh render's; with the box moving at every update, the far light's map still gets its
 * turn (its priority grows while it waits). */
static void test_map_budget(void **state)
{
    (void)state;
    live_scene l;
    two_lights_load(&l);
    lm_direct *d = NULL;
    lm_error err;
    assert_int_equal(lm_direct_create(l.s, NULL, NULL, &d, &err), LM_OK);
    float *rgb = malloc(sizeof(float) * 3 * W * W);
    assert_non_null(rgb);
    budget_render(d, &l, 0, rgb); /* no budget at all: the first maps are drawn still */
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 2);
    assert_int_equal(lm_direct_stale_maps(d), 0);
    free(render_both(d, &l, "first maps under a budget of 0"));

    l.s->nodes[4].translation[0] -= 0.4f;
    live_update(&l);
    budget_render(d, &l, 1, rgb);
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 3);
    assert_int_equal(lm_direct_stale_maps(d), 1);
    assert_false(lm_direct_map_stale(d, 0)); /* the light above the box first */
    assert_true(lm_direct_map_stale(d, 1));
    budget_render(d, &l, 1, rgb);
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 4);
    assert_int_equal(lm_direct_stale_maps(d), 0);
    free(render_both(d, &l, "both maps caught up"));

    int waited = 0;
    for (; waited < 200; waited++) {
        l.s->nodes[4].translation[2] += (waited & 1) ? 0.01f : -0.01f;
        live_update(&l);
        budget_render(d, &l, 1, rgb);
        if (!lm_direct_map_stale(d, 1))
            break;
    }
    assert_true(waited > 0);   /* the near light's map won while the far one had waited little */
    assert_true(waited < 200); /* and the far one was not starved */
    print_message("shadow map budget: first maps drawn at a budget of 0, near light first after a move, the far "
                  "light's map redrawn after %d updates of a box moving every update at one map an update\n", waited);
    free(rgb);
    lm_direct_free(d);
    live_free(&l);
}

/* (m) The maps' memory budget follows the live lights: 24 point lights share it at 256 a face; with 4 of
 * them removed (20 x 12.6 MB would fit at 512, but fill more than 3/4 of it) the sides stay, and with 12
 * removed they grow back to 512; adding them back shrinks them again. The pictures at 24 and 12 lights are
 * a fresh render's. */
static void test_map_sides_follow_lights(void **state)
{
    (void)state;
    lmt_mesh m[1];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-10, 0, 10}, (float[3]){20, 0, 0}, (float[3]){0, 0, -20});
    char nodes[8192], lights[4096];
    int n = snprintf(nodes, sizeof nodes, "[{\"mesh\": 0}");
    for (int i = 0; i < 24; i++)
        n += snprintf(nodes + n, sizeof nodes - (size_t)n, ", {\"translation\": [%d, 2, %d], \"extensions\": "
                      "{\"KHR_lights_punctual\": {\"light\": 0}}}", i % 6 - 3, i / 6 - 2);
    snprintf(nodes + n, sizeof nodes - (size_t)n, "]");
    snprintf(lights, sizeof lights, "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": "
             "{\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\", \"intensity\": 1}]}},");
    char path[512];
    snprintf(path, sizeof path, "%s/many_lights.gltf", lmt_tmpdir());
    if (lmt_write_gltf(path, m, 1, nodes, NULL, 0, lights) != 0)
        fail_msg("cannot write %s", path);
    live_scene l;
    lm_error err;
    lm_load_options opt = {0};
    assert_int_equal(lm_scene_load_gltf(path, &opt, &l.s, &err), LM_OK);
    assert_int_equal(l.s->light_count, 24);
    assert_int_equal(lm_emitters_build(l.s, &l.em, &err), LM_OK);
    lm_emitters_update(&l.em, l.s);
    lm_scene_update_bounds(l.s);
    top_view(&l.v);
    lm_direct *d = NULL;
    assert_int_equal(lm_direct_create(l.s, NULL, NULL, &d, &err), LM_OK);
    const int removed[4] = {0, 4, 12, 0}, want[4] = {256, 256, 512, 256};
    for (int k = 0; k < 4; k++) {
        for (int i = 0; i < 24; i++)
            l.s->lights[i].removed = i < removed[k];
        live_update(&l);
        if (k == 1) { /* a fresh render of 20 lights makes 512 a face: only the persistent one kept 256 */
            float *rgb = malloc(sizeof(float) * 3 * W * W);
            assert_int_equal(lm_direct_render(d, l.s, &l.em, &l.v, W, W, rgb, &err), LM_OK);
            free(rgb);
        } else {
            free(render_both(d, &l, "lights removed or back"));
        }
        int cube = 0, map = 0;
        lm_direct_map_sides(d, &cube, &map);
        print_message("%d point lights: cube faces of %d\n", 24 - removed[k], cube);
        assert_int_equal(cube, want[k]);
    }
    lm_direct_free(d);
    live_free(&l);
}

/* (l) A sun over a level 2 km across (the whole-scene map's texel 2.8 m, which would blur the 0.5 m box's
 * shadow away): the map fitted to the view (top_view, 4 m across) puts the umbra on the plane beyond the
 * box black and the plane round it at rho / pi E cos 30; the same view again, or moved by a centimetre,
 * redraws no map; moved 10 m it redraws the view's map once, and the shadow is the same. */
static void check_sun_shadow(const float *rgb, const char *what)
{
    double want = RHO / PI * cos(30.0 * PI / 180.0);
    shadow_tally t = {0};
    double reach = 0.5 * tan(30.0 * PI / 180.0); /* the box's top edge at 0.5 throws the shadow this far in -z */
    for (int r = 0; r < W; r++)
        for (int i = 0; i < W; i++) {
            double x, z;
            pixel_xz(i, r, &x, &z); /* relative to the view, which moves with the box */
            int umbra = fabs(x - 0.5) < 0.2 && z < -0.27 && z > -0.25 - reach + 0.03;
            if (umbra || fabs(x - 0.5) > 0.35 || z > 0.35 || z < -0.25 - reach - 0.1)
                tally_add(&t, umbra, lum(rgb + 3 * (r * W + i)), want);
        }
    tally_check(&t, what, 15, 2000, 0.02);
}

static void test_sun_over_a_large_level(void **state)
{
    (void)state;
    char node[256]; /* rotation about x by -60 degrees: the light travels along (0, -cos 30, -sin 30) */
    snprintf(node, sizeof node,
             "{\"rotation\": [%.9f, 0, 0, %.9f], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}",
             sin(-30.0 * PI / 180.0), cos(-30.0 * PI / 180.0));
    live_scene l;
    live_load(&l, scene_plane_box("large_level", 1000.0f, 1, 0.25f, node, "{\"type\": \"directional\", \"intensity\": 1}"),
              3);
    lm_direct *d = NULL;
    lm_error err;
    assert_int_equal(lm_direct_create(l.s, NULL, NULL, &d, &err), LM_OK);
    float *a = malloc(sizeof(float) * 3 * W * W), *b = malloc(sizeof(float) * 3 * W * W);
    assert_non_null(a);
    assert_non_null(b);
    assert_int_equal(lm_direct_render(d, l.s, &l.em, &l.v, W, W, a, &err), LM_OK);
    float texel = 0.0f;
    assert_true(lm_direct_view_map_texel(d, 0, 1, &texel));
    print_message("sun over 2 km: the view's map texel %.4f m\n", texel);
    assert_true(texel < 0.02f);
    check_sun_shadow(a, "sun over 2 km, the view's map");
    assert_int_equal(lm_direct_view_maps_rendered(d), 1);

    assert_int_equal(lm_direct_render(d, l.s, &l.em, &l.v, W, W, b, &err), LM_OK); /* the same view */
    assert_memory_equal(a, b, sizeof(float) * 3 * W * W);
    for (int k = 0; k < 2; k++) { /* a centimetre to the side and back: inside one snap cell */
        float step = k ? -0.01f : 0.01f, shift[16];
        lm_mat4_identity(shift);
        shift[12] = -step;
        lm_mat4_mul(l.v.view, l.v.view, shift);
        l.v.eye[0] += step;
        assert_int_equal(lm_direct_render(d, l.s, &l.em, &l.v, W, W, b, &err), LM_OK);
    }
    assert_int_equal(lm_direct_view_maps_rendered(d), 1);
    assert_int_equal(lm_direct_shadow_maps_rendered(d), 1);

    l.s->nodes[3].translation[0] += 10.0f; /* box and camera 10 m on */
    live_update(&l);
    float shift[16];
    lm_mat4_identity(shift);
    shift[12] = -10.0f;
    lm_mat4_mul(l.v.view, l.v.view, shift);
    l.v.eye[0] += 10.0f;
    assert_int_equal(lm_direct_render(d, l.s, &l.em, &l.v, W, W, b, &err), LM_OK);
    check_sun_shadow(b, "the box and the view 10 m on");
    assert_int_equal(lm_direct_view_maps_rendered(d), 2);

    /* A perspective camera 3 m up on the shadow's side looking out over the plane, far 100: the nearest
     * 25 m get their own map (the nearer cascade), which holds the box; its umbra black and a ring round
     * it lit. */
    lm_view p;
    memset(&p, 0, sizeof p);
    lm_vec3 eye = lm_v3(10.5f, 3.0f, -3.5f);
    lm_mat4_look_at(p.view, eye, lm_v3(10.5f, 0.0f, 12.0f), lm_v3(0, 1, 0)); /* over the box, to the horizon */
    lm_mat4_perspective(p.proj, 1.4f, 1.0f, 0.1f, 100.0f);
    lm_v3_store(p.eye, eye);
    assert_int_equal(lm_direct_render(d, l.s, &l.em, &p, W, W, b, &err), LM_OK);
    float near_texel = 0.0f, far_texel = 0.0f;
    assert_true(lm_direct_view_map_texel(d, 0, 0, &near_texel));
    assert_true(lm_direct_view_map_texel(d, 0, 1, &far_texel));
    print_message("perspective view: cascade texels %.4f m and %.4f m\n", near_texel, far_texel);
    assert_true(near_texel < far_texel && near_texel < 0.1f);
    float vp[16];
    lm_mat4_mul(vp, p.proj, p.view);
    double want = RHO / PI * cos(30.0 * PI / 180.0);
    shadow_tally t = {0};
    for (int k = 0; k < 400; k++) { /* umbra points, then a ring 1.2-1.8 m from the box */
        double x, z;
        if (k < 100) {
            x = 10.4 + 0.2 * (k % 10) / 9.0, z = -0.30 - 0.12 * (k / 10) / 9.0;
        } else {
            double a = 2.0 * PI * (k - 100) / 300.0, r = 1.2 + 0.6 * ((k * 7) % 300) / 300.0;
            x = 10.5 + r * cos(a), z = r * sin(a);
        }
        float c[4];
        for (int q = 0; q < 4; q++)
            c[q] = vp[q] * (float)x + vp[12 + q] + vp[8 + q] * (float)z;
        int i = (int)((c[0] / c[3] * 0.5f + 0.5f) * W), r = (int)((0.5f - c[1] / c[3] * 0.5f) * W);
        if (i < 0 || i >= W || r < 0 || r >= W)
            continue;
        tally_add(&t, k < 100, lum(b + 3 * (r * W + i)), want);
    }
    tally_check(&t, "perspective view, the near cascade (points, not pixels)", 80, 200, 0.02);
    lm_direct_free(d);
    live_free(&l);
    free(a);
    free(b);
}

/* One face of an environment map (lm_direct_draw_probe), size x size RGBA floats read back. */
static float *probe_face(lm_direct *d, lm_scene *s, const lm_emitters *em, const float eye[3], int face, int size,
                         int skip)
{
    lm_error err;
    lm_view v;
    lm_view_cube_face(eye, face, 1e-4f * lm_scene_size(s), 10.0f * lm_scene_size(s), &v);
    if (lm_direct_draw_probe(d, s, em, &v, size, skip, &err) != LM_OK)
        fail_msg("probe face %d: %s", face, err.msg);
    float *rgba = malloc(sizeof(float) * 4 * (size_t)size * (size_t)size);
    assert_non_null(rgba);
    glBindTexture(GL_TEXTURE_2D, lm_frame_targets_radiance(lm_direct_targets(d), LM_FRAME_PROBE));
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, rgba);
    return rgba;
}

/* (l) Environment faces draw the scene simplified (settings.probe_lod): scenes/cornell.glb, whose bumpy
 * floor is 12,808 of its 14,750 triangles, is drawn into them with under a tenth of its triangles. Each of
 * the six faces seen from the mirror sphere's place (the sphere left out, as lm_reflections draws them)
 * reads as with every triangle within 5% over the face, and under 5% of its pixels are more than 10% off:
 * direct light only, and what differs is the floor's shadow edges, where the simplified floor lies up to
 * 7 mm off the one the shadow map holds (measured 3.5% and 3.2% on the face looking down, under 1.3% and
 * 1% on the others; the light through a face is what matters, the frame shows it on the spheres alone).
 * The frame's own view draws every triangle: the same to the bit. With probe_lod 0 the faces draw every
 * triangle; a negative one is refused. */
static void test_probe_lod(void **state)
{
    (void)state;
    lm_scene *s = NULL;
    lm_emitters em;
    lm_error err;
    lm_load_options opt = {0};
    assert_int_equal(lm_scene_load_gltf("scenes/cornell.glb", &opt, &s, &err), LM_OK);
    assert_int_equal(lm_emitters_build(s, &em, &err), LM_OK);
    lm_emitters_update(&em, s);
    lm_scene_update_bounds(s);
    lm_direct_settings every, simplified, bad;
    lm_direct_settings_default(&every);
    simplified = bad = every;
    every.probe_lod = 0.0f;
    bad.probe_lod = -1.0f;
    lm_direct *full = NULL, *lod = NULL, *none = NULL;
    assert_int_equal(lm_direct_create(s, NULL, &every, &full, &err), LM_OK);
    assert_int_equal(lm_direct_create(s, NULL, &simplified, &lod, &err), LM_OK);
    assert_int_equal(lm_direct_create(s, NULL, &bad, &none, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "probe lod"));
    assert_int_equal(lm_direct_probe_triangles(full), s->tri_count);
    assert_true(lm_direct_probe_triangles(lod) < s->tri_count / 10);
    int mirror = -1;
    for (int n = 0; n < s->node_count; n++)
        mirror = !strcmp(s->nodes[n].name, "mirror_sphere") ? n : mirror;
    assert_true(mirror >= 0);
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, eye[3];
    const lm_node *nd = &s->nodes[mirror];
    for (uint32_t t = nd->first_tri; t < nd->first_tri + nd->tri_count; t++)
        for (int c = 0; c < 3; c++) {
            float p[3];
            lm_scene_vertex_world(s, s->tris[3 * (size_t)t + c], p);
            for (int k = 0; k < 3; k++)
                lo[k] = fminf(lo[k], p[k]), hi[k] = fmaxf(hi[k], p[k]);
        }
    for (int k = 0; k < 3; k++)
        eye[k] = 0.5f * (lo[k] + hi[k]);
    const int size = 128;
    double worst_face = 0.0, worst_share = 0.0;
    for (int face = 0; face < 6; face++) {
        float *a = probe_face(full, s, &em, eye, face, size, mirror), *b = probe_face(lod, s, &em, eye, face, size, mirror);
        double sum_a = 0.0, sum_d = 0.0;
        int off = 0;
        for (int i = 0; i < size * size; i++) {
            double la = lum(a + 4 * i), lb = lum(b + 4 * i);
            sum_a += la, sum_d += fabs(lb - la);
            off += fabs(lb - la) > 0.1 * la + 1e-6;
        }
        worst_face = fmax(worst_face, sum_d / sum_a);
        worst_share = fmax(worst_share, (double)off / (size * size));
        free(a);
        free(b);
    }
    print_message("environment faces: %u of %u triangles; worst face %.4f off, worst share of pixels 10%% off %.4f\n",
                  lm_direct_probe_triangles(lod), s->tri_count, worst_face, worst_share);
    assert_true(worst_face < 0.05);
    assert_true(worst_share < 0.05);
    lm_view v;
    lm_view_cube_face(eye, 3, 1e-4f * lm_scene_size(s), 10.0f * lm_scene_size(s), &v);
    float *va = malloc(sizeof(float) * 3 * W * W), *vb = malloc(sizeof(float) * 3 * W * W);
    assert_non_null(va);
    assert_non_null(vb);
    assert_int_equal(lm_direct_render(full, s, &em, &v, W, W, va, &err), LM_OK);
    assert_int_equal(lm_direct_render(lod, s, &em, &v, W, W, vb, &err), LM_OK);
    assert_memory_equal(va, vb, sizeof(float) * 3 * W * W);
    free(va);
    free(vb);
    lm_direct_free(full);
    lm_direct_free(lod);
    lm_emitters_free(&em);
    lm_scene_free(s);
}

/* (m) The nodes are drawn smallest first (direct_mesh.c, draw_order), so that the enclosing plane's hidden
 * pixels fail the early depth test behind the box instead of being shaded and covered: in box_scene's
 * index buffer every one of the box's triangles comes before every one of the plane's, although the file
 * lists the plane first. */
static void test_small_nodes_drawn_first(void **state)
{
    (void)state;
    lm_scene *s = NULL;
    lm_error err;
    lm_load_options opt = {0};
    assert_int_equal(lm_scene_load_gltf(box_scene(), &opt, &s, &err), LM_OK);
    int plane = -1, box = -1;
    for (int n = 0; n < s->node_count; n++)
        if (s->nodes[n].tri_count)
            *(plane < 0 ? &plane : &box) = n;
    assert_true(plane >= 0 && box > plane); /* the file's order: the plane, then the box */
    lm_direct_mesh m;
    assert_int_equal(lm_direct_mesh_build(&m, s, NULL, 1, 0.0f, &err), LM_OK);
    uint32_t *index = malloc(sizeof(uint32_t) * (size_t)m.mesh.vertices);
    assert_non_null(index);
    glBindVertexArray(m.mesh.vao);
    glGetBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, (GLsizeiptr)(sizeof(uint32_t) * (size_t)m.mesh.vertices), index);
    glBindVertexArray(0);
    int last_box = -1, first_plane = m.mesh.vertices, seen[2] = {0, 0};
    for (int i = 0; i < m.mesh.vertices; i++) {
        int v = (int)index[i];
        if (v >= m.node_first[box] && v < m.node_first[box] + m.node_verts[box])
            last_box = i, seen[0]++;
        if (v >= m.node_first[plane] && v < m.node_first[plane] + m.node_verts[plane])
            first_plane = i < first_plane ? i : first_plane, seen[1]++;
    }
    assert_true(seen[0] > 0 && seen[1] > 0);
    assert_true(last_box < first_plane);
    free(index);
    lm_direct_mesh_free(&m);
    lm_scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_plane), cmocka_unit_test(test_point_plane_range), cmocka_unit_test(test_box_shadow), cmocka_unit_test(test_box_shadow_every_face), cmocka_unit_test(test_grazing),
        cmocka_unit_test(test_spot), cmocka_unit_test(test_contact), cmocka_unit_test(test_glossy), cmocka_unit_test(test_class_edit_glossy), cmocka_unit_test(test_texture),
        cmocka_unit_test(test_deterministic), cmocka_unit_test(test_cache_follows_changes),
        cmocka_unit_test(test_cache_nothing_moved),
        cmocka_unit_test(test_cube_faces_follow_casters), cmocka_unit_test(test_map_budget),
        cmocka_unit_test(test_map_sides_follow_lights), cmocka_unit_test(test_sun_over_a_large_level),
        cmocka_unit_test(test_probe_lod), cmocka_unit_test(test_small_nodes_drawn_first),
    };
    return cmocka_run_group_tests(tests, lmt_gl_setup, lmt_gl_teardown);
}
