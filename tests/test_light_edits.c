/* Lights added and removed through the public API (lmgi_add_light, lmgi_remove_light): an added light
 * lights the room as the same light loaded from the level does, only its own photons are traced,
 * removing it gives back the lightmap from before, removing every light leaves the room dark, the same
 * edits give the same lightmaps, an added light in one room of the two-room scene leaves the other
 * untouched, and bad lights are refused naming what is wrong.
 *
 * Lights changed in power alone (issue 32, item 2; docs/tradeoff.md, "Light edits at once"): a light
 * dimmed, brightened, recoloured or switched off shows in the lightmaps at the next update. Its photons
 * keep their paths, so their hits are scaled (or dropped) instead of traced again, the AIMs they reach are
 * refreshed at once, and each IIM texel is scaled by the ratio of two small ray gathers over the AIM before
 * and after (update/light_scale.h). Lit by one light, that is the lightmap a fresh updater makes of the
 * edited room; lit by two, a first guess that the regathers refine. Before, the lightmaps kept the old
 * light until the light's photons were traced again and every surface regathered: 60 to 120 updates at
 * `run`'s texels. */
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

static const lmgi_light_desc LAMP = {.name = "lamp", .type = LMGI_LIGHT_POINT, .color = {1.0f, 0.9f, 0.8f},
                                     .intensity = 4.0f, .position = {-1.0f, 2.5f, -1.0f}};
static const lmgi_light_desc SPOT = {.name = "spot", .type = LMGI_LIGHT_SPOT, .color = {0.3f, 0.6f, 1.0f},
                                     .intensity = 12.0f, .inner_cone = 0.3f, .outer_cone = 0.7f,
                                     .position = {1.0f, 2.8f, 1.0f}, .direction = {-0.2f, -1.0f, 0.1f}};

/* The edit room (edit_room.h) with its block off centre, lit by `lights`. */
static lmgi_scene *load_room(const lmgi_light_desc *lights, int light_count)
{
    lmt_room_spec spec = {.lights = lights, .light_count = light_count, .block_lo = {0.1f, 0.0f, -0.9f},
                          .block_hi = {0.9f, 1.0f, -0.1f}};
    return lmt_room(&spec);
}

static double frame_mean(lmgi_updater *u)
{
    float *rgb = lmt_corner_frame(u);
    double sum = 0.0;
    for (int i = 0; i < 3 * LMT_SIDE * LMT_SIDE; i++)
        sum += rgb[i];
    free(rgb);
    return sum / (LMT_SIDE * LMT_SIDE);
}

static lmgi_light light_of(const lmgi_light_desc *d)
{
    lmgi_light l;
    memset(&l, 0, sizeof l);
    l.type = (lmgi_light_type)d->type;
    memcpy(l.color, d->color, sizeof l.color);
    l.intensity = d->intensity;
    l.inner_cone = d->inner_cone, l.outer_cone = d->outer_cone;
    l.enabled = 1;
    memcpy(l.position, d->position, sizeof l.position);
    memcpy(l.direction, d->direction, sizeof l.direction);
    return l;
}


static void test_add_and_remove(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_error e;
    const lmgi_light_desc both[2] = {LAMP, SPOT};
    lmgi_scene *loaded = load_room(both, 2);
    lmgi_updater *ul = lmt_room_updater(ctx, loaded);
    size_t n;
    float *want = lmt_iim(ul, loaded, &n);
    double want_frame = frame_mean(ul);

    lmgi_scene *sc = load_room(&LAMP, 1);
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    float *before = lmt_iim(u, sc, &n);
    lmgi_updater_info info0, info1;
    lmgi_get_updater_info(u, &info0);
    /* one light: the count's split over its groups, the largest group's photons (the round robin's round) */
    assert_true(info0.photons.per_group * info0.photons.groups >= info0.stored_photons &&
                (info0.photons.per_group - 1) * info0.photons.groups < info0.stored_photons);

    lmgi_light spot = light_of(&SPOT);
    int id = -2;
    assert_int_equal(lmgi_add_light(sc, &spot, &id, &e), LMGI_OK);
    assert_int_equal(id, 1);
    assert_int_equal(lmgi_light_count(sc), 2);
    lmgi_light got;
    assert_int_equal(lmgi_get_light(sc, id, &got, &e), LMGI_OK);
    float len = sqrtf(SPOT.direction[0] * SPOT.direction[0] + SPOT.direction[1] * SPOT.direction[1] +
                      SPOT.direction[2] * SPOT.direction[2]);
    assert_int_equal(got.node, -1);
    for (int k = 0; k < 3; k++) {
        assert_float_equal(got.position[k], SPOT.position[k], 1e-6);
        assert_float_equal(got.direction[k], SPOT.direction[k] / len, 1e-6);
    }
    lmgi_bake_report r;
    lmt_bake(u, &r);
    lmgi_get_updater_info(u, &info1);
    uint32_t added = info1.stored_photons - info0.stored_photons;
    print_message("the added spot: %u photons (the lamp has %u), %u paths changed of %u traced, %d surfaces\n",
                  added, info0.stored_photons, r.photons_changed, r.photons_traced, r.surfaces_changed);
    assert_true(added > 0);
    assert_true(r.photons_changed <= added && r.photons_changed > added / 2); /* its photons, no other's */
    float *with = lmt_iim(u, sc, &n);
    const char *nodes[2] = {"room", "block"};
    for (int k = 0; k < 2; k++) {
        double a = lmt_node_mean(sc, with, nodes[k]), b = lmt_node_mean(loaded, want, nodes[k]);
        print_message("%s: added %.4f, loaded %.4f (%+.1f%%), before %.4f\n", nodes[k], a, b, 100.0 * (a / b - 1.0),
                      lmt_node_mean(sc, before, nodes[k]));
        assert_true(fabs(a / b - 1.0) < 0.03);
    }
    double frame = frame_mean(u);
    print_message("frame: added %.4f, loaded %.4f\n", frame, want_frame);
    assert_true(fabs(frame / want_frame - 1.0) < 0.02);

    /* the same edits on the same scene: the same lightmap, to the bit */
    lmgi_scene *again = load_room(&LAMP, 1);
    lmgi_updater_free(ul);
    lmgi_free(loaded);
    ul = lmt_room_updater(ctx, again);
    assert_int_equal(lmgi_add_light(again, &spot, &id, &e), LMGI_OK);
    lmt_bake(ul, &r);
    float *same = lmt_iim(ul, again, &n);
    assert_memory_equal(same, with, n * sizeof *same);

    /* exported for an engine: the added spot comes back as a light of its own node, where it was put */
    lmgi_export_desc x = {.name = "room", .force = 1};
    char dir[64], path[1200];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    assert_int_equal(lmgi_export_gltf(u, dir, &x, &e), LMGI_OK);
    snprintf(path, sizeof path, "%s/room.gltf", dir);
    lmgi_scene *copy = NULL;
    lmgi_options o;
    lmgi_options_init(&o);
    o.use_file_uv1 = 1;
    if (lmgi_load(path, &o, &copy, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    assert_int_equal(lmgi_light_count(copy), 2);
    lmgi_light back;
    assert_int_equal(lmgi_get_light(copy, 1, &back, &e), LMGI_OK);
    assert_int_equal(back.type, LMGI_LIGHT_SPOT);
    assert_true(back.node >= 0);
    for (int k = 0; k < 3; k++) {
        assert_float_equal(back.position[k], got.position[k], 1e-5);
        assert_float_equal(back.direction[k], got.direction[k], 1e-5);
        assert_float_equal(back.color[k], got.color[k], 1e-6);
    }
    assert_float_equal(back.outer_cone, got.outer_cone, 1e-6);
    lmgi_free(copy);

    /* moved: only its photons are traced again */
    assert_int_equal(lmgi_get_light(sc, 1, &got, &e), LMGI_OK);
    got.position[0] = -0.5f;
    assert_int_equal(lmgi_set_light(sc, 1, &got, &e), LMGI_OK);
    lmt_bake(u, &r);
    assert_true(r.photons_changed <= added && r.photons_changed > 0);
    assert_int_equal(lmgi_get_light(sc, 1, &got, &e), LMGI_OK);
    assert_float_equal(got.position[0], -0.5f, 1e-6);

    /* removed: the lightmap from before it came, but for the order of sums and the texels that see a change
     * below the one a bake regathers for (a thousandth of the stored energy: update/photon_stage.c). Those
     * are under 2% of the texels (measured 1.2% at N = 32), each off by under 1e-3 (measured 3.8e-4). */
    assert_int_equal(lmgi_remove_light(sc, 1, &e), LMGI_OK);
    assert_true(lmgi_light_is_removed(sc, 1) && !lmgi_light_is_removed(sc, 0));
    lmt_bake(u, &r);
    assert_true(r.photons_changed <= added);
    float *after = lmt_iim(u, sc, &n);
    double worst = 0.0;
    int valid = 0, off = 0;
    for (size_t i = 0; i < n; i += 4) {
        if (before[i + 3] < 0.5f)
            continue;
        double d = 0.0;
        for (int c = 0; c < 3; c++)
            d = fmax(d, fabs((double)after[i + c] - before[i + c]) / (fabs((double)before[i + c]) + 1e-3));
        worst = fmax(worst, d);
        valid++;
        off += d > 1e-4;
    }
    print_message("removed again: %d of %d texels more than 1e-4 from the lightmap before the add, the worst by %.2e\n",
                  off, valid, worst);
    assert_true(off <= valid / 50 && worst < 1e-3);
    for (int k = 0; k < 2; k++)
        assert_float_equal(lmt_node_mean(sc, after, nodes[k]), lmt_node_mean(sc, before, nodes[k]),
                           1e-3 * lmt_node_mean(sc, before, nodes[k]));
    lmgi_info in;
    lmgi_get_info(sc, &in);
    assert_int_equal(in.lights, 1);
    assert_int_equal(lmgi_light_count(sc), 2); /* its id stays taken */

    /* the file's own light removed: dark */
    assert_int_equal(lmgi_remove_light(sc, 0, &e), LMGI_OK);
    lmt_bake(u, &r);
    float *dark = lmt_iim(u, sc, &n);
    double most = 0.0;
    for (size_t i = 0; i < n; i++)
        most = fmax(most, fabs((double)dark[i] * (i % 4 != 3)));
    assert_true(most == 0.0);
    assert_true(frame_mean(u) == 0.0);
    assert_int_equal(lmgi_export_gltf(u, dir, &x, &e), LMGI_OK); /* no light left to export */
    if (lmgi_load(path, &o, &copy, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_get_info(copy, &in);
    assert_int_equal(in.lights, 0);
    lmgi_free(copy);

    /* bad lights and ids */
    lmgi_light bad = light_of(&SPOT);
    lmt_expect_invalid(lmgi_get_light(sc, 1, &got, &e), &e, "was removed");
    lmt_expect_invalid(lmgi_set_light(sc, 1, &bad, &e), &e, "was removed");
    lmt_expect_invalid(lmgi_remove_light(sc, 0, &e), &e, "was removed");
    lmt_expect_invalid(lmgi_remove_light(sc, 7, &e), &e, "out of range");
    bad.position[1] = NAN;
    lmt_expect_invalid(lmgi_add_light(sc, &bad, &id, &e), &e, "position");
    assert_int_equal(id, -1);
    bad = light_of(&SPOT);
    memset(bad.direction, 0, sizeof bad.direction);
    lmt_expect_invalid(lmgi_add_light(sc, &bad, &id, &e), &e, "direction");
    bad.type = LMGI_LIGHT_POINT; /* a point light needs none */
    assert_int_equal(lmgi_add_light(sc, &bad, &id, &e), LMGI_OK);
    assert_int_equal(id, 2);
    lmt_expect_invalid(lmgi_set_light(sc, 2, &bad, &e), &e, "fixed"); /* bad.node 0: not its node, -1 */
    bad = light_of(&SPOT);
    bad.type = (lmgi_light_type)3;
    lmt_expect_invalid(lmgi_add_light(sc, &bad, &id, &e), &e, "type 3");
    bad = light_of(&SPOT);
    bad.outer_cone = 0.1f;
    lmt_expect_invalid(lmgi_add_light(sc, &bad, &id, &e), &e, "cones");
    lmt_expect_invalid(lmgi_add_light(sc, &bad, NULL, &e), &e, "NULL");
    lmt_expect_invalid(lmgi_add_light(NULL, &bad, &id, &e), &e, "NULL");
    lmt_expect_invalid(lmgi_add_light(sc, NULL, &id, &e), &e, "NULL");
    lmt_expect_invalid(lmgi_remove_light(NULL, 0, &e), &e, "NULL");
    lmt_expect_invalid(lmgi_remove_light(sc, -1, &e), &e, "out of range");
    assert_false(lmgi_light_is_removed(NULL, 1));
    assert_false(lmgi_light_is_removed(sc, 99));
    assert_int_equal(lmgi_light_count(sc), 3); /* nothing added by the refused calls */

    free(want), free(before), free(with), free(same), free(after), free(dark);
    lmgi_updater_free(ul);
    lmgi_free(again);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A level that starts without any light (an editor's empty level) is lit by the first light added, with
 * the desc's photons per group, and shows it in the frame. */
static void test_first_light(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_error e;
    lmgi_scene *sc = load_room(NULL, 0);
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    size_t n;
    float *dark = lmt_iim(u, sc, &n);
    assert_true(lmt_node_mean(sc, dark, "room") == 0.0);
    lmgi_light lamp = light_of(&LAMP);
    int id = -1;
    assert_int_equal(lmgi_add_light(sc, &lamp, &id, &e), LMGI_OK);
    assert_int_equal(id, 0);
    lmgi_bake_report r;
    lmt_bake(u, &r);
    lmgi_updater_info info;
    lmgi_get_updater_info(u, &info);
    assert_int_equal(info.stored_photons, 72 * 100); /* photons_per_group x the default 72 groups */
    float *lit = lmt_iim(u, sc, &n);
    lmgi_scene *loaded = load_room(&LAMP, 1);
    lmgi_updater *ul = lmt_room_updater(ctx, loaded);
    float *want = lmt_iim(ul, loaded, &n);
    double a = lmt_node_mean(sc, lit, "room"), b = lmt_node_mean(loaded, want, "room");
    print_message("the first light of an empty room: %.4f, loaded with it %.4f\n", a, b);
    assert_true(fabs(a / b - 1.0) < 1e-3); /* the same photons, in another order of sums */
    assert_true(frame_mean(u) > 0.5 * frame_mean(ul));
    free(dark), free(lit), free(want);
    lmgi_updater_free(ul);
    lmgi_free(loaded);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A room without any light gathers nothing (lmgi info's "indirect: off"): its updates regather no texel
 * and its lightmap is black; its first light starts the gather, every surface regathered; removing the
 * last light blackens the lightmap at the next update, without waiting for a regather, and stops the
 * gather again. */
static void test_no_light_no_gather(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_error e;
    lmgi_scene *sc = load_room(NULL, 0);
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    lmgi_update_stats st;
    for (int f = 0; f < 5; f++) {
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
        assert_int_equal(st.texels_gathered, 0);
    }
    lmgi_light lamp = light_of(&LAMP);
    int id = -1;
    assert_int_equal(lmgi_add_light(sc, &lamp, &id, &e), LMGI_OK);
    uint32_t gathered = 0;
    for (int f = 0; f < 5; f++) {
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
        gathered += st.texels_gathered;
    }
    assert_true(gathered > 0);
    lmgi_bake_report r;
    lmt_bake(u, &r);
    size_t n;
    float *lit = lmt_iim(u, sc, &n);
    assert_true(lmt_node_mean(sc, lit, "room") > 0.0);
    assert_int_equal(lmgi_remove_light(sc, id, &e), LMGI_OK);
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
    float *dark = lmt_iim(u, sc, &n);
    for (size_t i = 0; i < n; i += 4) /* n floats */
        assert_true(dark[i] == 0.0f && dark[i + 1] == 0.0f && dark[i + 2] == 0.0f);
    for (int f = 0; f < 3; f++) {
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
        assert_int_equal(st.texels_gathered, 0);
    }
    free(lit);
    free(dark);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A room where nothing can move (no dynamic node with triangles: lmgi info's "photon updates: off")
 * re-traces no photon after its first frame; an edit of its light re-traces that light's photons, and
 * making its block dynamic starts the round robin that watches it. */
static void test_still_room_traces_nothing(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_error e;
    lmgi_scene *sc = load_room(&LAMP, 1); /* its block static, no stool */
    int block = lmgi_find_node(sc, "block");
    assert_true(block >= 0 && !lmgi_node_is_dynamic(sc, block));
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    lmgi_update_stats st;
    for (int f = 0; f < 5; f++) {
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
        assert_int_equal(st.photons_retraced, 0);
    }
    lmgi_light l;
    assert_int_equal(lmgi_get_light(sc, 0, &l, &e), LMGI_OK);
    l.intensity *= 0.5f;
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
    uint32_t retraced = 0;
    int scaled = 0;
    for (int f = 0; f < 5; f++) {
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
        retraced += st.photons_retraced;
        scaled += st.lights_scaled;
    }
    assert_int_equal(retraced, 0); /* dimmed: its hits scaled, not one photon traced (test_light_edits) */
    assert_int_equal(scaled, 1);
    l.range = 3.0f; /* its reach cut short: its paths' light changes */
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
    for (int f = 0; f < 5; f++) {
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
        retraced += st.photons_retraced;
    }
    assert_true(retraced > 0); /* the reshaped light's groups */
    for (int f = 0; f < 60; f++) /* its groups all re-traced: quiet again */
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
    assert_int_equal(st.photons_retraced, 0);
    assert_int_equal(lmgi_set_node_dynamic(sc, block, 1, &e), LMGI_OK);
    retraced = 0;
    for (int f = 0; f < 3; f++) { /* the photon work runs beside the updates: counted one update late */
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
        retraced += st.photons_retraced;
    }
    assert_true(retraced > 0); /* the round robin, watching the block */
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* An updater on the room with the lamp at `at` (lmt_room_desc), its waiting texels shown from their rays'
 * estimates or, with `alone`, not (gather.spread off). */
static lmgi_updater *lamp_room_updater(lmgi_context *ctx, lmgi_scene *sc, int alone)
{
    lmgi_updater_desc d;
    lmt_room_desc(&d);
    d.gather.spread = alone ? LMGI_OFF : 0;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

/* The lamp's edit: with `moved`, its node moved 2 m along x and z (lmgi_set_node_transform writes the
 * scene at once), else its range cut to 3 m (staged, committed by the next update). */
static void edit_lamp(lmgi_scene *sc, int moved)
{
    lmgi_light l;
    lmgi_error e;
    assert_int_equal(lmgi_get_light(sc, 0, &l, &e), LMGI_OK);
    if (!moved) {
        l.range = 3.0f;
        assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
        return;
    }
    float m[16];
    assert_true(lmgi_get_node_transform(sc, l.node, m));
    m[12] += 2.0f, m[14] += 2.0f;
    assert_int_equal(lmgi_set_node_transform(sc, l.node, m, &e), LMGI_OK);
}

/* The lamp edited (edit_lamp) after `still` still updates, then `updates` updates: the mean over them of the
 * shown lightmap's relative L1 distance from want; based and gathered get each update's texels whose ray
 * bases it took and that it gathered. */
static double edited_lamp_lag(lmgi_context *ctx, int moved, int alone, int still, const float *want, int updates,
                              uint32_t *based, uint32_t *gathered)
{
    lmgi_scene *sc = load_room(&LAMP, 1);
    lmgi_updater *u = lamp_room_updater(ctx, sc, alone);
    for (int f = 0; f < still; f++) {
        lmgi_update_stats s = lmt_update(u);
        assert_int_equal(s.texels_based, 0); /* a still level takes no ray bases */
    }
    edit_lamp(sc, moved);
    double sum = 0.0;
    for (int f = 0; f < updates; f++) {
        lmgi_update_stats s = lmt_update(u);
        based[f] = s.texels_based, gathered[f] = s.texels_gathered;
        size_t n;
        float *shown = lmt_iim(u, sc, &n);
        sum += lmt_relative_l1(shown, want, n);
        free(shown);
    }
    lmgi_updater_free(u);
    lmgi_free(sc);
    return sum / updates;
}

/* The waiting texels' ray estimates (docs/gather.md, "Rays for the texels that wait") need every texel's
 * base, a gather of 180 rays: a fifth of truck-town's setup, spent for nothing on a level that is only
 * shown. A level without dynamic nodes or animations takes them before its first edit instead, over the
 * scene and AIMs as they were (lightmap_path.h, lm_lightmap_path_before_change): the edit's update counts
 * them (a node moved, which writes the scene at once, and a light's edit, staged until the update's
 * commit). A scene with a dynamic node takes them at the setup: no drag waits for them. Taken after the
 * edit, the estimates would see no change and show the lightmap from before it. */
static void test_still_level_bases_at_first_edit(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    enum { UPDATES = 4 };
    for (int moved = 0; moved < 2; moved++) {
        lmgi_scene *sc = load_room(&LAMP, 1);
        lmgi_info in;
        lmgi_get_info(sc, &in);
        edit_lamp(sc, moved);
        lmgi_updater *fresh = lamp_room_updater(ctx, sc, 0);
        lmt_bake(fresh, NULL);
        size_t n;
        float *want = lmt_iim(fresh, sc, &n);
        lmgi_updater_free(fresh);
        lmgi_free(sc);
        uint32_t based[2][UPDATES], gathered[2][UPDATES];
        double rays = edited_lamp_lag(ctx, moved, 0, 3, want, UPDATES, based[0], gathered[0]);
        double alone = edited_lamp_lag(ctx, moved, 1, 3, want, UPDATES, based[1], gathered[1]);
        print_message("the lamp %s after 3 still updates: %u ray bases taken in the edit's update (%u texels, %u "
                      "gathered); the lightmap %.3f off a fresh bake over %d updates, %.3f without the estimates\n",
                      moved ? "moved" : "cut short", based[0][0], in.texels, gathered[0][0], rays, UPDATES, alone);
        assert_int_equal(based[0][0], in.texels + gathered[0][0]);
        for (int f = 1; f < UPDATES; f++)
            assert_int_equal(based[0][f], gathered[0][f]);
        for (int f = 0; f < UPDATES; f++)
            assert_int_equal(based[1][f], 0);
        /* 0.172 and 0.051 measured, against 0.298 and 0.162 without them; with the bases taken at the first
         * update with a texel waiting (after the edit's photons and AIMs), 0.296 and 0.155 (0.162 and 0.051
         * against those before a third of the estimates went by their expected staleness) */
        assert_true(rays < 0.7 * alone);
        free(want);
    }
    lmt_room_spec spec = {.lights = &LAMP, .light_count = 1, .stool = 1};
    lmgi_scene *sc = lmt_room(&spec);
    lmgi_updater *u = lamp_room_updater(ctx, sc, 0);
    lmgi_update_stats s = lmt_update(u);
    assert_int_equal(s.texels_based, s.texels_gathered); /* a dynamic stool: its bases at the setup */
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A light added in room A of the two rooms, door closed, and removed again: room B's lightmap and its
 * surfaces' versions stay as they were, to the bit (an edit costs only what it reaches). */
static void test_added_light_stays_in_its_room(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_error e;
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 3000;
    lmgi_scene *sc = NULL;
    if (lmgi_load(lmt_project_scene("two_rooms.glb"), &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    size_t n;
    float *iim0 = lmt_iim(u, sc, &n);
    int surfaces = lmgi_surface_count(sc);
    uint32_t *ver0 = calloc((size_t)surfaces, sizeof *ver0);
    for (int s = 0; s < surfaces; s++)
        ver0[s] = lmgi_surface_version(u, s);
    lmgi_light a1;
    int id = lmt_light_on_node(sc, "light_a1");
    assert_int_equal(lmgi_get_light(sc, id, &a1, &e), LMGI_OK);
    lmgi_light lamp = {.type = LMGI_LIGHT_POINT, .color = {1.0f, 0.5f, 0.2f}, .intensity = 2.0f * a1.intensity,
                       .enabled = 1, .position = {a1.position[0] + 0.5f, a1.position[1] - 0.5f, a1.position[2]}};
    assert_true(lamp.position[0] < -0.5f); /* in room A */
    assert_int_equal(lmgi_add_light(sc, &lamp, &id, &e), LMGI_OK);
    lmgi_bake_report r;
    lmt_bake(u, &r);
    float *iim1 = lmt_iim(u, sc, &n);
    assert_int_equal(lmgi_remove_light(sc, id, &e), LMGI_OK);
    lmgi_bake_report r2;
    lmt_bake(u, &r2);
    float *iim2 = lmt_iim(u, sc, &n);

    lmgi_info in;
    lmgi_get_info(sc, &in);
    uint8_t *reaches_a = calloc((size_t)surfaces, 1); /* room B's surfaces reaching into the doorway */
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        reaches_a[t.surface] |= t.position[0] < 0.2f;
    }
    int b_texels = 0;
    double a_before = 0.0, a_with = 0.0;
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        size_t k = 4 * ((size_t)t.y * in.atlas_width + t.x);
        if (t.position[0] > 0.2f && !reaches_a[t.surface]) {
            b_texels++;
            assert_memory_equal(iim0 + k, iim1 + k, 4 * sizeof *iim0);
            assert_memory_equal(iim0 + k, iim2 + k, 4 * sizeof *iim0);
            assert_int_equal(lmgi_surface_version(u, t.surface), ver0[t.surface]);
        } else if (t.position[0] < -0.2f) {
            a_before += iim0[k] + iim0[k + 1] + iim0[k + 2];
            a_with += iim1[k] + iim1[k + 1] + iim1[k + 2];
        }
    }
    print_message("a lamp added in room A: its indirect light x%.3f, %u texels regathered (%d surfaces changed); "
                  "%d texels of room B untouched; removed: %u texels regathered\n", a_with / a_before,
                  r.texels_gathered, r.surfaces_changed, b_texels, r2.texels_gathered);
    assert_true(b_texels > 100);
    assert_true(a_with > 1.1 * a_before);
    assert_true(r.texels_gathered > 0 && r.texels_gathered < in.texels * 3 / 4);
    free(iim0), free(iim1), free(iim2), free(ver0), free(reaches_a);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* The room lit by `lights`, its updater after three updates and the lightmap they show (n floats). */
typedef struct {
    lmgi_context *ctx;
    lmgi_scene *sc;
    lmgi_updater *u;
    float *before;
    size_t n;
} settled_room;

static void settle(settled_room *r, const lmgi_light_desc *lights, int count)
{
    r->ctx = lmt_context();
    r->sc = load_room(lights, count);
    r->u = lmt_room_updater(r->ctx, r->sc);
    lmt_updates(r->u, 3);
    r->before = lmt_iim(r->u, r->sc, &r->n);
}

static void unsettle(settled_room *r)
{
    free(r->before);
    lmgi_updater_free(r->u);
    lmgi_free(r->sc);
    lmgi_context_free(r->ctx);
}

/* One update, which must scale `scaled` lights and trace no photon group again. The AIMs it refreshed for
 * the edit at once count in its stats, as AIM work (the budget's cost model learns from them). */
static void update_scaling(lmgi_updater *u, int scaled, int retraced)
{
    lmgi_update_stats st;
    lmgi_error e;
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
    assert_int_equal(st.lights_scaled, scaled);
    if (!retraced)
        assert_int_equal(st.groups_retraced, 0);
    print_message("the edit's update: %d AIM surfaces refreshed in %.2f ms\n", st.aim_surfaces_refreshed,
                  st.ms_aim);
    if (scaled && !retraced)
        assert_true(st.aim_surfaces_at_once > 0 && st.aim_surfaces_at_once <= st.aim_surfaces_refreshed &&
                    st.ms_aim > 0.0);
}

static void edit_light(lmgi_scene *sc, int id, float intensity_by, const float *color, int enabled)
{
    lmgi_light l;
    lmgi_error e;
    assert_int_equal(lmgi_get_light(sc, id, &l, &e), LMGI_OK);
    l.intensity *= intensity_by;
    if (color)
        memcpy(l.color, color, sizeof l.color);
    l.enabled = enabled;
    assert_int_equal(lmgi_set_light(sc, id, &l, &e), LMGI_OK);
}

/* Lit by one lamp, dimmed and recoloured: the next update's lightmap and frame are a fresh updater's of
 * the edited room (same photon paths, so to float rounding), and the updates after change nothing. */
static void test_one_light_at_once(void **state)
{
    (void)state;
    settled_room r;
    settle(&r, &LAMP, 1);
    size_t n = r.n;
    const float tint[3] = {0.4f, 0.9f, 1.0f};
    edit_light(r.sc, 0, 0.3f, tint, 1);
    update_scaling(r.u, 1, 0);
    float *now = lmt_iim(r.u, r.sc, &n), *frame = lmt_corner_frame(r.u);
    lmt_updates(r.u, 60);
    float *later = lmt_iim(r.u, r.sc, &n);
    lmgi_updater_free(r.u);
    r.u = lmt_room_updater(r.ctx, r.sc); /* a fresh one, of the edited room */
    lmt_updates(r.u, 3);
    float *want = lmt_iim(r.u, r.sc, &n), *want_frame = lmt_corner_frame(r.u);
    double was = lmt_relative_l1(r.before, want, n), at_once = lmt_relative_l1(now, want, n);
    double shown = lmt_relative_l1(frame, want_frame, 3 * LMT_SIDE * LMT_SIDE), after = lmt_relative_l1(later, want, n);
    print_message("one lamp dimmed and recoloured: lightmap against a fresh updater's %.3g before the edit, %.3g "
                  "at the next update (frame %.3g), %.3g 60 updates later\n", was, at_once, shown, after);
    assert_true(was > 0.5);
    assert_true(at_once < 1e-4);
    assert_true(shown < 1e-4);
    assert_true(after < 1e-4);
    free(now), free(frame), free(later), free(want), free(want_frame);
    unsettle(&r);
}

/* Brightened 30 times: past LM_LIGHT_SCALE_DARK, but a power edit keeps its factors (exact where one light
 * lights the room), which an addition of the gathers' change would replace by their noise. */
static void test_one_light_brightened(void **state)
{
    (void)state;
    settled_room r;
    settle(&r, &LAMP, 1);
    size_t n = r.n;
    edit_light(r.sc, 0, 30.0f, NULL, 1);
    update_scaling(r.u, 1, 0);
    float *now = lmt_iim(r.u, r.sc, &n);
    lmgi_updater_free(r.u);
    r.u = lmt_room_updater(r.ctx, r.sc);
    lmt_updates(r.u, 3);
    float *want = lmt_iim(r.u, r.sc, &n);
    double at_once = lmt_relative_l1(now, want, n);
    print_message("one lamp brightened 30 times: lightmap against a fresh updater's %.3g at the next update\n", at_once);
    assert_true(at_once < 1e-4);
    free(now), free(want);
    unsettle(&r);
}

/* The same on an atlas past LM_LIGHT_SCALE_WORK / 4 texels, where only every stride-th texel gathers its
 * factor and the others sum their neighbours' (light_scale.h): still a fresh updater's at once. */
static void test_large_atlas_at_once(void **state)
{
    (void)state;
    lmt_room_spec spec = {.lights = &LAMP, .light_count = 1, .texel_size = 0.07f};
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = lmt_room(&spec);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    assert_true(in.texels > 8192);
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    lmt_updates(u, 2);
    edit_light(sc, 0, 0.4f, NULL, 1);
    update_scaling(u, 1, 0);
    size_t n;
    float *now = lmt_iim(u, sc, &n);
    lmgi_updater_free(u);
    u = lmt_room_updater(ctx, sc);
    lmt_updates(u, 2);
    float *want = lmt_iim(u, sc, &n);
    double at_once = lmt_relative_l1(now, want, n);
    print_message("%u texels, lamp dimmed: lightmap against a fresh updater's %.3g at the next update\n", in.texels,
                  at_once);
    assert_true(at_once < 1e-4);
    free(now), free(want);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* Lit by a warm lamp and a blue spot, one of them dimmed (or switched off): at the next update the
 * lightmap has made most of the way to what the same photons give once every surface is regathered (a bake
 * with the shares of creation kept). */
static void two_lights(int id, float by, int enabled, double most)
{
    const lmgi_light_desc both[2] = {LAMP, SPOT};
    settled_room r;
    settle(&r, both, 2);
    size_t n = r.n;
    edit_light(r.sc, id, by, NULL, enabled);
    update_scaling(r.u, 1, !enabled);
    float *now = lmt_iim(r.u, r.sc, &n);
    lmt_bake(r.u, NULL);
    float *want = lmt_iim(r.u, r.sc, &n);
    double was = lmt_relative_l1(r.before, want, n), at_once = lmt_relative_l1(now, want, n);
    print_message("%s %s: lightmap against the regathered one %.3g before the edit, %.3g at the next update\n",
                  id ? "spot" : "lamp", enabled ? "dimmed" : "switched off", was, at_once);
    assert_true(was > 0.1);
    assert_true(at_once < most * was);
    free(now), free(want);
    unsettle(&r);
}

static void test_two_lights_first_guess(void **state)
{
    (void)state;
    two_lights(0, 0.25f, 1, 0.015); /* 0.0047 of the change is left */
    two_lights(1, 3.0f, 1, 0.1);    /* 0.044: the spot's light is a tenth of the room's */
}

static void test_switched_off(void **state)
{
    (void)state;
    two_lights(0, 1.0f, 0, 0.015); /* 0.0046 */
}

/* The spot added to r's scene at three times its intensity (a change the size of the lamp's light); its id. */
static int add_bright_spot(settled_room *r)
{
    lmgi_light spot = light_of(&SPOT);
    spot.intensity *= 3.0f;
    int id = -1;
    lmgi_error e;
    assert_int_equal(lmgi_add_light(r->sc, &spot, &id, &e), LMGI_OK);
    return id;
}

/* A light lit where there was none (issue 32, item 6), without a budget: the edit's update traces its
 * photons and refreshes the AIMs they reach (every one of its groups traced: no re-trace left of them to
 * wait for), and the IIM takes each texel's factor from them, so that its lightmap has made most of the
 * way to what the same photons give once every surface is regathered. Before, the light's groups were
 * queued and traced over the updates after, and the lightmap at the next update was where it had been. */
static void lit_at_once(settled_room *r, int id, const char *what, double most)
{
    lmgi_update_stats st;
    lmgi_error e;
    size_t n = r->n;
    assert_int_equal(lmgi_update(r->u, 0.0f, 0.0f, &st, &e), LMGI_OK);
    float *now = lmt_iim(r->u, r->sc, &n);
    lmgi_light l;
    assert_int_equal(lmgi_get_light(r->sc, id, &l, &e), LMGI_OK);
    assert_true(l.enabled && st.aim_surfaces_at_once > 0 && st.ms_aim > 0.0);
    assert_int_equal(st.lights_lit, 1);
    assert_int_equal(st.lights_scaled, 0);
    lmt_bake(r->u, NULL);
    float *want = lmt_iim(r->u, r->sc, &n);
    double was = lmt_relative_l1(r->before, want, n), at_once = lmt_relative_l1(now, want, n);
    print_message("%s: lightmap against the regathered one %.3g before the edit, %.3g at the next update "
                  "(%d AIM surfaces refreshed at once, %.1f ms)\n", what, was, at_once, st.aim_surfaces_at_once,
                  st.ms_aim);
    assert_true(was > 0.1);
    assert_true(at_once < most * was);
    free(now), free(want);
}

static void test_added_light_at_once(void **state)
{
    (void)state;
    settled_room r;
    settle(&r, &LAMP, 1);
    lit_at_once(&r, add_bright_spot(&r), "spot added", 0.1);
    unsettle(&r);
}

static void test_switched_on_at_once(void **state)
{
    (void)state;
    const lmgi_light_desc both[2] = {LAMP, SPOT};
    settled_room r;
    settle(&r, both, 2);
    edit_light(r.sc, 1, 3.0f, NULL, 0);
    lmt_updates(r.u, 3);
    free(r.before);
    r.before = lmt_iim(r.u, r.sc, &r.n);
    edit_light(r.sc, 1, 1.0f, NULL, 1);
    lit_at_once(&r, 1, "spot switched on", 0.1);
    unsettle(&r);
}

/* The block recoloured from red to blue (issue 32, item 2): at the next update the AIMs of its surfaces
 * reflect the new colour, the photons that bounced off it carry it on (reweighted), and the texels that see
 * what changed follow; the re-traced photons after bring only their own noise. */
static void test_recolour_at_once(void **state)
{
    (void)state;
    settled_room r;
    settle(&r, &LAMP, 1);
    size_t n = r.n;
    lmgi_material m;
    lmgi_error e;
    assert_int_equal(lmgi_get_material(r.sc, 1, &m, &e), LMGI_OK);
    m.base_color[0] = 0.1f, m.base_color[1] = 0.2f, m.base_color[2] = 0.8f;
    assert_int_equal(lmgi_set_material(r.sc, 1, &m, &e), LMGI_OK);
    lmt_updates(r.u, 1);
    float *now = lmt_iim(r.u, r.sc, &n);
    lmt_bake(r.u, NULL);
    float *want = lmt_iim(r.u, r.sc, &n);
    double was = lmt_relative_l1(r.before, want, n), at_once = lmt_relative_l1(now, want, n);
    print_message("block recoloured: lightmap against the regathered one %.3g before the edit, %.3g at the next "
                  "update\n", was, at_once);
    assert_true(was > 0.02);
    assert_true(at_once < 0.25 * was); /* 0.125; the first order alone, without the reweighting, 0.71 */
    free(now), free(want);
    unsettle(&r);
}

/* The room lit by its block alone, an emitter: its emission dimmed and tinted shows at the next update
 * as a fresh updater of the edited room shows it (issue 32, item 2: an emitter's emission changed). Its
 * photons keep their paths (one material: the choice of triangle stays), their hits are scaled, and the
 * gathers before see the old emission. */
static void test_emission_at_once(void **state)
{
    (void)state;
    static const lmgi_material_desc glow = {.name = "glow", .base_color = {0.6f, 0.6f, 0.6f, 1.0f},
                                            .emissive = {2.0f, 1.8f, 1.5f}};
    lmt_room_spec spec = {.block = &glow};
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = lmt_room(&spec);
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    lmt_updates(u, 3);
    size_t n;
    float *before = lmt_iim(u, sc, &n);
    lmgi_material m;
    lmgi_error e;
    assert_int_equal(lmgi_get_material(sc, 1, &m, &e), LMGI_OK);
    m.emissive[0] *= 0.3f, m.emissive[1] *= 0.5f, m.emissive[2] *= 0.9f;
    assert_int_equal(lmgi_set_material(sc, 1, &m, &e), LMGI_OK);
    update_scaling(u, 1, 0);
    float *now = lmt_iim(u, sc, &n);
    lmgi_updater_free(u);
    u = lmt_room_updater(ctx, sc);
    lmt_updates(u, 3);
    float *want = lmt_iim(u, sc, &n);
    double was = lmt_relative_l1(before, want, n), at_once = lmt_relative_l1(now, want, n);
    print_message("glowing block dimmed and tinted: lightmap against a fresh updater's %.3g before the edit, %.3g "
                  "at the next update\n", was, at_once);
    assert_true(was > 0.3);
    assert_true(at_once < 1e-4);
    free(before), free(now), free(want);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* One update at budget_ms (0: none), which must succeed; its stats. */
static lmgi_update_stats one_update(lmgi_updater *u, float budget_ms)
{
    lmgi_update_stats st;
    lmgi_error e;
    assert_int_equal(lmgi_update(u, 0.0f, budget_ms, &st, &e), LMGI_OK);
    return st;
}

/* n updates at budget_ms (0: none); the rays the light edits' texel factors cast over them, and the first
 * update's stats in *first when given. */
static uint64_t budgeted_updates(lmgi_updater *u, float budget_ms, int n, lmgi_update_stats *first)
{
    uint64_t rays = 0;
    for (int i = 0; i < n; i++) {
        lmgi_update_stats st = one_update(u, budget_ms);
        rays += st.light_scale_rays;
        if (i == 0 && first)
            *first = st;
    }
    return rays;
}

/* Under a time budget (issue 32, item 4) the lamp dimmed and tinted: the edit's update does not refresh
 * the AIMs at once but scales them as their hits were scaled, and its texel factors are a first guess
 * within the budget that the next updates refine; lit by one lamp, every factor is the lamp's, so the
 * next update's lightmap is already a fresh updater's, and stays so while the refinement runs. */
static void test_one_light_within_budget(void **state)
{
    (void)state;
    settled_room r;
    settle(&r, &LAMP, 1);
    size_t n = r.n;
    budgeted_updates(r.u, 4.0f, 3, NULL); /* the cost models learn this machine */
    const float tint[3] = {0.4f, 0.9f, 1.0f};
    edit_light(r.sc, 0, 0.3f, tint, 1);
    lmgi_update_stats st;
    budgeted_updates(r.u, 4.0f, 1, &st);
    float *now = lmt_iim(r.u, r.sc, &n);
    uint64_t refined = budgeted_updates(r.u, 4.0f, 60, NULL);
    float *later = lmt_iim(r.u, r.sc, &n);
    lmgi_updater_free(r.u);
    r.u = lmt_room_updater(r.ctx, r.sc); /* a fresh one, of the edited room */
    lmt_updates(r.u, 3);
    float *want = lmt_iim(r.u, r.sc, &n);
    double was = lmt_relative_l1(r.before, want, n), at_once = lmt_relative_l1(now, want, n);
    double after = lmt_relative_l1(later, want, n);
    print_message("4 ms budget, one lamp dimmed and tinted: %d AIMs refreshed at once, a first guess of %u rays "
                  "in %.2f ms, %llu rays of refinement after; lightmap against a fresh updater's %.3g before, %.3g "
                  "at the next update, %.3g 60 updates later\n",
                  st.aim_surfaces_at_once, st.light_scale_rays, st.ms_light_scale, (unsigned long long)refined,
                  was, at_once, after);
    assert_int_equal(st.lights_scaled, 1);
    assert_int_equal(st.aim_surfaces_at_once, 0);
    assert_true(st.light_scale_rays > 0 && refined > 0);
    assert_true(was > 0.5);
    assert_true(at_once < 1e-4);
    assert_true(after < 1e-4);
    free(now), free(later), free(want);
    unsettle(&r);
}

/* Five more updates within 4 ms, whose refinement's rays are returned (the budget bounds them, so how far
 * they get depends on the machine), then 60 without a budget: the first of those finishes the refinement
 * at once, and the refreshes and regathers go at the fixed counts, the same on any machine. */
static uint64_t finish_refinement(lmgi_updater *u)
{
    uint64_t within = budgeted_updates(u, 4.0f, 5, NULL);
    budgeted_updates(u, 0.0f, 60, NULL);
    lmgi_update_stats st;
    budgeted_updates(u, 0.0f, 1, &st);
    assert_int_equal(st.light_scale_rays, 0); /* nothing left to refine */
    return within;
}

/* The edit's update within 4 ms (its stats into *st), then the refinement finished (finish_refinement),
 * then a bake: the relative L1 distances from the baked lightmap of r->before, of the lightmap at the
 * edit's update and of the one once refined. Returns the refinement's rays within the budget. */
static uint64_t refined_then_regathered(settled_room *r, lmgi_update_stats *st, double *was, double *at_once,
                                        double *after)
{
    size_t n = r->n;
    budgeted_updates(r->u, 4.0f, 1, st);
    float *now = lmt_iim(r->u, r->sc, &n);
    uint64_t refined = finish_refinement(r->u);
    float *later = lmt_iim(r->u, r->sc, &n);
    lmt_bake(r->u, NULL);
    float *want = lmt_iim(r->u, r->sc, &n);
    *was = lmt_relative_l1(r->before, want, n);
    *at_once = lmt_relative_l1(now, want, n);
    *after = lmt_relative_l1(later, want, n);
    free(now), free(later), free(want);
    return refined;
}

/* refined_then_regathered, its figures printed for the edit `what`. */
static uint64_t edit_within_budget(settled_room *r, const char *what, lmgi_update_stats *st, double *was,
                                   double *at_once, double *after)
{
    uint64_t refined = refined_then_regathered(r, st, was, at_once, after);
    print_message("4 ms budget, %s: %d AIMs at once, %.2f ms; against the regathered lightmap %.3g before, %.3g at "
                  "the next update, %.3g once refined (%llu rays within the budget)\n", what,
                  st->aim_surfaces_at_once, st->ms_total, *was, *at_once, *after, (unsigned long long)refined);
    return refined;
}

/* The block recoloured under a time budget: its AIM scaled by the colour's ratio at once, the surfaces
 * its reweighted photons reach by how much their hits' flux changed, the texel factors a first guess; the
 * refinement and the refreshes after (finish_refinement) then bring the lightmap under a quarter of the
 * change from the regathered one. */
static void test_recolour_within_budget(void **state)
{
    (void)state;
    settled_room r;
    settle(&r, &LAMP, 1);
    budgeted_updates(r.u, 4.0f, 3, NULL);
    lmgi_material m;
    lmgi_error e;
    assert_int_equal(lmgi_get_material(r.sc, 1, &m, &e), LMGI_OK);
    m.base_color[0] = 0.1f, m.base_color[1] = 0.2f, m.base_color[2] = 0.8f;
    assert_int_equal(lmgi_set_material(r.sc, 1, &m, &e), LMGI_OK);
    lmgi_update_stats st;
    double was, at_once, after;
    assert_true(refined_then_regathered(&r, &st, &was, &at_once, &after) > 0);
    print_message("4 ms budget, block recoloured: %d AIMs refreshed at once, a first guess of %u rays; lightmap "
                  "against the regathered one %.3g before the edit, %.3g at the next update, %.3g once refined\n",
                  st.aim_surfaces_at_once, st.light_scale_rays, was, at_once, after);
    assert_int_equal(st.aim_surfaces_at_once, 0);
    assert_true(was > 0.02);
    assert_true(at_once < 0.5 * was);
    assert_true(after < 0.25 * was);
    unsettle(&r);
}

/* The room's only lamp switched off, then on again: nothing lit the room in between, so no factor can
 * bring its light back (0 times anything); each texel takes the change its two gathers saw, added
 * (update/light_scale.h, LM_LIGHT_SCALE_DARK), and under a budget the AIMs the lamp alone lights are
 * refreshed at once (none could be scaled). Before, the lightmap stayed black at the next update and took
 * 90 updates of regathers to come back. */
static void dark_room_switched_on(float budget_ms, double most)
{
    settled_room r;
    settle(&r, &LAMP, 1);
    size_t n = r.n;
    edit_light(r.sc, 0, 1.0f, NULL, 0);
    budgeted_updates(r.u, budget_ms, 3, NULL);
    float *dark = lmt_iim(r.u, r.sc, &n);
    edit_light(r.sc, 0, 1.0f, NULL, 1);
    lmgi_update_stats st;
    budgeted_updates(r.u, budget_ms, 1, &st);
    float *now = lmt_iim(r.u, r.sc, &n);
    lmt_bake(r.u, NULL);
    float *want = lmt_iim(r.u, r.sc, &n);
    double off = lmt_relative_l1(dark, want, n), at_once = lmt_relative_l1(now, want, n);
    print_message("the room's only lamp switched on again, budget %.0f ms: lightmap against the regathered one "
                  "%.3g while it was off, %.3g at the next update (%d AIMs at once)\n", budget_ms, off, at_once,
                  st.aim_surfaces_at_once);
    assert_int_equal(st.lights_lit, 1);
    assert_true(st.aim_surfaces_at_once > 0);
    assert_true(off > 0.5);
    assert_true(at_once < most);
    free(dark), free(now), free(want);
    unsettle(&r);
}

static void test_dark_room_switched_on(void **state)
{
    (void)state;
    dark_room_switched_on(0.0f, 0.1);
    dark_room_switched_on(4.0f, 0.2);
}

/* The spot added to the lamp-lit room under a 4 ms budget: the edit's update still traces its photons
 * (lights_lit; their cost is the edit's, like a power edit's first guess), scales the AIMs that had
 * light by how much their hits' flux grew instead of refreshing them at once, and shows the IIM's first
 * guess; the refinement and the budgeted refreshes then bring it to the regathered lightmap. Before, its
 * groups waited in the re-trace queue and the lightmap at the next update was where it had been. */
static void test_added_light_within_budget(void **state)
{
    (void)state;
    settled_room r;
    settle(&r, &LAMP, 1);
    budgeted_updates(r.u, 4.0f, 3, NULL);
    add_bright_spot(&r);
    lmgi_update_stats st;
    double was, at_once, after;
    edit_within_budget(&r, "spot added", &st, &was, &at_once, &after);
    assert_int_equal(st.lights_lit, 1);
    assert_int_equal(st.aim_surfaces_at_once, 0);
    assert_true(at_once < 0.5 * was); /* 0.33: the scaled AIMs are a guess where the spot lights other places */
    assert_true(after < 0.05 * was);
    unsettle(&r);
}

/* Lit by the lamp and the spot, the lamp dimmed under a time budget: each surface's AIM is scaled by how
 * much its hits' flux changed (a guess where both lights reach it, which the refreshes after replace),
 * and the texel factors are a first guess refined over the updates after (finish_refinement); then the
 * lightmap is nearer the regathered one than the full quality at once brings it without a budget
 * (test_two_lights_first_guess: under 0.015 of the change). */
static void test_two_lights_within_budget(void **state)
{
    (void)state;
    const lmgi_light_desc both[2] = {LAMP, SPOT};
    settled_room r;
    settle(&r, both, 2);
    budgeted_updates(r.u, 4.0f, 3, NULL);
    edit_light(r.sc, 0, 0.25f, NULL, 1);
    lmgi_update_stats st;
    double was, at_once, after;
    uint64_t refined = edit_within_budget(&r, "lamp dimmed beside the spot", &st, &was, &at_once, &after);
    assert_int_equal(st.aim_surfaces_at_once, 0);
    assert_true(refined > 0);
    assert_true(at_once < 0.2 * was);
    assert_true(after < 0.015 * was);
    unsettle(&r);
}

/* The shared sunlit room at 1,800 texels, settled, its cost models taught a 4 ms budget (skips the test
 * where ../shared is absent). Its AIMs compute the sun's direct light, the photons bring the rest. */
static int sunlit_room(settled_room *r)
{
    const char *path = lmt_shared_scene("occlusion-room/room_lit.glb");
    if (!path) {
        print_message("skipped: scene not found (occlusion-room/room_lit.glb)\n");
        return 0;
    }
    *r = (settled_room){.ctx = lmt_context(), .sc = lmt_load(path, 1800)};
    r->u = lmt_room_updater(r->ctx, r->sc);
    lmt_updates(r->u, 3);
    r->before = lmt_iim(r->u, r->sc, &r->n);
    budgeted_updates(r->u, 4.0f, 3, NULL);
    return 1;
}

/* The sunlit room under a time budget, its lamp dimmed: the edit's update scales each AIM's rest, the part
 * its photons bring, by how much the flux of the hits its estimate sums changed, and keeps the sun's part
 * (lm_aim_scale_surfaces), where it refreshed 468 AIMs at once, 25 ms of the update. The lightmap at the
 * next update is within 2% of the change from the regathered one, and once refined within 0.2%. */
static void test_sunlit_lamp_within_budget(void **state)
{
    (void)state;
    settled_room r;
    if (!sunlit_room(&r))
        skip();
    edit_light(r.sc, lmt_light_on_node(r.sc, "RoomLight"), 0.3f, NULL, 1);
    lmgi_update_stats st;
    double was, at_once, after;
    edit_within_budget(&r, "the sunlit room's lamp dimmed", &st, &was, &at_once, &after);
    assert_int_equal(st.lights_scaled, 1);
    assert_int_equal(st.aim_surfaces_at_once, 0);
    assert_true(was > 0.5);
    assert_true(at_once < 0.03 * was);
    assert_true(after < 0.005 * was);
    unsettle(&r);
}

/* The sunlit room's glass recoloured under a time budget: the surfaces its reweighted photons reach scale
 * their AIM's rest, the sun's part kept (a bounce moves no first hit), where 370 were refreshed at once. */
static void test_sunlit_recolour_within_budget(void **state)
{
    (void)state;
    settled_room r;
    if (!sunlit_room(&r))
        skip();
    int glass = lmt_material_named(r.sc, "Glass");
    lmgi_material m;
    lmgi_error e;
    assert_int_equal(lmgi_get_material(r.sc, glass, &m, &e), LMGI_OK);
    m.base_color[0] = 0.8f, m.base_color[1] = 0.3f, m.base_color[2] = 0.05f;
    assert_int_equal(lmgi_set_material(r.sc, glass, &m, &e), LMGI_OK);
    lmgi_update_stats st;
    double was, at_once, after;
    edit_within_budget(&r, "the sunlit room's glass recoloured", &st, &was, &at_once, &after);
    assert_int_equal(st.aim_surfaces_at_once, 0);
    assert_true(was > 0.02);
    assert_true(at_once < 0.5 * was);
    assert_true(after < 0.25 * was);
    unsettle(&r);
}

/* n updates at budget_ms: the mean texels_budget, and into *idle (may be NULL) how many were allowed a
 * single texel and yet took under half the budget, and into *longest the longest update's milliseconds. */
static double texel_budgets(lmgi_updater *u, float budget_ms, int n, int *idle, double *longest)
{
    double sum = 0.0;
    *longest = 0.0;
    for (int i = 0; i < n; i++) {
        lmgi_update_stats st = one_update(u, budget_ms);
        sum += st.texels_budget;
        *longest = fmax(*longest, st.ms_total);
        if (idle)
            *idle += st.texels_budget <= 1 && st.ms_total < 0.5 * budget_ms;
    }
    return sum / n;
}

#define LIT_BUDGET_MS 8.0f /* test_budget_after_lit_light's */

/* One play of the lamp switched off and on again under LIT_BUDGET_MS: the updates after it that were
 * allowed one texel and took under half the budget; *quiet, the longest still update before the edit. */
static int idle_after_lit_light(double *quiet)
{
    settled_room r = {.ctx = lmt_context(), .sc = lmt_load(lmt_project_scene("cornell.glb"), 1800)};
    lmgi_error e;
    assert_int_equal(lmgi_updater_create(r.ctx, r.sc, NULL, &r.u, &e), LMGI_OK);
    const float budget = LIT_BUDGET_MS;
    double longest;
    texel_budgets(r.u, budget, 40, NULL, &longest); /* the cost models learn this machine */
    double before = texel_budgets(r.u, budget, 10, NULL, quiet);
    edit_light(r.sc, 0, 1.0f, NULL, 0);
    double off = texel_budgets(r.u, budget, 5, NULL, &longest);
    edit_light(r.sc, 0, 1.0f, NULL, 1);
    int idle = 0;
    double after = texel_budgets(r.u, budget, 30, &idle, &longest);
    print_message("%.0f ms budget: %.1f texels an update before (the longest update %.1f ms), %.1f while the lamp "
                  "was off, %.1f in the 30 updates after it was switched on again, of which %d were allowed one "
                  "texel and took under half the budget\n", budget, before, *quiet, off, after, idle);
    unsettle(&r);
    return idle;
}

/* Under a time budget, the work an edit does at once in its own update (the lamp's photons traced as it
 * is switched on again, the AIMs it alone lights refreshed: 40 ms and more), and the burst of caustic
 * photons after it, are not what the updates after must leave room for: counted into the gather's rest
 * (update/budget_plan.h), three such updates in the cost model's window made its 95th percentile pass the
 * budget, and for the next 30 updates the gather was allowed one texel and the light edit's refinement
 * 16 rays while each update took 1.5 to 4 ms of the 8 (the first guess's blocks stayed on screen). The
 * scene has caustics: after the lamp was switched on, their photons, priced while it was dark, took 16 ms
 * of a 2 ms plan. */
static void test_budget_after_lit_light(void **state)
{
    (void)state;
    double quiet;
    int idle = idle_after_lit_light(&quiet);
    /* 26 before, on a quiet machine; 0 to 2 now, and up to 14 beside another test suite, whose load makes
     * the gather's price per texel jump for a few updates. Such jumps count into the gather's rest, whose
     * 95th percentile then starves the gather for up to LM_COST_WINDOW updates: 22 in CI beside
     * test_frame_check, 2 binaries at a time. Played again, a burst of load seldom comes twice; the edit's
     * work counted into the rest would. */
    const double busy = 0.5 * LIT_BUDGET_MS; /* a still scene's update took half the budget: others share
                                              * this machine */
    if (idle >= 20 && quiet <= busy) {
        print_message("played again: a burst of load, or the edit's work in the gather's rest?\n");
        idle = idle_after_lit_light(&quiet);
    }
    if (quiet > busy)
        print_message("skipped: the machine is busy\n");
    else
        assert_true(idle < 20);
}

/* The two rooms at `run`'s defaults (3,000 texels), room A lit by light_a1 and light_a2 in shares that differ
 * from surface to surface, light_a2 removed (issue 32, item 6). The first guess's factor per texel is the
 * ratio of a few rays' gathers summed over 3 x 3 texels: on a face that light_a2 lit to 80% it was off by up
 * to 21% per texel, 6.5% over the face, and with the surfaces' order busy elsewhere the face stayed so for
 * 75 updates. Each factor's doubt (update/light_scale.h) sends the texels most in doubt ahead
 * (texel_change.h, lm_texel_change_doubt): against a fresh updater of the edited rooms the worst surface is
 * within 5% in 30 updates. */
static void test_removed_light_doubted_first(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 3000;
    lmgi_scene *sc = NULL, *edited = NULL;
    lmgi_error e;
    if (lmgi_load(lmt_project_scene("two_rooms.glb"), &o, &sc, &e) != LMGI_OK ||
        lmgi_load(lmt_project_scene("two_rooms.glb"), &o, &edited, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    assert_int_equal(lmgi_remove_light(edited, lmt_light_on_node(edited, "light_a2"), &e), LMGI_OK);
    lmgi_updater *fresh = lmt_updater(ctx, edited), *u = lmt_updater(ctx, sc); /* the defaults */
    size_t n;
    float *want = lmt_iim(fresh, edited, &n);
    lmt_updates(u, 5);
    assert_int_equal(lmgi_remove_light(sc, lmt_light_on_node(sc, "light_a2"), &e), LMGI_OK);
    enum { UPDATES = 40 };
    double first = 0.0, last = 0.0;
    int within = lmt_worst_surface_lag(u, sc, want, UPDATES, &first, &last);
    print_message("light_a2 removed, 20 texels an update: the worst surface %.3f off a fresh updater's at the next "
                  "update, within 5%% from update %d on, %.3f after %d\n", first, within, last, UPDATES);
    assert_true(first > 0.05);
    assert_true(within > 0 && within <= 30);
    free(want);
    lmgi_updater_free(u);
    lmgi_updater_free(fresh);
    lmgi_free(sc);
    lmgi_free(edited);
    lmgi_context_free(ctx);
}

static void widen_cone(lmgi_scene *sc)
{
    lmgi_light l;
    lmgi_error e;
    assert_int_equal(lmgi_get_light(sc, 0, &l, &e), LMGI_OK);
    l.outer_cone += 0.05f;
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
}

/* A spot light's cone widened after still updates: a change of its shape, so all its photon groups are
 * traced again, and in one go (photon_stage.c, catch_up; tests/test_motion_trail.c holds the same for a
 * moved node), not 16 an update. Widened again in every update after, it keeps to those 16. */
static void test_reshaped_light_caught_up(void **state)
{
    (void)state;
    static const lmgi_light_desc spot = {.name = "spot", .type = LMGI_LIGHT_SPOT, .intensity = 30.0f,
                                         .outer_cone = 0.5f, .position = {0.0f, 2.8f, 0.0f},
                                         .direction = {0.0f, -1.0f, 0.0f}};
    lmt_room_spec spec = {.lights = &spot, .light_count = 1};
    lmgi_scene *sc = lmt_room(&spec);
    lmgi_context *ctx = lmt_context();
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    lmt_updates(u, 3);
    widen_cone(sc);
    lmgi_update_stats w[2] = {lmt_update(u), lmt_update(u)};
    print_message("a spot's cone widened after still updates: %u groups re-traced at once, then %u\n",
                  w[0].groups_at_once, w[1].groups_retraced);
    assert_true(w[0].groups_at_once > 16); /* 72 measured: all of its groups */
    assert_int_equal(w[1].groups_retraced, 0);
    for (int f = 0; f < 6; f++) { /* widened at every update: the first is caught up, the rest are not */
        widen_cone(sc);
        lmgi_update_stats s = lmt_update(u);
        if (f > 0) {
            assert_int_equal(s.groups_at_once, 0);
            assert_true(s.groups_retraced <= 16);
        }
    }
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_add_and_remove),
        cmocka_unit_test(test_first_light),
        cmocka_unit_test(test_no_light_no_gather),
        cmocka_unit_test(test_still_room_traces_nothing),
        cmocka_unit_test(test_still_level_bases_at_first_edit),
        cmocka_unit_test(test_added_light_stays_in_its_room),
        cmocka_unit_test(test_one_light_at_once),
        cmocka_unit_test(test_one_light_brightened),
        cmocka_unit_test(test_large_atlas_at_once),
        cmocka_unit_test(test_two_lights_first_guess),
        cmocka_unit_test(test_switched_off),
        cmocka_unit_test(test_removed_light_doubted_first),
        cmocka_unit_test(test_reshaped_light_caught_up),
        cmocka_unit_test(test_added_light_at_once),
        cmocka_unit_test(test_switched_on_at_once),
        cmocka_unit_test(test_dark_room_switched_on),
        cmocka_unit_test(test_recolour_at_once),
        cmocka_unit_test(test_emission_at_once),
        cmocka_unit_test(test_one_light_within_budget),
        cmocka_unit_test(test_recolour_within_budget),
        cmocka_unit_test(test_two_lights_within_budget),
        cmocka_unit_test(test_sunlit_lamp_within_budget),
        cmocka_unit_test(test_sunlit_recolour_within_budget),
        cmocka_unit_test(test_added_light_within_budget),
        cmocka_unit_test(test_budget_after_lit_light),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
