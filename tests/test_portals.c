/* Portals (issue 30, item 3; docs/levels.md, "Portals"; src/trace/portals.h, portal_finder.h): a closed
 * room, 4 x 3 x 4 m, on a 60 x 60 m ground, lit inside only through a 1 x 1 m window in its +x wall by a
 * sun and a sky. Without portals the sun's photons leave from a rectangle across the whole level and about
 * one in 2,000 enters, the sky's fewer still; with the window tagged as a portal, or found without a tag,
 * half of them are drawn through it and the places outside that light the room. The estimate must stay the
 * same (the mixture's density weighs each photon), and the room must be lit by photons everywhere. The
 * generated sunlit living room (scenes/sunlit_room.glb) against the reference; its lawn's bounces aimed in
 * through the windows found, drawn as their density says and steadying the light inside. A portal with no
 * mesh is refused, naming its node. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <lmgi_tools.h>

#include "../src/core/qmc.h"
#include "../src/trace/lights.h"
#include "../src/core/vecmath.h"
#include "../src/trace/portal_finder.h"
#include "../src/trace/portals.h"
#include "../src/update/photon_stage.h"
#include "edit_room.h"
#include "support.h"

/* The room (mesh 0: floor, ceiling, four walls facing in, the +x wall around its window), the window's
 * portal quad (mesh 1, its front facing out, +x) and a sun of `sun` lux (0: dark) travelling along (-1,
 * -0.6, 0): through the window onto the floor near x = -0.5. `portal`: tag mesh 1 as a portal (else it is
 * left out). `sky`: extras of the root, or "". */
static const char *lit_room(const char *name, int portal, const char *sky, double sun)
{
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, -2}, (float[3]){0, 0, 4}, (float[3]){4, 0, 0});   /* floor */
    lmt_mesh_quad(&m[0], (float[3]){-2, 3, -2}, (float[3]){4, 0, 0}, (float[3]){0, 0, 4});   /* ceiling */
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, -2}, (float[3]){0, 3, 0}, (float[3]){0, 0, 4});   /* x = -2 */
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, -2}, (float[3]){4, 0, 0}, (float[3]){0, 3, 0});   /* z = -2 */
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, 2}, (float[3]){0, 3, 0}, (float[3]){4, 0, 0});    /* z = +2 */
    lmt_mesh_quad(&m[0], (float[3]){2, 0, -2}, (float[3]){0, 0, 4}, (float[3]){0, 1, 0});    /* x = +2 below */
    lmt_mesh_quad(&m[0], (float[3]){2, 2, -2}, (float[3]){0, 0, 4}, (float[3]){0, 1, 0});    /* above */
    lmt_mesh_quad(&m[0], (float[3]){2, 1, -2}, (float[3]){0, 0, 1.5f}, (float[3]){0, 1, 0}); /* beside */
    lmt_mesh_quad(&m[0], (float[3]){2, 1, 0.5f}, (float[3]){0, 0, 1.5f}, (float[3]){0, 1, 0});
    lmt_mesh_quad(&m[0], (float[3]){-30, -0.01f, -30}, (float[3]){0, 0, 60}, (float[3]){60, 0, 0}); /* ground */
    lmt_mesh_quad(&m[1], (float[3]){2, 1, -0.5f}, (float[3]){0, 1, 0}, (float[3]){0, 0, 1}); /* the window */
    char nodes[1024], file[64];
    /* the sun's node: -Z along (-1, -0.6, 0) / 1.16619: x' = (0, 0, 1), y' = (0.6, -1, 0) / n, z' = (1, 0.6, 0) / n */
    snprintf(nodes, sizeof nodes,
             "[{\"mesh\": 0}%s, {\"matrix\": [0, 0, 1, 0, 0.514496, -0.857493, 0, 0, 0.857493, 0.514496, 0, 0, 0, 0, "
             "0, 1], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}, {\"translation\": [-1.9, 1.5, 1.9], "
             "\"rotation\": [0, -0.3827, 0, 0.9239], \"camera\": 0}]",
             portal ? ", {\"mesh\": 1, \"extras\": {\"lmgi\": {\"portal\": true}}}" : "");
    snprintf(file, sizeof file, "%s.gltf", name);
    char materials[1024];
    snprintf(materials, sizeof materials,
             "[" LMT_DIFFUSE(0.7) ", " LMT_DIFFUSE(0.7) "], %s" LMT_LIGHTS("{\"type\": \"directional\", \"intensity\": %g}")
             ", \"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 1.2, \"znear\": 0.01}}]", sky,
             sun);
    return lmt_write_scene(file, m, 2, nodes, materials);
}

typedef struct {
    double aim_mean;   /* the AIM's mean radiance over the room's inside (green, area-weighted) */
    uint32_t valid, dark; /* the inside's valid AIM texels, and those exactly 0 */
    double ratio[3], rmse; /* the frame against the reference (not measured with cam NULL) */
} outcome;

static const char *room(const char *name, int portal, const char *sky) { return lit_room(name, portal, sky, 20.0); }

/* find: whether the updater looks for portals (lmgi_updater_desc.find_portals); target: the reference's
 * relative error per pixel. */
static outcome bake(const char *path, const lmgi_camera *cam, uint32_t photons, int find, float target)
{
    lmgi_scene *sc = lmt_load(path, 4000);
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.photons.count = photons;
    d.photons.find_portals = find ? 0 : LMGI_OFF;
    lmgi_updater *u = NULL;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *rgba = malloc(n * sizeof *rgba);
    assert_non_null(rgba);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_AIM, rgba, n, &e), LMGI_OK);
    outcome o;
    memset(&o, 0, sizeof o);
    double area = 0.0;
    for (uint32_t i = 0; i < lmgi_texel_count(sc); i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        const float *px = rgba + 4 * ((size_t)t.y * in.atlas_width + t.x);
        if (!(px[3] > 0.0f) || t.position[1] < 0.0f || fabsf(t.position[0]) > 2.001f || fabsf(t.position[2]) > 2.001f)
            continue; /* the ground, and what is not valid */
        o.valid++;
        o.dark += px[1] == 0.0f;
        o.aim_mean += t.area * px[1];
        area += t.area;
    }
    o.aim_mean /= area > 0.0 ? area : 1.0;
    free(rgba);
    if (!cam) {
        lmgi_updater_free(u);
        lmgi_free(sc);
        lmgi_context_free(ctx);
        return o;
    }
    lmgi_reference_desc rd;
    memset(&rd, 0, sizeof rd);
    rd.target_error = target;
    rd.cache_dir = lmt_reference_cache();
    lmgi_check_result c;
    assert_int_equal(lmgi_check_updater(u, cam, 48, 48, &rd, &c, &e), LMGI_OK);
    memcpy(o.ratio, c.ratio, sizeof o.ratio);
    o.rmse = c.rel_rmse;
    lmgi_check_free(&c);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
    return o;
}

static void print_outcome(const char *what, const char *how, const outcome *o)
{
    print_message("%s, %s: AIM mean inside %.5f, %u of %u valid texels 0; frame / reference %.3f %.3f %.3f, RMSE "
                  "%.3f\n", what, how, o->aim_mean, o->dark, o->valid, o->ratio[0], o->ratio[1], o->ratio[2], o->rmse);
}

/* With portals (tagged or found), no texel inside is left at 0, the frame is within 5% of the reference and
 * nearer it than without; and, where 16 times the photons without portals make a fair estimate of the
 * room (many not NULL: the sun's 450 photons through the window; the sky's are a handful), the room's AIM
 * within 5% of theirs. */
static void assert_guided(const outcome *o, const outcome *none, const outcome *many)
{
    assert_int_equal(o->dark, 0);
    if (many)
        assert_true(fabs(o->aim_mean / many->aim_mean - 1.0) < 0.05);
    for (int k = 0; k < 3; k++)
        assert_float_equal(o->ratio[k], 1.0, 0.05);
    assert_true(fabs(o->ratio[1] - 1.0) < fabs(none->ratio[1] - 1.0));
}

/* The room at the default photons with neither portal (finding switched off), with the window tagged, and
 * untagged with its window found; and without portals at 16 times the photons. Measured (frame /
 * reference): the sun alone none 1.122 (its AIM +37%), tagged 0.973, found 0.982; the sun and the sky none
 * 0.947 (56 of 173 texels inside at 0), tagged 0.958, found 0.976; the sky alone none 0.472 (every texel
 * inside at 0), tagged 1.033, found 1.036. Over seeds 1 to 3 the tagged and found frames stay within 5%
 * but for two at -5.1% and -8% (the tagged sun and sky of seed 2). */
static void compare(const char *what, const char *sky, double sun)
{
    char name[64];
    lmgi_camera cam;
    lmt_look_at((const float[3]){-1.9f, 1.6f, 1.9f}, (const float[3]){1.0f, 0.6f, -1.0f}, 1.2f, &cam);
    char open[1024];
    snprintf(name, sizeof name, "%s_open", what);
    snprintf(open, sizeof open, "%s", lit_room(name, 0, sky, sun));
    /* the sky through a window is slow to path-trace: its references are noisier, still about 0.1% over the
     * frame's 2,000 pixels */
    float target = sky[0] ? 0.06f : 0.03f;
    outcome none = bake(open, &cam, 0, 0, target), many = bake(open, NULL, 16 * 46080, 0, target);
    outcome found = bake(open, &cam, 0, 1, target);
    snprintf(name, sizeof name, "%s_portal", what);
    outcome tagged = bake(lit_room(name, 1, sky, sun), &cam, 0, 1, target);
    print_message("%s, 16 x the photons, no portal: AIM mean inside %.5f, %u of %u valid texels 0\n", what,
                  many.aim_mean, many.dark, many.valid);
    print_outcome(what, "no portal", &none);
    print_outcome(what, "the window tagged a portal", &tagged);
    print_outcome(what, "the window found", &found);
    int fair = !strstr(what, "sky");
    assert_guided(&tagged, &none, fair ? &many : NULL);
    assert_guided(&found, &none, fair ? &many : NULL);
}

/* The flux that enters through the window from above (the lines from below cross the ground first), summed
 * over N photons of emitter e: the same with and without portals, tagged or found (find: as the photon
 * stage finds them), what the mixture's weights promise; here straight from the emitters. */
static double entering(const char *path, int e, int find, uint32_t n, uint32_t *through)
{
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 0.5f);
    static const float window[9 * 2] = {2, 1, -0.5f, 2, 2, -0.5f, 2, 2, 0.5f, 2, 1, -0.5f, 2, 2, 0.5f, 2, 1, 0.5f};
    lm_portals *probe = lm_portals_make(window, NULL, NULL, NULL, 2, NULL); /* to count what crosses the window */
    assert_non_null(probe);
    lm_portals_aim(probe, NULL);
    if (find) { /* the emitter's portals found, as the photon stage does */
        lm_portals *found = NULL;
        lm_error err;
        assert_int_equal(lm_portals_find(p.s, &p.su, p.rt, &p.em.e[e], &found, &err), LM_OK);
        assert_non_null(found);
        lm_emitter_set_portals(&p.em, e, found);
    }
    double sum = 0.0;
    *through = 0;
    for (uint32_t i = 0; i < n; i++) {
        float u[4];
        for (int k = 0; k < 4; k++)
            u[k] = (float)lm_halton((uint32_t)k, i);
        lm_emission emi;
        lm_emitter_emit(&p.em, p.s, e, u, n, &emi);
        if (emi.dir[1] < 0.0f && lm_portals_density(probe, emi.org, emi.dir) > 0.0) {
            sum += emi.flux[1];
            (*through)++;
        }
    }
    lm_portals_free(probe);
    lmt_pipeline_free(&p);
    return sum;
}

#define SKY_EXTRAS "\"extras\": {\"lmgi\": {\"sky\": [1, 1, 1]}}, "

/* The flux through the window from 65,536 photons, tagged or found: within 2% of what it is, from hundreds
 * of times the photons (a third of the found portals' photons go to the places outside that light the room
 * too). The sun's: E A cos = 20 x 1 x 0.857 (within 1% of 4M photons without portals too); the sky's from
 * above: L pi / 2 (a vertical window, the upper half of its hemisphere), which 65,536 photons without
 * portals do not reach at all. */
static void test_unbiased_emission(void **state)
{
    (void)state;
    char open[1024], tagged[1024]; /* lmt_write_scene's path is its own buffer */
    snprintf(open, sizeof open, "%s", room("emit_open", 0, SKY_EXTRAS));
    snprintf(tagged, sizeof tagged, "%s", room("emit_portal", 1, SKY_EXTRAS));
    const double sun = 20.0 / sqrt(1.36), sky = LM_PI / 2.0;
    uint32_t a, b, f, many, sa, sb, sf;
    double without = entering(open, 0, 0, 1u << 16, &a), with = entering(tagged, 0, 0, 1u << 16, &b);
    double found = entering(open, 0, 1, 1u << 16, &f), truth = entering(open, 0, 0, 1u << 22, &many);
    double sky_without = entering(open, 1, 0, 1u << 16, &sa), sky_with = entering(tagged, 1, 0, 1u << 16, &sb);
    double sky_found = entering(open, 1, 1, 1u << 16, &sf);
    print_message("sun: flux through the window %.5f (%.5f from %u of 4M photons without portals); from 65,536: %.5f "
                  "from %u without, %.5f from %u tagged, %.5f from %u found\n", sun, truth, many, without, a, with, b,
                  found, f);
    print_message("sky: from above %.5f; from 65,536 photons: %.5f from %u without, %.5f from %u tagged, %.5f from %u "
                  "found\n", sky, sky_without, sa, sky_with, sb, sky_found, sf);
    assert_true(fabs(truth / sun - 1.0) < 0.01);
    assert_true(b > 500 * (a > 0 ? a : 1) && f > 200 * (a > 0 ? a : 1));
    assert_true(fabs(with / sun - 1.0) < 0.02 && fabs(found / sun - 1.0) < 0.02);
    assert_true(sb > 1000 * (sa > 0 ? sa : 1) && sf > 1000 * (sa > 0 ? sa : 1));
    assert_true(fabs(sky_with / sky - 1.0) < 0.02 && fabs(sky_found / sky - 1.0) < 0.02);
}

/* The window found without a tag (trace/portal_finder.h), for the sun and for the sky: the portal worth most
 * is the window, 1 x 1 m at x = 2 facing out (+x), its edges within 5 cm; none is found for an open plane. */
static void test_window_found(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, room("found_window", 0, SKY_EXTRAS), 0.5f);
    for (int e = 0; e < 2; e++) {
        lm_portals *found = NULL;
        lm_error err;
        assert_int_equal(lm_portals_find(p.s, &p.su, p.rt, &p.em.e[e], &found, &err), LM_OK);
        assert_non_null(found);
        lm_portals_aim(found, e == 0 ? p.em.e[0].dir : NULL);
        uint32_t best = 0;
        for (uint32_t i = 2; i < found->count; i += 2)
            best = found->weight[i] > found->weight[best] ? i : best;
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int v = 0; v < 6; v++)
            for (int k = 0; k < 3; k++) {
                lo[k] = fminf(lo[k], found->tris[9 * best + 3 * v + k]);
                hi[k] = fmaxf(hi[k], found->tris[9 * best + 3 * v + k]);
            }
        print_message("%s: %u portals found; the worthiest x %.3f .. %.3f, y %.3f .. %.3f, z %.3f .. %.3f, facing %.2f "
                      "%.2f %.2f\n", e ? "sky" : "sun", found->count / 2, lo[0], hi[0], lo[1], hi[1], lo[2], hi[2],
                      found->normal[3 * best], found->normal[3 * best + 1], found->normal[3 * best + 2]);
        assert_float_equal(lo[0], 2.0, 1e-3);
        assert_float_equal(hi[0], 2.0, 1e-3);
        assert_float_equal(lo[1], 1.0, 0.05);
        assert_float_equal(hi[1], 2.0, 0.05);
        assert_float_equal(lo[2], -0.5, 0.05);
        assert_float_equal(hi[2], 0.5, 0.05);
        assert_float_equal(found->normal[3 * best], 1.0, 1e-4);
        lm_portals_free(found);
    }
    lmt_pipeline_free(&p);
    static lmt_mesh m[1]; /* a lawn under the sun and the sky: nothing to find */
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-30, 0, -30}, (float[3]){0, 0, 60}, (float[3]){60, 0, 0});
    lmt_pipeline_load(&p, lmt_write_scene("lawn.gltf", m, 1,
                                          "[{\"mesh\": 0}, {\"matrix\": [0, 0, 1, 0, 0.514496, -0.857493, 0, 0, "
                                          "0.857493, 0.514496, 0, 0, 0, 0, 0, 1], \"extensions\": "
                                          "{\"KHR_lights_punctual\": {\"light\": 0}}}]",
                                          "[" LMT_DIFFUSE(0.7) "], " SKY_EXTRAS
                                          LMT_LIGHTS("{\"type\": \"directional\", \"intensity\": 20}")), 1.0f);
    for (int e = 0; e < 2; e++) {
        lm_portals *found = NULL;
        lm_error err;
        assert_int_equal(lm_portals_find(p.s, &p.su, p.rt, &p.em.e[e], &found, &err), LM_OK);
        assert_null(found);
    }
    lmt_pipeline_free(&p);
}

/* The updater's lightmap `kind` (RGBA, the atlas's size); in->atlas_width its row. */
static float *lightmap_of(lmgi_scene *sc, lmgi_updater *u, lmgi_lightmap kind, lmgi_info *in)
{
    lmgi_get_info(sc, in);
    size_t n = 4 * (size_t)in->atlas_width * in->atlas_height;
    float *rgba = malloc(n * sizeof *rgba);
    assert_non_null(rgba);
    lmgi_error e;
    assert_int_equal(lmgi_get_lightmap(u, kind, rgba, n, &e), LMGI_OK);
    return rgba;
}

/* Whether texel t, whose lightmap value is px, is valid and inside the house of scenes/sunlit_room.glb
 * (x in [-3, 3], z in [-2.5, 2.5], y in [0, 2.8]). */
static int inside_house(const lmgi_texel *t, const float *px)
{
    return px[3] > 0.0f && fabsf(t->position[0]) <= 3.0f && fabsf(t->position[2]) <= 2.5f &&
           t->position[1] >= -0.01f && t->position[1] <= 2.8f;
}

/* The reference's texels of sc at a target error of 0.1, not cached. */
static void reference_texels(lmgi_scene *sc, lmgi_reference *ref)
{
    lmgi_reference_desc rd;
    memset(&rd, 0, sizeof rd);
    rd.target_error = 0.1f;
    rd.no_cache = 1;
    lmgi_error e;
    if (lmgi_reference_texels(sc, &rd, ref, &e) != LMGI_OK)
        fail_msg("%s", e.message);
}

/* The texels of the lightmap inside the house that are valid and exactly 0 where the reference's IIM is
 * above 1% of its surface's mean. */
static uint32_t black_inside(lmgi_scene *sc, lmgi_updater *u, lmgi_lightmap kind, const float *reference,
                             uint32_t *valid)
{
    lmgi_info in;
    float *rgba = lightmap_of(sc, u, kind, &in);
    double *sum = calloc((size_t)in.surfaces + 1, sizeof *sum);
    uint32_t *count = calloc((size_t)in.surfaces + 1, sizeof *count), black = 0;
    assert_true(sum && count);
    for (int pass = 0; pass < 2; pass++) { /* the surfaces' reference means, then the texels against them */
        *valid = 0;
        for (uint32_t i = 0; i < lmgi_texel_count(sc); i++) {
            lmgi_texel t;
            lmgi_get_texel(sc, i, &t);
            size_t at = (size_t)t.y * in.atlas_width + t.x;
            const float *px = rgba + 4 * at, *r = reference + 3 * at;
            if (!inside_house(&t, px))
                continue;
            double lum = 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2];
            if (pass == 0) {
                sum[t.surface] += lum;
                count[t.surface]++;
                continue;
            }
            ++*valid;
            black += px[0] == 0.0f && px[1] == 0.0f && px[2] == 0.0f && lum > 0.01 * sum[t.surface] / count[t.surface];
        }
    }
    free(rgba);
    free(sum);
    free(count);
    return black;
}

/* Issue 30's sunlit interior: the generated living room (scenes/sunlit_room.glb, untagged windows) lit by
 * its sun alone (the sky and the bulbs switched off, so that only light through the windows lights the
 * room), baked at 8,000 texels, against the reference per texel: no texel of the lightmap inside is
 * exactly 0 where the reference is lit, and of the AIM's (the photons' estimate the lightmap gathers)
 * those fall more than fivefold with the windows found (measured: 270 of 839 without, 31 with). */
static void test_sunlit_room_has_no_black_texels(void **state)
{
    (void)state;
    lmgi_scene *sc = lmt_load("scenes/sunlit_room.glb", 8000);
    lmgi_error e;
    assert_int_equal(lmgi_set_environment(sc, (const float[3]){0, 0, 0}, &e), LMGI_OK);
    for (int l = 1; l <= 2; l++) {
        lmgi_light light;
        assert_int_equal(lmgi_get_light(sc, l, &light, &e), LMGI_OK);
        light.enabled = 0;
        assert_int_equal(lmgi_set_light(sc, l, &light, &e), LMGI_OK);
    }
    lmgi_reference ref;
    reference_texels(sc, &ref);
    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    uint32_t black[2], valid[2], aim_black[2];
    for (int find = 0; find < 2; find++) {
        lmgi_updater_desc d;
        memset(&d, 0, sizeof d);
        d.photons.find_portals = find ? 0 : LMGI_OFF;
        lmgi_updater *u = NULL;
        if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
            fail_msg("%s", e.message);
        black[find] = black_inside(sc, u, LMGI_LIGHTMAP_IIM, ref.iim, &valid[find]);
        aim_black[find] = black_inside(sc, u, LMGI_LIGHTMAP_AIM, ref.radiance, &valid[find]);
        lmgi_updater_free(u);
    }
    print_message("sunlit room, the sun alone, 8,000 texels: valid texels inside exactly 0 where the reference is lit: "
                  "IIM %u, AIM %u of %u without portals, IIM %u, AIM %u with the windows found (reference %.1f s)\n",
                  black[0], aim_black[0], valid[0], black[1], aim_black[1], ref.seconds);
    assert_int_equal(black[1], 0);
    assert_true(aim_black[1] * 5 < aim_black[0]);
    lmgi_reference_free(&ref);
    lmgi_context_free(ctx);
    lmgi_free(sc);
}

/* The same room as the issue measures it, everything on (the sun, the sky, the bulbs), baked as `lmgi bake`
 * bakes it (65,536 texels asked, 67,679 made; 16 photons a texel, at most 2^20: lm_cli_bake_photons; one
 * bounce pass), its frame from the file's camera against the reference: over the frame within 2%, and every
 * visible surface of 25 pixels or more at 64 x 64 (100 at lmgi check's 128 x 128: the walls, floor, ceiling,
 * table, sofa and the lawn seen through the window) within 5% per channel. Measured: the frame 0.988 0.997
 * 0.983, the floor furthest off at 0.956 in blue, surface 24 (31 pixels) 1.047 in all three (at 4 photons a
 * texel, a bake's before 2026-12-07: the frame 0.983 0.985 0.983, the floor 0.956 in blue, 24 the same, 58
 * 0.960 in green where it now reads 1.026). */
static void test_sunlit_room_against_reference(void **state)
{
    (void)state;
    lmgi_scene *sc = lmt_load("scenes/sunlit_room.glb", 65536);
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    uint32_t photons = 16 * lmgi_texel_count(sc); /* lmgi bake's (LM_CLI_BAKE_PHOTONS_PER_TEXEL), at most 2^20 */
    d.photons.count = photons < 1048576u ? photons : 1048576u;
    d.gather.bounce_passes = 1; /* lmgi bake's own (LM_CLI_BAKE_BOUNCE_PASSES) */
    d.frame.width = d.frame.height = 64;
    lmgi_reference_desc rd;
    memset(&rd, 0, sizeof rd);
    rd.target_error = 0.05f;
    rd.cache_dir = lmt_reference_cache();
    lmgi_check_result c;
    if (lmgi_check(ctx, sc, &d, &rd, 1, &c, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    print_message("sunlit room as lmgi bake bakes it (%u texels, %u photons): frame / reference %.3f %.3f %.3f over %u "
                  "pixels (reference %.1f s)\n", lmgi_texel_count(sc), d.photons.count, c.ratio[0], c.ratio[1], c.ratio[2],
                  c.pixels, c.reference_seconds);
    for (int k = 0; k < 3; k++)
        assert_float_equal(c.ratio[k], 1.0, 0.02);
    for (int i = 0; i < c.surface_count; i++) {
        const lmgi_check_surface *f = &c.surfaces[i];
        if (f->pixels == 0)
            continue;
        print_message("  surface %d (node %d): %u pixels, %.3f %.3f %.3f\n", i, f->node, f->pixels, f->ratio[0],
                      f->ratio[1], f->ratio[2]);
        for (int k = 0; f->pixels >= 25 && k < 3; k++)
            assert_float_equal(f->ratio[k], 1.0, 0.05);
    }
    lmgi_check_free(&c);
    lmgi_context_free(ctx);
    lmgi_free(sc);
}

/* The relative L1 distance of the IIM's texels inside the house (as black_inside) from the reference's. */
static double inside_error(lmgi_scene *sc, lmgi_updater *u, const float *reference)
{
    lmgi_info in;
    float *rgba = lightmap_of(sc, u, LMGI_LIGHTMAP_IIM, &in);
    double diff = 0.0, sum = 0.0;
    for (uint32_t i = 0; i < lmgi_texel_count(sc); i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        size_t at = (size_t)t.y * in.atlas_width + t.x;
        const float *px = rgba + 4 * at, *r = reference + 3 * at;
        if (!inside_house(&t, px))
            continue;
        for (int c = 0; c < 3; c++)
            diff += fabs((double)px[c] - r[c]), sum += r[c];
    }
    free(rgba);
    return diff / sum;
}

/* Bounce passes (docs/gather.md): the sunlit room at the updater's photons, gathered once more twice over
 * from its own lightmap: for every seed the texels inside are nearer the reference's, and the seeds stay
 * together. */
static void test_bounce_passes_steady_the_room(void **state)
{
    (void)state;
    lmgi_scene *sc = lmt_load("scenes/sunlit_room.glb", 8000);
    lmgi_error e;
    lmgi_reference ref;
    reference_texels(sc, &ref);
    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    double err[2][3];
    for (int passes = 0; passes < 2; passes++)
        for (uint32_t seed = 0; seed < 3; seed++) {
            lmgi_updater_desc d;
            memset(&d, 0, sizeof d);
            d.photons.seed = seed;
            d.gather.bounce_passes = passes ? 2 : LMGI_OFF;
            lmgi_updater *u = NULL;
            if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
                fail_msg("%s", e.message);
            err[passes][seed] = inside_error(sc, u, ref.iim);
            lmgi_updater_free(u);
        }
    print_message("sunlit room, 8,000 texels, the IIM inside against the reference (relative L1), seeds 0-2: "
                  "%.4f %.4f %.4f; with 2 bounce passes %.4f %.4f %.4f (reference %.1f s)\n", err[0][0], err[0][1],
                  err[0][2], err[1][0], err[1][1], err[1][2], ref.seconds);
    double lo[2] = {1e9, 1e9}, hi[2] = {0.0, 0.0};
    for (int p = 0; p < 2; p++)
        for (int seed = 0; seed < 3; seed++)
            lo[p] = fmin(lo[p], err[p][seed]), hi[p] = fmax(hi[p], err[p][seed]);
    /* Measured: 0.1107 0.1153 0.1129 without, 0.1026 0.1069 0.1077 with. Before the lawn's bounces were aimed
     * in (portals.h) the photons alone read 0.174 0.134 0.124, and the passes halved that spread; now the
     * photons hardly spread, and what the passes still bring is the gather's bounce in place of the AIM's.
     * The spread with the passes also holds the gather's own noise since the seed draws its strata too
     * (lm_hemicube_settings.seed): 0.104 0.105 0.104 before, a spread of 0.001 that left that noise out.
     * So does each seed's gain: 0.0081 0.0084 0.0052 here (the sanitizer build, its sums in another order:
     * 0.0078 0.0085 0.0035), where one pattern for every seed had given each about 0.008; the gain on the
     * seeds' mean is 0.0072 (0.0066). */
    double gain = 0.0;
    for (int seed = 0; seed < 3; seed++) {
        assert_true(err[1][seed] < err[0][seed] - 0.002);
        gain += (err[0][seed] - err[1][seed]) / 3.0;
    }
    assert_true(gain > 0.005);
    assert_true(hi[1] < 0.11 && hi[1] - lo[1] < 0.008);
    lmgi_reference_free(&ref);
    lmgi_context_free(ctx);
    lmgi_free(sc);
}

/* The solid angle of triangle (a, b, c) seen from the origin (Van Oosterom and Strackee 1983). */
static double solid_angle(const double a[3], const double b[3], const double c[3])
{
    double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double bc[3] = {b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]};
    double triple = a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2];
    double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2], ac = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
    double bcd = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
    return 2.0 * atan2(fabs(triple), la * lb * lc + ab * lc + ac * lb + bcd * la);
}

/* Bounces aimed in (portals.h, "Bounces aimed in"): from a point of the ground outside, the draws towards
 * the window and their density agree, E[1 / p] over the draws being the window's solid angle (exact, from
 * its two triangles); a place outside in the same set is never aimed at; a point inside, and one whose
 * horizon hides the window, get nothing. */
static void test_bounce_draws_match_their_density(void **state)
{
    (void)state;
    static const float tris[9 * 4] = {2, 1, -0.5f, 2, 2, -0.5f, 2, 2, 0.5f, 2, 1, -0.5f, 2, 2, 0.5f, 2, 1, 0.5f,
                                      /* a place outside: lawn in front of the window, facing up */
                                      3, 0, -1, 3, 0, 1, 5, 0, 1, 3, 0, -1, 5, 0, 1, 5, 0, -1};
    static const unsigned char opening[4] = {1, 1, 0, 0};
    lm_portals *p = lm_portals_make(tris, NULL, NULL, opening, 4, NULL);
    assert_non_null(p);
    const float x[3] = {6.0f, 0.0f, 1.5f}, up[3] = {0, 1, 0};
    double omega = 0.0;
    for (int t = 0; t < 2; t++) {
        double c[3][3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                c[k][a] = tris[9 * t + 3 * k + a] - x[a];
        omega += solid_angle(c[0], c[1], c[2]);
    }
    double reach = lm_portals_bounce_reach(p, x, up), sum = 0.0;
    assert_true(reach > 0.0);
    const uint32_t n = 1u << 14;
    uint32_t missed = 0;
    for (uint32_t i = 0; i < n; i++) {
        float w[3];
        assert_true(lm_portals_bounce_dir(p, x, up, reach, (float)lm_halton(0, i), (float)lm_halton(1, i), w));
        double pdf = lm_portals_bounce_density(p, x, up, reach, w);
        float through = 2.0f - x[0];
        float y = x[1] + w[1] * through / w[0], z = x[2] + w[2] * through / w[0];
        missed += !(w[0] < 0.0f && y >= 0.999f && y <= 2.001f && fabsf(z) <= 0.501f);
        if (pdf > 0.0)
            sum += 1.0 / pdf;
        else
            missed++;
    }
    print_message("bounce aimed in from the lawn: E[1/p] %.6f sr against the window's solid angle %.6f sr; "
                  "%u of %u draws missed it\n", sum / n, omega, missed, n);
    assert_int_equal(missed, 0);
    assert_true(fabs(sum / n / omega - 1.0) < 0.005);
    const float down[3] = {-1, 0, 0}; /* along the lawn, not through the window */
    assert_true(lm_portals_bounce_density(p, x, up, reach, down) == 0.0);
    const float inside[3] = {0.0f, 0.5f, 0.0f}, above[3] = {6.0f, 3.0f, 1.5f};
    assert_true(lm_portals_bounce_reach(p, inside, up) == 0.0);
    assert_true(lm_portals_bounce_reach(p, above, up) == 0.0);
    lm_portals_free(p);
}

/* The light the sunlit living room's photons leave inside its house (x in [-3, 3], z in [-2.5, 2.5], y in
 * [0, 2.8]), as the updater's photon stage traces them, its bounces outside aimed in or not; *largest: the
 * largest share of a surface's light inside that one hit holds, over the surfaces with 2% of it or more. */
static double light_inside(lmt_pipeline *p, uint32_t photons, uint32_t seed, int aim, double *largest)
{
    lm_photon_stage_settings set;
    lm_photon_stage_settings_default(&set);
    set.photons.total_photons = photons;
    set.photons.seed = seed;
    set.photons.aim_bounces = aim;
    set.direct_at_hits = 1;
    lm_photon_stage *st = NULL;
    lm_error err;
    if (lm_photon_stage_create(&p->w, &set, &st, NULL, &err) != LM_OK)
        fail_msg("%s", err.msg);
    const lm_photon_store *s = lm_photon_stage_store(st);
    double *sum = calloc((size_t)s->surface_count, sizeof *sum), *top = calloc((size_t)s->surface_count, sizeof *top);
    assert_true(sum && top);
    double all = 0.0;
    for (int k = 0; k < s->surface_count; k++)
        for (uint32_t i = 0; i < s->surfaces[k].count; i++) {
            const lm_hit *h = &s->hits[s->surfaces[k].slots[i]];
            if (!lm_hit_in_iim(h) || fabsf(h->pos[0]) > 3.0f || fabsf(h->pos[2]) > 2.5f || h->pos[1] < -0.01f ||
                h->pos[1] > 2.8f)
                continue;
            double e = lm_hit_energy(h);
            sum[k] += e, all += e;
            top[k] = fmax(top[k], e);
        }
    *largest = 0.0;
    for (int k = 0; k < s->surface_count; k++)
        if (sum[k] >= 0.02 * all)
            *largest = fmax(*largest, top[k] / sum[k]);
    free(sum);
    free(top);
    lm_photon_stage_free(st);
    return all;
}

/* What aiming the lawn's bounces in buys: the light inside the sunlit living room over 8 seeds of the
 * updater's 46,080 photons swings far less, and no hit holds a large share of a surface's light (a sunlit
 * lawn's bounce through a window was one photon in a thousand, each worth a thousand); the mean is the same
 * as without, over 4 seeds of 16 times the photons (without aiming, their mean's own noise is about 1.5%). */
static void test_bounces_aimed_in_steady_the_light(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, "scenes/sunlit_room.glb", 0.25f);
    double mean[2][2] = {{0}}, sq[2] = {0}, heavy[2] = {0};
    for (int aim = 0; aim < 2; aim++) {
        for (uint32_t seed = 0; seed < 8; seed++) {
            double largest, e = light_inside(&p, 46080, seed, aim, &largest);
            mean[aim][0] += e / 8.0;
            sq[aim] += e * e / 8.0;
            heavy[aim] = fmax(heavy[aim], largest);
        }
        for (uint32_t seed = 0; seed < 4; seed++) {
            double largest;
            mean[aim][1] += light_inside(&p, 737280, 100 + seed, aim, &largest) / 4.0;
        }
    }
    double rsd[2];
    for (int aim = 0; aim < 2; aim++)
        rsd[aim] = sqrt(fmax(sq[aim] - mean[aim][0] * mean[aim][0], 0.0)) / mean[aim][0];
    print_message("sunlit room, the light inside over 8 seeds of 46,080 photons: mean %.0f, spread %.1f%%, largest "
                  "share of a surface's light in one hit %.1f%% without aiming the bounces in; mean %.0f, spread "
                  "%.1f%%, largest share %.1f%% with; over 4 seeds of 737,280: %.0f and %.0f\n", mean[0][0],
                  100 * rsd[0], 100 * heavy[0], mean[1][0], 100 * rsd[1], 100 * heavy[1], mean[0][1], mean[1][1]);
    assert_true(rsd[1] < 0.5 * rsd[0]);
    assert_true(heavy[1] < 0.5 * heavy[0]);
    assert_true(fabs(mean[1][1] / mean[0][1] - 1.0) < 0.05);
    lmt_pipeline_free(&p);
}

/* A portal node without a mesh: refused, naming it. */
static void test_portal_without_mesh(void **state)
{
    (void)state;
    static lmt_mesh m[1];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-1, 0, -1}, (float[3]){0, 0, 2}, (float[3]){2, 0, 0});
    const char *path = lmt_write_scene("bad_portal.gltf", m, 1,
                                       "[{\"mesh\": 0}, {\"name\": \"window\", \"extras\": {\"lmgi\": {\"portal\": true}}}]",
                                       "[" LMT_DIFFUSE(0.7) "]");
    lmgi_options o;
    lmgi_options_init(&o);
    lmgi_scene *sc = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_load(path, &o, &sc, &e), LMGI_ERR_INVALID);
    assert_null(sc);
    assert_non_null(strstr(e.message, "window"));
    assert_non_null(strstr(e.message, "portal"));
}

static void test_sun_through_a_window(void **state)
{
    (void)state;
    compare("sun", "", 20.0);
}

static void test_sun_and_sky_through_a_window(void **state)
{
    (void)state;
    compare("sun and sky", SKY_EXTRAS, 20.0);
}

static void test_sky_through_a_window(void **state)
{
    (void)state;
    compare("sky", SKY_EXTRAS, 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_unbiased_emission),
        cmocka_unit_test(test_window_found),
        cmocka_unit_test(test_sun_through_a_window),
        cmocka_unit_test(test_sun_and_sky_through_a_window),
        cmocka_unit_test(test_sky_through_a_window),
        cmocka_unit_test(test_sunlit_room_has_no_black_texels),
        cmocka_unit_test(test_sunlit_room_against_reference),
        cmocka_unit_test(test_bounce_passes_steady_the_room),
        cmocka_unit_test(test_bounce_draws_match_their_density),
        cmocka_unit_test(test_bounces_aimed_in_steady_the_light),
        cmocka_unit_test(test_portal_without_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
