/* photons: selective photon emission (Larsen & Christensen 2004, section 2). Deterministic traces,
 * no invalidation in an unchanged scene, locality of invalidation (two rooms and a door), energy of
 * first hits, emitter invalidation drained oldest first, and moving an object back restoring the hits. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/core/timing.h"
#include "../src/scene/moved_nodes.h"
#include "../src/trace/photons.h"
#include "../src/trace/photons_internal.h"
#include "support.h"

typedef struct {
    lm_scene *s;
    lm_surfaces su;
    lm_rt *rt;
    lm_emitters em;
    lm_photons *ph;
} world;

static void world_load(world *w, const char *path)
{
    memset(w, 0, sizeof *w);
    lm_error err;
    lm_load_options lo = {0};
    if (lm_scene_load_gltf(path, &lo, &w->s, &err) != LM_OK)
        fail_msg("load: %s", err.msg);
    lm_surface_options so;
    lm_surface_options_default(&so);
    assert_int_equal(lm_surfaces_build(w->s, &so, &w->su, &err), LM_OK);
    assert_int_equal(lm_rt_build(w->s, &w->su, &w->rt, &err), LM_OK);
    assert_int_equal(lm_emitters_build(w->s, &w->em, &err), LM_OK);
}

/* The scene's photons with settings set, traced once (the trace's stats in *st when st is not NULL). */
static void world_photons_stats(world *w, const lm_photon_settings *set, lm_photon_frame_stats *st)
{
    lm_error err;
    if (lm_photons_create(w->s, &w->su, w->rt, &w->em, set, &w->ph, &err) != LM_OK)
        fail_msg("photons: %s", err.msg);
    assert_int_equal(lm_photons_trace_all(w->ph, st, &err), LM_OK);
}

static void world_photons(world *w, const lm_photon_settings *set) { world_photons_stats(w, set, NULL); }

/* Photons of `total` over the scene, traced once (stats in *st). */
static void world_trace(world *w, uint32_t total, lm_photon_frame_stats *st)
{
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    set.total_photons = total;
    world_photons_stats(w, &set, st);
}

static void world_free(world *w)
{
    lm_photons_free(w->ph);
    lm_emitters_free(&w->em);
    lm_rt_free(w->rt);
    lm_surfaces_free(&w->su);
    lm_scene_free(w->s);
}

static int find_node(const lm_scene *s, const char *name)
{
    for (int i = 0; i < s->node_count; i++)
        if (!strcmp(s->nodes[i].name, name))
            return i;
    fail_msg("no node '%s'", name);
    return -1;
}

static int find_anim(const lm_scene *s, const char *name)
{
    for (int i = 0; i < s->animation_count; i++)
        if (!strcmp(s->animations[i].name, name))
            return i;
    fail_msg("no animation '%s'", name);
    return -1;
}

/* Sets animation `anim` to time t and moves the BVH along. */
static void animate(world *w, int anim, float t)
{
    lm_error err;
    lm_scene_eval_animation(w->s, anim, t);
    assert_int_equal(lm_rt_sync_transforms(w->rt, w->s, &err), LM_OK);
}

static lm_photon_frame_stats frame(world *w)
{
    lm_photon_frame_stats st;
    lm_error err;
    if (lm_photons_frame(w->ph, 1, &st, &err) != LM_OK)
        fail_msg("frame: %s", err.msg);
    return st;
}

/* ---- hit snapshots: every live hit, links cleared, sorted by (surface, photon, bounce) ---- */

typedef struct {
    lm_hit *h;
    uint32_t n;
} snapshot;

static int hit_order(const void *pa, const void *pb)
{
    const lm_hit *a = pa, *b = pb;
    if (a->surface != b->surface)
        return a->surface < b->surface ? -1 : 1;
    if (a->photon != b->photon)
        return a->photon < b->photon ? -1 : 1;
    return (a->bounce > b->bounce) - (a->bounce < b->bounce);
}

static snapshot take_snapshot(const lm_photons *ph)
{
    const lm_photon_store *ps = lm_photons_store(ph);
    snapshot sn = {malloc(sizeof(lm_hit) * (lm_photons_stored_hits(ph) + 1)), 0};
    assert_non_null(sn.h);
    for (int s = 0; s < ps->surface_count; s++)
        for (uint32_t k = 0; k < ps->surfaces[s].count; k++) {
            lm_hit h = ps->hits[ps->surfaces[s].slots[k]];
            h.at = h.next = 0;
            sn.h[sn.n++] = h;
        }
    assert_int_equal(sn.n, lm_photons_stored_hits(ph));
    qsort(sn.h, sn.n, sizeof *sn.h, hit_order);
    return sn;
}

static void assert_same_snapshot(const snapshot *a, const snapshot *b)
{
    assert_int_equal(a->n, b->n);
    assert_memory_equal(a->h, b->h, sizeof(lm_hit) * a->n);
}

/* ---- determinism ---- */

static void test_deterministic(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    world a, b;
    world_load(&a, path);
    world_photons(&a, &set);
    int threads = omp_get_max_threads();
    omp_set_num_threads(1); /* the second run single-threaded: results must not depend on threads */
    world_load(&b, path);
    world_photons(&b, &set);
    omp_set_num_threads(threads);
    assert_int_equal(lm_photons_count(a.ph), LM_PHOTONS_MIN_TOTAL); /* one light: the scene's floor, 72 x 640 */
    assert_true(lm_photons_stored_hits(a.ph) > lm_photons_count(a.ph)); /* a closed-ish box: > 1 hit each */
    snapshot sa = take_snapshot(a.ph), sb = take_snapshot(b.ph);
    assert_same_snapshot(&sa, &sb);

    /* 1000 frames of an unchanged scene: nothing differs, nothing is invalidated, no store churn. */
    uint32_t rr = 0;
    double seconds = 0.0;
    for (int f = 0; f < 1000; f++) {
        lm_photon_frame_stats st = frame(&a);
        seconds += st.seconds;
        assert_int_equal(st.paths_changed, 0);
        assert_int_equal(st.groups_invalidated, 0);
        assert_int_equal(st.groups_retraced, 0);
        assert_int_equal(st.hits_added + st.hits_removed, 0);
        rr += st.rr_photons;
    }
    assert_int_equal(rr, 1000 * 72);
    print_message("unchanged frame: %u photons checked in %.4f ms (mean of 1000)\n", rr / 1000, seconds);
    snapshot sc = take_snapshot(a.ph);
    assert_same_snapshot(&sa, &sc);
    free(sa.h);
    free(sb.h);
    free(sc.h);
    world_free(&a);
    world_free(&b);
}

/* A light removed for good: its removal's re-trace empties its groups (its hits leave the store), then
 * lm_photons_release_emitter gives back its paths' memory (waiting groups counted until then); no other
 * light's hit changes, and a later full trace keeps it empty. */
static void test_release_removed_light(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    world w;
    world_load(&w, path);
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    world_photons(&w, &set);
    lm_photon_memory before, after;
    lm_photons_memory(w.ph, &before);
    uint32_t photons = lm_photons_emitter_photons(w.ph, 1);
    assert_true(photons > 0);
    int light = w.em.e[1].light;
    w.s->lights[light].removed = 1;
    lm_emitters_update(&w.em, w.s);
    lm_error err;
    assert_int_equal(lm_photons_invalidate_emitter(w.ph, 1, &err), LM_OK);
    assert_int_equal(lm_photons_release_emitter(w.ph, 1), lm_photons_groups_per_emitter(w.ph)); /* all wait */
    while (lm_photons_pending_groups(w.ph))
        frame(&w);
    snapshot mid = take_snapshot(w.ph);
    assert_int_equal(lm_photons_release_emitter(w.ph, 1), 0);
    assert_int_equal(lm_photons_release_emitter(w.ph, 1), 0); /* again: nothing left to give back */
    lm_photons_memory(w.ph, &after);
    print_message("light %d removed: its %u photons' paths given back, %zu -> %zu bytes of paths\n", light, photons,
                  before.path_bytes, after.path_bytes);
    assert_true(after.path_bytes + (size_t)photons * 20 <= before.path_bytes); /* 4 of offset + 16 of numbers */
    for (uint32_t i = 0; i < mid.n; i++)
        assert_true(lm_photons_group_of(w.ph, mid.h[i].photon) / lm_photons_groups_per_emitter(w.ph) != 1);
    for (int f = 0; f < 5; f++) /* the round robin passes over it */
        frame(&w);
    lm_error e2;
    assert_int_equal(lm_photons_trace_all(w.ph, NULL, &e2), LM_OK);
    snapshot end = take_snapshot(w.ph);
    assert_same_snapshot(&mid, &end);
    free(mid.h);
    free(end.h);
    world_free(&w);
}

/* ---- a trace shared among processes (lm_photon_split), the processes played by threads ---- */

#define SHARES 3

typedef struct {
    lmt_hub *h;
    uint32_t id;
    const char *path;
    world w;
} process;

static int hub_exchange(void *user, const void *mine, size_t size, size_t *sizes, void *all)
{
    process *p = user;
    return lmt_hub_exchange(p->h, (int)p->id, mine, size, sizes, all);
}

static void *process_trace(void *arg)
{
    process *p = arg;
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    lm_error err;
    if (lm_photons_create(p->w.s, &p->w.su, p->w.rt, &p->w.em, &set, &p->w.ph, &err) != LM_OK)
        return "create";
    lm_photon_split sp = {p->id, SHARES, hub_exchange, p};
    lm_photons_set_split(p->w.ph, &sp);
    return lm_photons_trace_all(p->w.ph, NULL, &err) == LM_OK ? NULL : "trace";
}

/* Three processes (threads here, one OpenMP thread each) share a full trace of the two-rooms scene: each
 * traces a third of the photons, and every one ends with the store one process makes alone, slot for
 * slot. */
static void test_split_trace_is_one_process_trace(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    world one;
    world_load(&one, path);
    world_photons(&one, &set);
    lmt_hub h;
    lmt_hub_init(&h, SHARES);
    process p[SHARES];
    pthread_t t[SHARES];
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    for (uint32_t i = 0; i < SHARES; i++) {
        p[i] = (process){&h, i, path, {0}};
        world_load(&p[i].w, path);
    }
    for (uint32_t i = 0; i < SHARES; i++)
        assert_int_equal(pthread_create(&t[i], NULL, process_trace, &p[i]), 0);
    for (uint32_t i = 0; i < SHARES; i++) {
        void *failed = NULL;
        pthread_join(t[i], &failed);
        if (failed)
            fail_msg("process %u: %s failed", i, (const char *)failed);
    }
    omp_set_num_threads(threads);
    const lm_photon_store *a = lm_photons_store(one.ph);
    snapshot sa = take_snapshot(one.ph);
    for (uint32_t i = 0; i < SHARES; i++) {
        const lm_photon_store *b = lm_photons_store(p[i].w.ph);
        assert_int_equal(b->used, a->used);
        assert_memory_equal(b->hits, a->hits, sizeof *a->hits * a->used); /* slot for slot */
        snapshot sb = take_snapshot(p[i].w.ph);
        assert_same_snapshot(&sa, &sb);
        free(sb.h);
        assert_int_equal(h.calls[i], h.calls[0]);
    }
    /* two calls a batch of at most 16,384 photons */
    assert_true(h.calls[0] >= 2 * (int)((lm_photons_count(one.ph) + 16383) / 16384));
    print_message("%u photons, %u stored hits, traced by %d processes in %d exchanges\n", lm_photons_count(one.ph),
                  lm_photons_stored_hits(one.ph), SHARES, h.calls[0]);
    free(sa.h);
    lmt_hub_free(&h);
    for (uint32_t i = 0; i < SHARES; i++)
        world_free(&p[i].w);
    world_free(&one);
}

/* Each group's photons share one cell of the 8 x 9 stratification of the first two QMC coordinates:
 * their first directions from a point light stay close (the cell spans 1/8 of cos theta, 40 degrees
 * of phi), so first-hit points cluster. Checked on the group's first-vertex direction spread. */
static void test_groups_are_coherent(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    world w;
    world_load(&w, path);
    world_photons(&w, &set);
    float lp[3];
    memcpy(lp, &w.s->nodes[w.s->lights[0].node].world[12], sizeof lp);
    double worst = 1.0;
    for (uint32_t g = 0; g < lm_photons_group_count(w.ph); g++) {
        float mean[3] = {0, 0, 0}, dirs[64][3];
        uint32_t n = 0;
        for (uint32_t m = 0; m < 40; m++) {
            const lm_path_vertex *v;
            if (lm_photons_path(w.ph, g + m * 72, &v) == 0)
                continue;
            float d[3] = {v[0].pos[0] - lp[0], v[0].pos[1] - lp[1], v[0].pos[2] - lp[2]};
            float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int k = 0; k < 3; k++) {
                dirs[n][k] = d[k] / len;
                mean[k] += dirs[n][k];
            }
            assert_int_equal(lm_photons_group_of(w.ph, g + m * 72), g);
            n++;
        }
        float ml = sqrtf(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]);
        for (uint32_t i = 0; i < n; i++) {
            double c = (dirs[i][0] * mean[0] + dirs[i][1] * mean[1] + dirs[i][2] * mean[2]) / ml;
            worst = c < worst ? c : worst;
        }
    }
    print_message("widest group: %.1f degrees from its mean direction\n", acos(worst) * 180.0 / M_PI);
    assert_true(worst > cos(60.0 * M_PI / 180.0));
    world_free(&w);
}

/* ---- locality: two rooms and a door ---- */

typedef struct {
    uint32_t b_only_groups, b_only_invalidations;
    uint32_t a_light_invalidations, b_light_invalidations;
    uint32_t total_invalidations, frames, groups_retraced;
    double seconds;
} locality;

/* 1 if every stored vertex of every photon of group g lies in room B (x > 0). */
static int group_in_room_b(const lm_photons *ph, uint32_t g)
{
    uint32_t G = lm_photons_groups_per_emitter(ph);
    lm_photon_group_info gi;
    lm_photons_group_info(ph, g, &gi);
    uint32_t first = 0;
    for (int e = 0; e < gi.emitter; e++)
        first += lm_photons_emitter_photons(ph, e);
    for (uint32_t m = 0; m < gi.photons; m++) {
        const lm_path_vertex *v;
        uint32_t n = lm_photons_path(ph, first + gi.index + m * G, &v);
        for (uint32_t i = 0; i < n; i++)
            if (v[i].pos[0] <= 0.0f)
                return 0;
    }
    return 1;
}

/* Door at door_t; the cube in room A follows its animation for 4 s while frames run. */
static locality run_locality(const char *path, float door_t)
{
    world w;
    world_load(&w, path);
    animate(&w, find_anim(w.s, "door_swing"), door_t);
    int cube_anim = find_anim(w.s, "cube_path");
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    world_photons(&w, &set);
    uint32_t groups = lm_photons_group_count(w.ph);
    assert_int_equal(groups, 4 * 72);
    uint8_t *b_only = malloc(groups), *b_light = malloc(groups);
    assert_true(b_only && b_light);
    locality r;
    memset(&r, 0, sizeof r);
    for (uint32_t g = 0; g < groups; g++) {
        lm_photon_group_info gi;
        lm_photons_group_info(w.ph, g, &gi);
        b_only[g] = (uint8_t)group_in_room_b(w.ph, g);
        b_light[g] = w.s->nodes[w.em.e[gi.emitter].node].world[12] > 0.0f;
        r.b_only_groups += b_only[g];
    }
    for (int f = 1; f <= 200; f++, r.frames++) {
        animate(&w, cube_anim, 0.02f * (float)f);
        lm_photon_frame_stats st = frame(&w);
        r.total_invalidations += st.groups_invalidated;
        r.groups_retraced += st.groups_retraced;
        r.seconds += st.seconds;
    }
    for (uint32_t g = 0; g < groups; g++) {
        lm_photon_group_info gi;
        lm_photons_group_info(w.ph, g, &gi);
        if (b_only[g])
            r.b_only_invalidations += gi.invalidations;
        if (b_light[g])
            r.b_light_invalidations += gi.invalidations;
        else
            r.a_light_invalidations += gi.invalidations;
    }
    free(b_only);
    free(b_light);
    world_free(&w);
    return r;
}

static void test_locality_door_closed(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    locality r = run_locality(path, 0.0f);
    print_message("door closed, %u frames: %u invalidations (room A lights %u, room B lights %u); "
                  "%u groups entirely in room B, invalidated %u times; %u groups re-traced; %.2f ms/frame\n",
                  r.frames, r.total_invalidations, r.a_light_invalidations, r.b_light_invalidations,
                  r.b_only_groups, r.b_only_invalidations, r.groups_retraced, 1e3 * r.seconds / r.frames);
    assert_true(r.b_only_groups >= 2 * 72 - 4); /* room B's lights' photons stay in room B */
    assert_int_equal(r.b_only_invalidations, 0);
    assert_int_equal(r.b_light_invalidations, 0);
    assert_true(r.a_light_invalidations > 0);
}

static void test_locality_door_open(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    locality r = run_locality(path, 2.0f);
    print_message("door open, %u frames: %u invalidations (room A lights %u, room B lights %u); "
                  "%u groups entirely in room B, invalidated %u times; %u groups re-traced; %.2f ms/frame\n",
                  r.frames, r.total_invalidations, r.a_light_invalidations, r.b_light_invalidations,
                  r.b_only_groups, r.b_only_invalidations, r.groups_retraced, 1e3 * r.seconds / r.frames);
    assert_int_equal(r.b_only_invalidations, 0);
    assert_true(r.b_light_invalidations > 0); /* photons through the doorway meet the cube */
    assert_true(r.a_light_invalidations > r.b_light_invalidations);
}

/* ---- energy: a point light in a closed box ---- */

/* The inward unit cube with a point lamp of intensity 10 and colour `color` (a JSON array) at
 * (0.2, 0.3, -0.1), written to `file` in the temporary folder and loaded into w. */
static void load_lamp_box(world *w, const char *file, const char *color)
{
    static lmt_mesh box;
    memset(&box, 0, sizeof box);
    lmt_mesh_cube_inward(&box, 1.0f);
    const char *nodes = "[{\"name\": \"root\", \"children\": [1, 2]}, {\"name\": \"box\", \"mesh\": 0},"
                        " {\"name\": \"lamp\", \"translation\": [0.2, 0.3, -0.1],"
                        "  \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]";
    char lights[512], path[512];
    snprintf(lights, sizeof lights, "\"extensionsUsed\": [\"KHR_lights_punctual\"],"
             " \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\","
             " \"intensity\": 10, \"color\": %s}]}},", color);
    snprintf(path, sizeof path, "%s/%s", lmt_tmpdir(), file);
    assert_int_equal(lmt_write_gltf(path, &box, 1, nodes, NULL, 0, lights), 0);
    world_load(w, path);
}

/* Every path traced again with the scene as it is now, stored where any bit differs: the worst relative
 * difference per surface and channel between what the store held (`held`, lm_photon_store_surface_flux)
 * and what it holds then; the paths that differed into *differ. */
static double against_a_trace(world *w, const double *held, uint32_t *differ)
{
    const lm_photon_store *store = lm_photons_store(w->ph);
    int S = store->surface_count;
    double *traced = calloc(3 * (size_t)S, sizeof *traced), worst = 0.0;
    assert_non_null(traced);
    lm_photon_frame_stats st;
    lm_error err;
    assert_int_equal(lm_photons_trace_all_exact(w->ph, &st, &err), LM_OK);
    lm_photon_store_surface_flux(store, traced);
    for (int i = 0; i < 3 * S; i++)
        worst = fmax(worst, fabs(held[i] - traced[i]) / fmax(traced[i], 1e-12));
    *differ = st.photons_updated;
    free(traced);
    return worst;
}

/* Issue 32, item 2: a light changed in power alone keeps its photons' paths, which follow albedos and
 * never power (photon_trace.c), so scaling the flux of its stored hits (lm_photons_scale_emitter) stores
 * what tracing them again with the new colour does, up to rounding, and each surface's energy and deltas
 * follow the change. */
static void test_power_edit_scales_hits(void **state)
{
    (void)state;
    world w;
    load_lamp_box(&w, "power.gltf", "[1, 0.5, 0.25]");
    world_trace(&w, 20000, NULL);
    const lm_photon_store *store = lm_photons_store(w.ph);
    int S = store->surface_count;
    double *scaled = calloc(3 * (size_t)S, sizeof *scaled), *delta = calloc((size_t)S, sizeof *delta);
    assert_non_null(scaled);
    assert_non_null(delta);
    for (int k = 0; k < S; k++)
        delta[k] = store->surfaces[k].delta_f;
    const float by[3] = {0.3f, 1.7f, 0.45f};
    lm_error err;
    assert_int_equal(lm_photons_scale_emitter(w.ph, 0, by, &err), LM_OK);
    lm_photon_store_surface_flux(store, scaled);
    for (int k = 0; k < S; k++) { /* the energy kept as hits come and go is the hits' own, and it moved */
        double e = 0.0;
        for (uint32_t i = 0; i < store->surfaces[k].count; i++)
            e += lm_hit_energy(&store->hits[store->surfaces[k].slots[i]]);
        assert_float_equal(store->surfaces[k].energy, e, 1e-9 * e);
        assert_true(store->surfaces[k].delta_f > delta[k]);
    }
    for (int c = 0; c < 3; c++) /* the same light with that colour */
        w.s->lights[0].color[c] *= by[c];
    lm_emitters_update(&w.em, w.s);
    uint32_t differ = 0;
    double worst = against_a_trace(&w, scaled, &differ);
    print_message("power edit: hits scaled against traced again, per surface and channel worst %.2g (%u of %u "
                  "paths differ in some bit)\n", worst, differ, lm_photons_count(w.ph));
    assert_true(worst < 1e-5);
    free(scaled);
    free(delta);
    world_free(&w);
}

/* The lamp box's material (the box's, its only one) recoloured from `was` to `now` as an edit does: every
 * hit reweighted (lm_photons_scale_materials), then the colour set; touched (surface_count) marks the
 * surfaces reached. */
static void recolour_box(world *w, const float was[3], const float now[3], uint8_t *touched)
{
    int M = w->s->material_count, box = w->s->tri_material[0];
    float *ratio = malloc(3 * sizeof *ratio * (size_t)M);
    assert_non_null(ratio);
    for (int i = 0; i < 3 * M; i++)
        ratio[i] = 1.0f;
    for (int c = 0; c < 3; c++)
        ratio[3 * box + c] = now[c] / was[c];
    lm_photons_scale_materials(w->ph, ratio, M, touched);
    memcpy(w->s->materials[box].base_color, now, 3 * sizeof *now);
    free(ratio);
}

/* Issue 32, item 2: a diffuse material recoloured alone. Its photons' paths follow the albedo only through
 * the survival probability (the largest channel), so a recolour that keeps the largest channel keeps every
 * path, and reweighting the hits after each bounce off it (lm_photons_scale_materials) stores what tracing
 * them again does, up to rounding. */
static void test_recolour_reweights_hits(void **state)
{
    (void)state;
    world w;
    load_lamp_box(&w, "recolour.gltf", "[1, 1, 1]");
    lm_material *m = &w.s->materials[w.s->tri_material[0]];
    const float was[3] = {0.8f, 0.5f, 0.3f}, now[3] = {0.8f, 0.2f, 0.6f};
    memcpy(m->base_color, was, sizeof was);
    world_trace(&w, 20000, NULL);
    const lm_photon_store *store = lm_photons_store(w.ph);
    int S = store->surface_count;
    double *scaled = calloc(3 * (size_t)S, sizeof *scaled);
    uint8_t *touched = calloc((size_t)S, 1);
    assert_non_null(scaled);
    assert_non_null(touched);
    recolour_box(&w, was, now, touched);
    lm_photon_store_surface_flux(store, scaled);
    int reached = 0;
    for (int k = 0; k < S; k++)
        reached += touched[k];
    uint32_t differ = 0;
    double worst = against_a_trace(&w, scaled, &differ);
    print_message("recolour: hits reweighted against traced again, per surface and channel worst %.2g (%d of %d "
                  "surfaces reached)\n", worst, reached, S);
    assert_int_equal(reached, S);
    assert_true(worst < 1e-5);
    free(scaled), free(touched);
    world_free(&w);
}

/* A channel recoloured far down and back (0.9 -> 0.001 -> 0.9): a path that bounced k times off the
 * material had its hits scaled by 1e-3^k and then by 1e3^k, and past 1e-12 their float flux has lost its
 * digits (0 x inf: NaN in the AIMs of the two rooms' soak after 874 updates, tests/test_soak.c). Every
 * hit stays finite, the groups of such paths are queued again at once, and once traced the store holds
 * what tracing every path again does. */
static void test_recolour_far_and_back(void **state)
{
    (void)state;
    world w;
    load_lamp_box(&w, "far.gltf", "[1, 1, 1]");
    lm_material *m = &w.s->materials[w.s->tri_material[0]];
    const float was[3] = {0.9f, 0.9f, 0.9f}, low[3] = {0.9f, 0.001f, 0.9f};
    memcpy(m->base_color, was, sizeof was);
    world_trace(&w, 20000, NULL);
    const lm_photon_store *store = lm_photons_store(w.ph);
    int S = store->surface_count;
    uint8_t *touched = calloc((size_t)S, 1);
    double *held = calloc(3 * (size_t)S, sizeof *held);
    assert_non_null(touched);
    assert_non_null(held);
    assert_int_equal(lm_photons_pending_groups(w.ph), 0);
    recolour_box(&w, was, low, touched);
    recolour_box(&w, low, was, touched);
    uint32_t hits = 0;
    for (uint32_t i = 0; i < store->used; i++) {
        const lm_hit *h = lm_photon_store_live(store, i);
        if (h && !(isfinite(h->flux[0]) && isfinite(h->flux[1]) && isfinite(h->flux[2])))
            fail_msg("hit %u: flux %g %g %g after a recolour far down and back", i, (double)h->flux[0],
                     (double)h->flux[1], (double)h->flux[2]);
        hits += h != NULL;
    }
    uint32_t queued = lm_photons_pending_groups(w.ph);
    while (lm_photons_pending_groups(w.ph))
        frame(&w);
    lm_photon_store_surface_flux(store, held);
    uint32_t differ = 0;
    double worst = against_a_trace(&w, held, &differ);
    print_message("recolour far and back: %u hits finite, %u groups queued again; then against every path traced "
                  "again, per surface and channel worst %.2g\n", hits, queued, worst);
    assert_true(queued > 0);
    assert_true(worst < 1e-5);
    free(touched), free(held);
    world_free(&w);
}

static void test_energy_closed_box(void **state)
{
    (void)state;
    world w;
    load_lamp_box(&w, "box.gltf", "[1, 0.5, 0.25]");
    assert_int_equal(w.em.count, 1);
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    set.total_photons = 20000;
    world_photons(&w, &set);
    uint32_t n = lm_photons_count(w.ph);
    assert_true(n >= 19900 && n % 72 == 0);
    int surfaces = lm_photons_store(w.ph)->surface_count;
    assert_int_equal(surfaces, 6);
    double *flux = calloc((size_t)surfaces * 3, sizeof *flux), sum[3] = {0, 0, 0};
    assert_non_null(flux);
    lm_photons_first_hit_flux(w.ph, flux);
    for (int s = 0; s < surfaces; s++)
        for (int c = 0; c < 3; c++)
            sum[c] += flux[3 * s + c];
    double power = 4.0 * M_PI * 10.0;
    print_message("first-hit flux (%.4f %.4f %.4f), light power 4 pi I = (%.4f %.4f %.4f)\n", sum[0], sum[1],
                  sum[2], power, power * 0.5, power * 0.25);
    assert_float_equal(sum[0], power, 0.01 * power);
    assert_float_equal(sum[1], 0.5 * power, 0.005 * power);
    assert_float_equal(sum[2], 0.25 * power, 0.0025 * power);
    /* Every photon's first hit was stored: bounce-0 hits = photons. */
    lm_photon_memory mem;
    lm_photons_memory(w.ph, &mem);
    assert_true(mem.mean_hits > 1.0);
    free(flux);
    world_free(&w);
}

/* Each stored hit knows where its photon came from (lm_hit.travelled, for the AIM's visibility test): a
 * first hit lies that far from the lamp back along its direction, a later one that far from a wall of the
 * box it bounced off. */
static void test_hits_know_where_they_came_from(void **state)
{
    (void)state;
    world w;
    load_lamp_box(&w, "box_from.gltf", "[1, 1, 1]");
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    set.total_photons = 5000;
    world_photons(&w, &set);
    const lm_photon_store *ps = lm_photons_store(w.ph);
    const float lamp[3] = {0.2f, 0.3f, -0.1f};
    double worst_first = 0.0, worst_later = 0.0;
    uint32_t first = 0, later = 0;
    for (int s = 0; s < ps->surface_count; s++)
        for (uint32_t k = 0; k < ps->surfaces[s].count; k++) {
            const lm_hit *h = &ps->hits[ps->surfaces[s].slots[k]];
            assert_true(h->travelled > 0.0f);
            float q[3], wall = 0.0f, half = 0.0f;
            for (int c = 0; c < 3; c++) {
                q[c] = h->pos[c] - h->travelled * h->dir[c];
                wall = fmaxf(wall, fabsf(q[c]));
                half = fmaxf(half, fabsf(h->pos[c])); /* every hit lies on a wall */
            }
            if (h->bounce == 0) {
                for (int c = 0; c < 3; c++)
                    worst_first = fmax(worst_first, fabs(q[c] - lamp[c]));
                first++;
            } else {
                worst_later = fmax(worst_later, fabs(wall - half));
                later++;
            }
        }
    print_message("%u first hits: at most %.2e from the lamp; %u later ones: their previous vertex at most %.2e off "
                  "a wall\n", first, worst_first, later, worst_later);
    assert_true(first > 1000 && later > 1000);
    assert_true(worst_first < 1e-4);
    assert_true(worst_later < 1e-3);
    world_free(&w);
}

/* Russian roulette by the albedo's largest channel: no channel of a photon's flux grows at a bounce, so
 * in a closed box of saturated red (0.8 0.2 0.1) no stored hit carries more, per channel, than the
 * photon left the lamp with. (With the luminance, 0.32, as the survival the red channel grew 2.5x a
 * bounce: hits of 100 times a photon's red.) The mean of the stored red flux per bounce falls by the
 * albedo, as it should. */
static void test_no_channel_grows(void **state)
{
    (void)state;
    static lmt_mesh box;
    memset(&box, 0, sizeof box);
    lmt_mesh_cube_inward(&box, 1.0f);
    const char *nodes = "[{\"name\": \"box\", \"mesh\": 0},"
                        " {\"name\": \"lamp\", \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]";
    const char *materials = "\"extensionsUsed\": [\"KHR_lights_punctual\"],"
                            " \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\", \"intensity\": 10}]}},"
                            " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.8, 0.2, 0.1, 1],"
                            " \"metallicFactor\": 0}}],";
    char path[512];
    snprintf(path, sizeof path, "%s/red.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, &box, 1, nodes, NULL, 0, materials), 0);
    lmt_use_material_0(path);
    world w;
    world_load(&w, path);
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    set.total_photons = 20000;
    world_photons(&w, &set);
    double emitted = 4.0 * M_PI * 10.0 / lm_photons_count(w.ph), worst[3] = {0, 0, 0}, red[8] = {0};
    uint32_t count[8] = {0};
    const lm_photon_store *ps = lm_photons_store(w.ph);
    for (int k = 0; k < ps->surface_count; k++)
        for (uint32_t j = 0; j < ps->surfaces[k].count; j++) {
            const lm_hit *x = &ps->hits[ps->surfaces[k].slots[j]];
            for (int c = 0; c < 3; c++)
                worst[c] = fmax(worst[c], x->flux[c] / emitted);
            if (x->bounce < 8)
                red[x->bounce] += x->flux[0], count[x->bounce]++;
        }
    print_message("largest stored flux over a photon's: %.3f %.3f %.3f; mean red per hit by bounce: %.3f %.3f %.3f\n",
                  worst[0], worst[1], worst[2], red[0] / count[0] / emitted, red[1] / count[1] / emitted,
                  red[2] / count[2] / emitted);
    for (int c = 0; c < 3; c++)
        assert_true(worst[c] <= 1.0 + 1e-5);
    /* survivors keep the red (0.8 / 0.8): each bounce's stored red is the one before times the albedo */
    assert_float_equal(red[1] / emitted, 0.8 * red[0] / emitted, 0.03 * red[0] / emitted);
    world_free(&w);
}

/* ---- emitter invalidation: every group queued, drained oldest first under the budget ---- */

static void assert_emitter_pending(const lm_photons *ph, int e, uint32_t valid_groups)
{
    for (uint32_t g = 0; g < 72; g++) {
        lm_photon_group_info gi;
        lm_photons_group_info(ph, (uint32_t)e * 72 + g, &gi);
        assert_int_equal(gi.emitter, e);
        assert_int_equal(gi.invalid, g >= valid_groups);
    }
}

/* The scene at path traced with the default settings, 16 invalid groups re-traced a frame. */
static void queue_world(world *w, const char *path)
{
    world_load(w, path);
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    set.group_budget = 16;
    world_photons(w, &set);
}

static void test_invalidate_emitter(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    world w;
    queue_world(&w, path);
    lm_error err;
    assert_int_equal(lm_photons_invalidate_emitter(w.ph, 99, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "99"));
    assert_int_equal(lm_photons_invalidate_emitter(w.ph, 2, &err), LM_OK);
    assert_int_equal(lm_photons_invalidate_emitter(w.ph, 0, &err), LM_OK);
    assert_int_equal(lm_photons_invalidate_emitter(w.ph, 2, &err), LM_OK); /* already queued: no change */
    assert_int_equal(lm_photons_pending_groups(w.ph), 144);
    for (int f = 1; f <= 9; f++) {
        lm_photon_frame_stats st = frame(&w);
        assert_int_equal(st.groups_retraced, 16);
        assert_int_equal(st.pending_groups, 144 - 16 * f);
        assert_int_equal(st.hits_added + st.hits_removed + st.photons_updated, 0); /* nothing changed */
        uint32_t done = 16u * (uint32_t)f;
        assert_emitter_pending(w.ph, 2, done < 72 ? done : 72);
        assert_emitter_pending(w.ph, 0, done > 72 ? done - 72 : 0);
    }
    assert_int_equal(frame(&w).groups_retraced, 0);

    /* A brighter light: its groups re-trace with twice the flux on the same paths. */
    int light = w.em.e[1].light;
    double before = 0.0, after = 0.0;
    snapshot s0 = take_snapshot(w.ph);
    w.s->lights[light].intensity *= 2.0f;
    lm_emitters_update(&w.em, w.s);
    assert_int_equal(lm_photons_invalidate_emitter(w.ph, 1, &err), LM_OK);
    uint32_t updated = 0;
    while (lm_photons_pending_groups(w.ph))
        updated += frame(&w).photons_updated;
    assert_int_equal(updated, lm_photons_emitter_photons(w.ph, 1));
    snapshot s1 = take_snapshot(w.ph);
    assert_int_equal(s0.n, s1.n);
    for (uint32_t i = 0; i < s0.n; i++) {
        if (lm_photons_group_of(w.ph, s0.h[i].photon) / 72 != 1) {
            assert_memory_equal(&s0.h[i], &s1.h[i], sizeof(lm_hit));
            continue;
        }
        before += s0.h[i].flux[1];
        after += s1.h[i].flux[1];
    }
    assert_float_equal(after, 2.0 * before, 1e-4 * after);
    free(s0.h);
    free(s1.h);
    world_free(&w);
}

/* ---- move a dynamic object and back: the original hits return exactly ---- */

/* An emitter traced at once (lm_photons_retrace_emitter: a light switched on or added, shown at the next
 * update) leaves the re-trace queue; the groups of the others queued with it keep their place and order,
 * and the re-trace it spares would have changed nothing. */
static void test_retrace_emitter_leaves_queue(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    world w;
    queue_world(&w, path);
    lm_error err;
    assert_int_equal(lm_photons_invalidate_emitter(w.ph, 0, &err), LM_OK);
    assert_int_equal(lm_photons_invalidate_emitter(w.ph, 1, &err), LM_OK);
    assert_int_equal(lm_photons_invalidate_emitter(w.ph, 2, &err), LM_OK);
    assert_int_equal(lm_photons_pending_groups(w.ph), 216);
    snapshot s0 = take_snapshot(w.ph);
    assert_int_equal(lm_photons_retrace_emitter(w.ph, 1, &err), LM_OK);
    assert_int_equal(lm_photons_pending_groups(w.ph), 144);
    assert_emitter_pending(w.ph, 1, 72);
    snapshot s1 = take_snapshot(w.ph); /* the same scene: the same paths and hits */
    assert_int_equal(s0.n, s1.n);
    assert_memory_equal(s0.h, s1.h, s0.n * sizeof *s0.h);
    for (int f = 1; f <= 9; f++) { /* emitter 0's groups first, then 2's, as they were queued */
        lm_photon_frame_stats st = frame(&w);
        assert_int_equal(st.groups_retraced, 16);
        uint32_t done = 16u * (uint32_t)f;
        assert_emitter_pending(w.ph, 0, done < 72 ? done : 72);
        assert_emitter_pending(w.ph, 2, done > 72 ? done - 72 : 0);
    }
    assert_int_equal(frame(&w).groups_retraced, 0);
    assert_int_equal(lm_photons_retrace_emitter(w.ph, (int)(lm_photons_group_count(w.ph) / 72), &err), LM_ERR_INVALID);
    free(s0.h), free(s1.h);
    world_free(&w);
}

/* Places node `node` at world matrix m, in the scene and the BVH, as an animation would. */
static void move_node(world *w, int node, const float m[16])
{
    lm_error err;
    memcpy(w->s->nodes[node].world, m, 16 * sizeof(float));
    assert_int_equal(lm_rt_set_node_transform(w->rt, node, m, &err), LM_OK);
}

static uint32_t settle(world *w)
{
    uint32_t frames = 0, quiet = 0;
    /* Every photon is checked within M = 40 frames; then drain what is left. */
    while ((quiet < 41 || lm_photons_pending_groups(w->ph)) && frames < 2000) {
        lm_photon_frame_stats st = frame(w);
        quiet = st.groups_invalidated ? 0 : quiet + 1;
        frames++;
    }
    return frames;
}

static void test_move_and_back(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    world w;
    world_load(&w, path);
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    world_photons(&w, &set);
    snapshot s0 = take_snapshot(w.ph);
    int cube = find_node(w.s, "dynamic_cube");
    float home[16], moved[16];
    memcpy(home, w.s->nodes[cube].world, sizeof home);
    memcpy(moved, home, sizeof moved);
    moved[12] -= 0.8f; /* 0.8 m along -x, still in room A */
    moved[14] += 0.5f;
    move_node(&w, cube, moved);
    uint32_t f1 = settle(&w);
    snapshot s1 = take_snapshot(w.ph);
    assert_true(s1.n != s0.n || memcmp(s1.h, s0.h, sizeof(lm_hit) * s0.n) != 0);

    move_node(&w, cube, home);
    uint32_t f2 = settle(&w);
    print_message("settled in %u frames after the move, %u after moving back\n", f1, f2);
    snapshot s2 = take_snapshot(w.ph);
    assert_same_snapshot(&s0, &s2);
    free(s0.h);
    free(s1.h);
    free(s2.h);
    world_free(&w);
}

/* The cube of two_rooms.glb moved by an edit, 0.9 m along -x and 0.5 m along z, in world w (loaded, photons
 * traced); moved_nodes (initialised before) gives its boxes into boxes. Returns their count. */
static int edit_cube(world *w, lm_moved_nodes *mv, float *boxes)
{
    int cube = find_node(w->s, "dynamic_cube");
    float m[16];
    memcpy(m, w->s->nodes[cube].world, sizeof m);
    m[12] -= 0.8f; /* still in room A */
    m[14] += 0.5f;
    memcpy(w->s->nodes[cube].world, m, sizeof m); /* as its animation would: no box without room for it */
    assert_int_equal(lm_moved_nodes_boxes(mv, w->s, boxes, 0), 0);
    float nudged[16];
    memcpy(nudged, m, sizeof m);
    nudged[14] += 0.01f;
    memcpy(w->s->nodes[cube].world, nudged, sizeof m); /* with room: its box where it was, then where it is */
    assert_int_equal(lm_moved_nodes_boxes(mv, w->s, boxes, 2), 2);
    assert_float_equal(boxes[6 + 2] - boxes[2], 0.01, 1e-5);
    assert_float_equal(boxes[6 + 5] - boxes[5], 0.01, 1e-5);
    memcpy(w->s->nodes[cube].world, m, sizeof m); /* and back, no room: noted, no box */
    assert_int_equal(lm_moved_nodes_boxes(mv, w->s, boxes, 0), 0);
    lm_error err; /* its paths caught up, as the round robin would in time */
    assert_int_equal(lm_rt_set_node_transform(w->rt, cube, w->s->nodes[cube].world, &err), LM_OK);
    lm_photon_frame_stats st;
    assert_int_equal(lm_photons_trace_all(w->ph, &st, &err), LM_OK);
    m[12] -= 0.1f;
    assert_true(lm_scene_set_node_world(w->s, cube, m)); /* an edit */
    assert_int_equal(lm_rt_set_node_transform(w->rt, cube, w->s->nodes[cube].world, &err), LM_OK);
    int n = lm_moved_nodes_boxes(mv, w->s, boxes, 0);
    assert_int_equal(lm_moved_nodes_boxes(mv, w->s, boxes, 0), 0); /* seen once */
    return n;
}

/* The paths of w's photons that differ from a full trace of the scene as it is now. */
static uint32_t paths_behind(world *w)
{
    const lm_photon_store *store = lm_photons_store(w->ph);
    double *held = calloc(3 * (size_t)store->surface_count, sizeof *held);
    assert_non_null(held);
    lm_photon_store_surface_flux(store, held);
    uint32_t differ = 0;
    against_a_trace(w, held, &differ);
    free(held);
    return differ;
}

/* The two rooms with photons traced and their cube moved by edit_cube: its boxes into *boxes (allocated
 * on the first call, NULL before); returns how many. */
static int world_with_moved_cube(world *w, lm_moved_nodes *mv, const char *path, const lm_photon_settings *set,
                                 float **boxes)
{
    lm_error err;
    world_load(w, path);
    world_photons(w, set);
    assert_int_equal(lm_moved_nodes_init(mv, w->s, &err), LM_OK);
    *boxes = *boxes ? *boxes : malloc(sizeof **boxes * LM_MOVED_NODE_BOXES * (size_t)w->s->node_count);
    assert_non_null(*boxes);
    return edit_cube(w, mv, *boxes);
}

/* An edit's move (scene/moved_nodes.h): the groups whose stored paths cross the node's box where it was or
 * where it is now are queued at once (lm_photons_invalidate_boxes), and re-tracing them leaves none of the
 * 346 changed paths behind. An animated node is the round robin's alone: no box (the paths its move changed
 * are caught up first, as the round robin would in time; left out, 12 of them, which hit the cube where it
 * stood before, stayed behind). The two rooms are closed: no path leaves the scene, whose last leg the test
 * could not see (it is not stored). */
static void test_moved_node_boxes_queue_its_paths(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    world w[2];
    lm_moved_nodes mv[2];
    lm_error err;
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    float *boxes = NULL;
    int n = 0;
    for (int k = 0; k < 2; k++) {
        n = world_with_moved_cube(&w[k], &mv[k], path, &set, &boxes);
        assert_int_equal(n, 2);
    }
    uint32_t changed = paths_behind(&w[0]); /* every path the move changed, none re-traced */
    uint32_t queued = lm_photons_invalidate_boxes(w[1].ph, boxes, n), G = lm_photons_group_count(w[1].ph);
    uint32_t b_lights = 0; /* room B's lights' groups: their photons stay in room B behind the closed door */
    for (uint32_t g = 0; g < G; g++) {
        lm_photon_group_info gi;
        lm_photons_group_info(w[1].ph, g, &gi);
        b_lights += gi.invalid && w[1].em.e[gi.emitter].node >= 0 &&
                    strstr(w[1].s->nodes[w[1].em.e[gi.emitter].node].name, "light_b") != NULL;
    }
    assert_int_equal(lm_photons_pending_groups(w[1].ph), queued);
    int frames = 0;
    while (lm_photons_pending_groups(w[1].ph) && frames++ < 100) { /* the queue alone, no round robin */
        lm_photon_frame_stats st;
        assert_int_equal(lm_photons_frame(w[1].ph, 0, &st, &err), LM_OK);
    }
    uint32_t behind = paths_behind(&w[1]);
    print_message("the cube moved by an edit: %u paths changed; %u of %u groups queued at once (%u of room B's "
                  "lights), re-traced in %d frames, after which %u paths differ from a full trace\n",
                  changed, queued, G, b_lights, frames, behind);
    assert_true(queued > 0 && queued < G);
    assert_int_equal(b_lights, 0);
    assert_true(changed > 100);
    assert_int_equal(behind, 0);
    free(boxes);
    for (int k = 0; k < 2; k++) {
        lm_moved_nodes_free(&mv[k]);
        world_free(&w[k]);
    }
}

/* An animated node's boxes (lm_photons_retrace_boxes): the photons whose paths cross them are re-traced one
 * by one at once, and no changed path is left behind, with no group queued, for a fraction of the photons;
 * the same photons, more than a frame's group budget can take, are queued as whole groups instead. World 0
 * counts the changed paths (paths_behind traces them), 1 re-traces them, 2 has a budget of one group. */
static void test_moved_node_boxes_retrace_photons(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    lm_error err;
    world w[3];
    lm_moved_nodes mv[3];
    lm_photon_frame_stats st[3];
    float *boxes = NULL;
    int n = 0;
    for (int k = 0; k < 3; k++) {
        lm_photon_settings set;
        lm_photon_settings_default(&set);
        set.group_budget = k == 2 ? 1 : 16;
        n = world_with_moved_cube(&w[k], &mv[k], path, &set, &boxes);
        if (k > 0)
            assert_int_equal(lm_photons_retrace_boxes(w[k].ph, boxes, n, &st[k], &err), LM_OK);
    }
    uint32_t changed = paths_behind(&w[0]), behind = paths_behind(&w[1]), photons = lm_photons_count(w[1].ph);
    print_message("the cube moved: %u paths changed; %u of %u photons met its boxes and were re-traced (%u paths "
                  "replaced), %u groups queued, then %u paths differ from a full trace; with one group a frame, "
                  "%u groups queued\n",
                  changed, st[1].box_photons, photons, st[1].photons_updated, st[1].pending_groups, behind,
                  st[2].pending_groups);
    assert_true(changed > 100);
    assert_int_equal(st[1].photons_updated, changed);
    assert_true(st[1].box_photons >= changed && st[1].box_photons < photons / 4);
    assert_int_equal(st[1].pending_groups, 0);
    assert_int_equal(behind, 0);
    assert_true(st[1].box_photons > photons / lm_photons_group_count(w[2].ph)); /* more than one group's worth */
    assert_int_equal(st[2].box_photons, 0);
    assert_int_equal(st[2].photons_updated, 0);
    assert_true(st[2].pending_groups > 0);
    free(boxes);
    for (int k = 0; k < 3; k++) {
        lm_moved_nodes_free(&mv[k]);
        world_free(&w[k]);
    }
}

/* lm_photons_reset keeps the memory but forgets everything else: after some store churn (a move,
 * settling, a move back), a reset and full trace on 3 threads gives the same store, slot for slot,
 * and the same paths as a fresh photon set traced on 1 thread. */
static void test_reset_matches_fresh(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    world w;
    world_load(&w, path);
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    world_photons(&w, &set);
    int cube = find_node(w.s, "dynamic_cube");
    float home[16], moved[16];
    memcpy(home, w.s->nodes[cube].world, sizeof home);
    memcpy(moved, home, sizeof moved);
    moved[12] -= 0.8f;
    move_node(&w, cube, moved);
    settle(&w);
    move_node(&w, cube, home);
    frame(&w); /* leaves groups pending and a non-empty free list behind */

    int threads = omp_get_max_threads();
    omp_set_num_threads(3);
    lm_error err;
    lm_photons_reset(w.ph);
    assert_int_equal(lm_photons_stored_hits(w.ph), 0);
    assert_int_equal(lm_photons_pending_groups(w.ph), 0);
    assert_int_equal(lm_photons_trace_all(w.ph, NULL, &err), LM_OK);
    omp_set_num_threads(1);
    lm_photons *fresh = NULL;
    assert_int_equal(lm_photons_create(w.s, &w.su, w.rt, &w.em, &set, &fresh, &err), LM_OK);
    assert_int_equal(lm_photons_trace_all(fresh, NULL, &err), LM_OK);
    omp_set_num_threads(threads);

    const lm_photon_store *a = lm_photons_store(w.ph), *b = lm_photons_store(fresh);
    assert_int_equal(a->used, b->used);
    assert_int_equal(a->free_head, b->free_head);
    assert_true(lm_photon_store_same(a, b));
    assert_int_equal(lm_photons_stored_hits(w.ph), lm_photons_stored_hits(fresh));
    for (uint32_t p = 0; p < lm_photons_count(fresh); p++) {
        const lm_path_vertex *va, *vb;
        uint32_t na = lm_photons_path(w.ph, p, &va), nb = lm_photons_path(fresh, p, &vb);
        assert_int_equal(na, nb);
        if (na)
            assert_memory_equal(va, vb, sizeof *va * na);
    }
    for (uint32_t g = 0; g < lm_photons_group_count(fresh); g++) {
        lm_photon_group_info ga, gb;
        lm_photons_group_info(w.ph, g, &ga);
        lm_photons_group_info(fresh, g, &gb);
        assert_memory_equal(&ga, &gb, sizeof ga);
    }
    lm_photons_free(fresh);
    world_free(&w);
}

/* A full trace keeps a path whose hits moved by float noise (within epsilon and the flux tolerance: a
 * node switched static holds its place through another matrix); the exact one stores it again, as a
 * fresh trace would. Two hits nudged by an ulp stand for that noise. */
static void test_exact_trace_replaces_noise(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    world w;
    world_load(&w, path);
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    world_photons(&w, &set);
    lm_photon_store *ps = lm_photons_store_mutable(w.ph);
    uint32_t a = ps->surfaces[0].slots[0], b = ps->surfaces[1].slots[0];
    lm_hit ha = ps->hits[a], hb = ps->hits[b];
    int c = fabsf(hb.local[0]) > fabsf(hb.local[2]) ? 0 : 2; /* a coordinate far from 0 */
    ps->hits[a].flux[0] = nextafterf(ha.flux[0], INFINITY);
    ps->hits[b].local[c] = nextafterf(hb.local[c], INFINITY);
    lm_photon_frame_stats st;
    lm_error err;
    assert_int_equal(lm_photons_trace_all(w.ph, &st, &err), LM_OK);
    assert_int_equal(st.photons_updated, 0);
    assert_true(ps->hits[a].flux[0] != ha.flux[0] && ps->hits[b].local[c] != hb.local[c]);
    assert_int_equal(lm_photons_trace_all_exact(w.ph, &st, &err), LM_OK);
    assert_int_equal(st.photons_updated, 2);
    assert_int_equal(lm_photons_trace_all_exact(w.ph, &st, &err), LM_OK);
    assert_int_equal(st.photons_updated, 0); /* an unchanged scene traces the same bits */
    lm_photons *fresh = NULL;
    assert_int_equal(lm_photons_create(w.s, &w.su, w.rt, &w.em, &set, &fresh, &err), LM_OK);
    assert_int_equal(lm_photons_trace_all(fresh, NULL, &err), LM_OK);
    for (uint32_t p = 0; p < lm_photons_count(fresh); p++) { /* every hit as fresh, wherever its slot */
        const lm_path_vertex *va, *vb;
        uint32_t na = lm_photons_path(w.ph, p, &va), nb = lm_photons_path(fresh, p, &vb);
        assert_int_equal(na, nb);
        for (uint32_t i = 0; i < na; i++) {
            assert_int_equal(va[i].slot == LM_NONE, vb[i].slot == LM_NONE);
            if (va[i].slot == LM_NONE)
                continue;
            const lm_hit *x = &ps->hits[va[i].slot], *y = &lm_photons_store(fresh)->hits[vb[i].slot];
            assert_memory_equal(x->local, y->local, sizeof x->local);
            assert_memory_equal(x->flux, y->flux, sizeof x->flux);
        }
    }
    lm_photons_free(fresh);
    world_free(&w);
}

/* ---- settings and sizes ---- */

static void test_settings(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    world w;
    world_load(&w, path);
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    lm_error err;
    set.groups = 70;
    assert_int_equal(lm_photons_create(w.s, &w.su, w.rt, &w.em, &set, &w.ph, &err), LM_ERR_INVALID);
    assert_null(w.ph);
    assert_non_null(strstr(err.msg, "groups"));
    set.groups = 108;
    set.max_bounces = 0;
    assert_int_equal(lm_photons_create(w.s, &w.su, w.rt, &w.em, &set, &w.ph, &err), LM_ERR_INVALID);
    set.max_bounces = 8;
    set.total_photons = 10000;
    assert_int_equal(lm_photons_create(w.s, &w.su, w.rt, &w.em, &set, &w.ph, &err), LM_OK);
    /* Four equal lights: 10000 / 4 / 108 = 23.1 -> 23 per group. */
    assert_int_equal(lm_photons_group_count(w.ph), 4 * 108);
    for (int e = 0; e < 4; e++)
        assert_int_equal(lm_photons_emitter_photons(w.ph, e), 23 * 108);
    assert_int_equal(lm_photons_stored_hits(w.ph), 0);
    assert_int_equal(lm_photons_trace_all(w.ph, NULL, &err), LM_OK);
    for (uint32_t p = 0; p < lm_photons_count(w.ph); p++) {
        const lm_path_vertex *v;
        assert_true(lm_photons_path(w.ph, p, &v) <= 8);
    }
    world_free(&w);
}

/* Rough speed and memory on the Cornell box (printed, not asserted beyond sanity). */
static void test_cornell_rate_and_memory(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    world w;
    world_load(&w, path);
    lm_photon_frame_stats st;
    world_trace(&w, 72 * 1400, &st);
    lm_photon_memory mem;
    lm_photons_memory(w.ph, &mem);
    print_message("cornell: %u photons traced in %.3f s (%.0f photons/s, %d threads); %.2f path vertices and "
                  "%.2f hits per photon; memory %.1f bytes/photon allocated, %.1f used "
                  "(paths %zu, store %zu, other %zu bytes)\n",
                  st.group_photons, st.seconds, st.group_photons / st.seconds, omp_get_max_threads(),
                  mem.mean_path_vertices, mem.mean_hits, mem.per_photon, mem.live_per_photon, mem.path_bytes,
                  mem.store_bytes, mem.other_bytes);
    assert_int_equal(st.group_photons, lm_photons_count(w.ph));
    assert_true(mem.mean_path_vertices >= mem.mean_hits && mem.mean_hits > 1.0);
    assert_float_equal(mem.live_per_photon, 4.0 + 16.0 + 24.0 * mem.mean_path_vertices + 76.0 * mem.mean_hits, 1e-6);
    assert_true(mem.per_photon >= mem.live_per_photon && mem.per_photon < 2.5 * mem.live_per_photon);
    world_free(&w);
}

/* Hidden light (docs/photons.md): a lamp facing up 2 mm under a ceiling, the lamp double-sided like the
 * shared Cornell box's. Every photon its top sends into the gap lands within 2 mm of the lamp: with
 * cover_distance 1 cm none of the hits in the gap (on the ceiling over the lamp, on the lamp's top) is
 * stored (the photons still scatter), while the hits on the floor below, in the open, are all kept. */
static void test_hidden_light(void **state)
{
    (void)state;
    lmt_mesh m[3];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, 2}, (float[3]){4, 0, 0}, (float[3]){0, 0, -4});     /* floor, up */
    lmt_mesh_quad(&m[1], (float[3]){-2, 2, -2}, (float[3]){4, 0, 0}, (float[3]){0, 0, 4});     /* ceiling, down */
    lmt_mesh_quad(&m[2], (float[3]){-0.3f, 1.998f, 0.3f}, (float[3]){0.6f, 0, 0}, (float[3]){0, 0, -0.6f}); /* lamp */
    const char *path = lmt_write_scene("hidden.gltf", m, 3, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"mesh\": 2}]",
                                       "[{}, {}, {\"doubleSided\": true, \"emissiveFactor\": [1, 1, 1]}]");
    uint32_t floor_hits[2], gap_hits[2];
    for (int k = 0; k < 2; k++) {
        world w;
        world_load(&w, path);
        lm_photon_settings set;
        lm_photon_settings_default(&set);
        set.total_photons = 20000;
        set.cover_distance = k ? 0.01f : 0.0f;
        world_photons(&w, &set);
        const lm_photon_store *ps = lm_photons_store(w.ph);
        floor_hits[k] = gap_hits[k] = 0;
        for (uint32_t h = 0; h < ps->used; h++) {
            const lm_hit *x = &ps->hits[h];
            if (x->surface < 0 || ps->surfaces[x->surface].count == 0)
                continue;
            int node = w.su.surfaces[x->surface].node;
            int top = node == 2 && !lm_tri_is_back(w.s, x->tri); /* the file wound the lamp facing up */
            int over = node == 1 && fabsf(x->pos[0]) < 0.29f && fabsf(x->pos[2]) < 0.29f;
            floor_hits[k] += node == 0;
            gap_hits[k] += top || over;
        }
        world_free(&w);
    }
    print_message("stored hits without / with cover: floor %u / %u, in the gap %u / %u\n", floor_hits[0],
                  floor_hits[1], gap_hits[0], gap_hits[1]);
    assert_true(gap_hits[0] > 1000); /* the gap fills with hits */
    assert_int_equal(gap_hits[1], 0);
    assert_int_equal(floor_hits[1], floor_hits[0]); /* the open floor keeps every hit */
    assert_true(floor_hits[0] > 1000);
}

/* A lamp inside a glass cube, off its centre: light leaving it within about 35 degrees of a diagonal
 * meets every face beyond the critical angle (41.8 degrees at ior 1.5) and is reflected for ever, at the
 * same angles each time. Such photons end after PH_SPECULAR_RUN mirror or glass vertices in a row
 * instead of max_bounces (1,024): a soak that placed lights at random spent 0.9 s on 16 groups. The rest
 * leaves the cube and lights the floor. */
static void test_light_trapped_in_glass(void **state)
{
    (void)state;
    lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-4, 0, 4}, (float[3]){8, 0, 0}, (float[3]){0, 0, -8});
    lmt_mesh_cube(&m[1], 0.5f);
    const char *path = lmt_write_scene("trapped.gltf", m, 2,
                                       "[{\"mesh\": 0}, {\"mesh\": 1, \"translation\": [0, 1, 0]},"
                                       " {\"translation\": [0.07, 1.05, -0.03], \"extensions\":"
                                       " {\"KHR_lights_punctual\": {\"light\": 0}}}]",
                                       "[" LMT_DIFFUSE(0.5) ", " LMT_GLASS "], "
                                       LMT_LIGHTS("{\"type\": \"point\", \"intensity\": 10}"));
    world w;
    world_load(&w, path);
    lm_photon_frame_stats st;
    world_trace(&w, 72 * 64, &st);
    double rays = (double)st.rays / lm_photons_count(w.ph);
    print_message("lamp in a glass cube: %.1f rays a photon (a run of %u specular vertices ends one), %u hits "
                  "stored\n", rays, PH_SPECULAR_RUN, lm_photons_stored_hits(w.ph));
    assert_int_equal(PH_SPECULAR_RUN, 64);
    assert_true(rays < 66.0); /* without the bound: 244 rays a photon */
    assert_true(rays > 4.0); /* a share of them was caught */
    assert_true(lm_photons_stored_hits(w.ph) > lm_photons_count(w.ph) / 4); /* the rest lights the floor */
    world_free(&w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_groups_are_coherent),
        cmocka_unit_test(test_locality_door_closed),
        cmocka_unit_test(test_locality_door_open),
        cmocka_unit_test(test_energy_closed_box),
        cmocka_unit_test(test_hits_know_where_they_came_from),
        cmocka_unit_test(test_power_edit_scales_hits),
        cmocka_unit_test(test_recolour_reweights_hits),
        cmocka_unit_test(test_recolour_far_and_back),
        cmocka_unit_test(test_no_channel_grows),
        cmocka_unit_test(test_invalidate_emitter),
        cmocka_unit_test(test_retrace_emitter_leaves_queue),
        cmocka_unit_test(test_move_and_back),
        cmocka_unit_test(test_moved_node_boxes_queue_its_paths),
        cmocka_unit_test(test_moved_node_boxes_retrace_photons),
        cmocka_unit_test(test_reset_matches_fresh),
        cmocka_unit_test(test_exact_trace_replaces_noise),
        cmocka_unit_test(test_settings),
        cmocka_unit_test(test_cornell_rate_and_memory),
        cmocka_unit_test(test_hidden_light),
        cmocka_unit_test(test_split_trace_is_one_process_trace),
        cmocka_unit_test(test_release_removed_light),
        cmocka_unit_test(test_light_trapped_in_glass),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
