/* Caustic photons (trace/caustics.h): where they land against the analytic image of a light in a mirror,
 * energy through mirrors and glass, what moves re-traces what, bad geometry, switches, determinism. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/trace/caustics.h"
#include "../src/trace/photons.h"
#include "support.h"

static lm_caustics *make(const lmt_pipeline *p, uint32_t photons, lm_caustic_frame_stats *st)
{
    lm_caustic_settings set;
    lm_caustic_settings_default(&set);
    set.photons = photons;
    lm_caustics *c = NULL;
    lm_error err;
    if (lm_caustics_create(p->s, p->rt, &p->em, &set, &c, st, &err) != LM_OK)
        fail_msg("%s", err.msg);
    return c;
}

/* The photons binned in 0.1 m cells of the floor: cells well inside the lit patch read the image of the
 * light within 10%, cells well outside nothing. */
static void test_mirror_image(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, lmt_mirror_scene("mirror.gltf", NULL, NULL), 0.2f);
    lm_caustic_frame_stats st;
    lm_caustics *c = make(&p, 1u << 16, &st);
    assert_int_equal(lm_caustics_generator_count(c), 1);
    assert_int_equal(lm_caustics_pair_count(c), 1);
    enum { N = 80 };
    const double cell = 0.1, lo = -4.0;
    static double bins[N][N];
    memset(bins, 0, sizeof bins);
    const lm_caustic_hit *h = lm_caustics_hits(c);
    for (uint32_t i = 0; i < lm_caustics_photon_count(c); i++) {
        if (h[i].flux[1] == 0.0f)
            continue;
        assert_int_equal(h[i].node, 0);
        assert_true(h[i].ng[1] > 0.99f);
        int bx = (int)floor((h[i].pos[0] - lo) / cell), bz = (int)floor((h[i].pos[2] - lo) / cell);
        if (bx >= 0 && bx < N && bz >= 0 && bz < N)
            bins[bx][bz] += h[i].flux[1];
    }
    double worst_in = 0.0, sum_in = 0.0, want_in = 0.0, out_flux = 0.0, in_flux = 0.0;
    int inside_cells = 0;
    for (int i = 0; i < N; i++)
        for (int k = 0; k < N; k++) {
            double x0 = lo + i * cell, z0 = lo + k * cell, E = bins[i][k] / (cell * cell);
            int all_in = 1, all_out = 1;
            for (int cx = -1; cx <= 2; cx++) /* the cell and a margin of half a cell */
                for (int cz = -1; cz <= 2; cz++) {
                    int in;
                    lmt_mirror_image(x0 + cx * 0.5 * cell, z0 + cz * 0.5 * cell, &in);
                    all_in &= in, all_out &= !in;
                }
            int in;
            double want = lmt_mirror_image(x0 + 0.5 * cell, z0 + 0.5 * cell, &in);
            if (all_in) {
                worst_in = fmax(worst_in, fabs(E / want - 1.0));
                sum_in += E, want_in += want, inside_cells++;
                in_flux += bins[i][k];
            } else if (all_out) {
                out_flux += bins[i][k];
            }
        }
    print_message("mirror image: %d cells inside, mean %.4f of F I cos / d^2, worst cell %.3f; flux outside %.2e of "
                  "inside; %u landed, %u missed of %u\n", inside_cells, sum_in / want_in, worst_in, out_flux / in_flux,
                  st.landed, st.missed, st.traced);
    assert_true(inside_cells > 40);
    assert_true(fabs(sum_in / want_in - 1.0) < 0.02);
    assert_true(worst_in < 0.10);
    assert_true(out_flux == 0.0);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);
}

/* What the photons off the mirror at x = 1 (facing -x) carried before it: each landed photon's flux over the
 * mirror's Fresnel reflectance at the angle it left at (its direction's x), summed. */
static double unreflected(const lm_caustics *c)
{
    double sum = 0.0;
    for (uint32_t i = 0; i < lm_caustics_photon_count(c); i++) {
        const lm_caustic_hit *h = &lm_caustics_hits(c)[i];
        if (h->flux[1] != 0.0f)
            sum += h->flux[1] / lmt_mirror_fresnel(0.9, 1.0 - fabs(h->dir[0]));
    }
    return sum;
}

/* A mirror of albedo 0.9 stores exactly what it received times its Fresnel reflectance photon by photon
 * (at least 0.9); received, the light's intensity times the mirror's solid angle from the light (a
 * rectangle seen off its axis: the difference of four on-axis corner rectangles, Omega(a, b, h) =
 * atan(a b / (h sqrt(a^2 + b^2 + h^2)))). */
static double rect_solid_angle(double a, double b, double h) { return atan(a * b / (h * sqrt(a * a + b * b + h * h))); }

static void test_mirror_energy(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, lmt_mirror_scene("mirror_energy.gltf", NULL, NULL), 0.2f);
    lm_caustics *c = make(&p, 1u << 16, NULL);
    double stored[3], emitted[3];
    lm_caustics_flux(c, stored, emitted);
    /* from (0, 2, 0) the mirror plane x = 1 lies at h = 1; the mirror spans y - 2 in [-1.25, -0.75], z in
     * [-0.25, 0.25] */
    double omega = 2.0 * (rect_solid_angle(1.25, 0.25, 1.0) - rect_solid_angle(0.75, 0.25, 1.0));
    double before = unreflected(c);
    print_message("mirror energy: stored %.6f (%.4f of what it received), which carried %.6f before the mirror; "
                  "received %.6f, I x Omega %.5f\n", stored[1], stored[1] / emitted[1], before, emitted[1], 10.0 * omega);
    assert_true(fabs(before - emitted[1]) <= 1e-5 * emitted[1]);
    assert_true(stored[1] >= 0.9 * emitted[1] && stored[1] <= 0.91 * emitted[1]);
    assert_true(fabs(emitted[1] / (10.0 * omega) - 1.0) < 0.005);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);
}

/* A closed diffuse room (half-size 3) with a light and a generator cube (half-size 0.3) at its centre. */
static const char *room_scene(const char *name, const char *generator, const char *light_json, float light_y,
                              float cube_size)
{
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_cube_inward(&m[0], 3.0f);
    lmt_mesh_cube(&m[1], cube_size);
    char nodes[512], materials[2048];
    snprintf(nodes, sizeof nodes,
             "[{\"mesh\": 0}, {\"mesh\": 1}, {\"translation\": [0, %g, 0.01], \"extensions\": "
             "{\"KHR_lights_punctual\": {\"light\": 0}}}]", (double)light_y);
    snprintf(materials, sizeof materials, "[" LMT_DIFFUSE(0.5) ", %s], " LMT_LIGHTS("%s"), generator, light_json);
    return lmt_write_scene(name, m, 2, nodes, materials);
}

/* Clear glass passes every photon on (Fresnel picks reflection or refraction, weight 1): what lands is what
 * the cube received, less what total internal reflection kept past the bounce cap. A light inside a glass
 * cube: the whole sphere of directions, every photon through the glass. */
static void test_glass_energy(void **state)
{
    (void)state;
    const char *point = "{\"type\": \"point\", \"intensity\": 10}";
    for (int inside = 0; inside < 2; inside++) {
        lmt_pipeline p;
        lmt_pipeline_load(&p, room_scene("glass.gltf", LMT_GLASS, point, inside ? 0.0f : 2.0f, 0.3f), 0.5f);
        lm_caustic_frame_stats st;
        lm_caustics *c = make(&p, 1u << 14, &st);
        double stored[3], emitted[3];
        lm_caustics_flux(c, stored, emitted);
        print_message("glass (light %s): stored %.5f of received %.5f; %u landed, %u capped, %u absorbed, %u escaped, "
                      "%u missed\n", inside ? "inside" : "outside", stored[1], emitted[1], st.landed, st.capped,
                      st.absorbed, st.escaped, st.missed);
        assert_int_equal(st.escaped, 0); /* a closed room */
        assert_true(stored[1] <= emitted[1] * (1.0 + 1e-6));
        assert_true(stored[1] >= emitted[1] * (1.0 - 1e-6) - (double)(st.capped + st.absorbed) * emitted[1] / st.landed * 2.0);
        if (inside) { /* every direction reaches the glass */
            assert_int_equal(st.missed, 0);
            assert_true(fabs(emitted[1] / (4.0 * M_PI * 10.0) - 1.0) < 1e-3);
        }
        lm_caustics_free(c);
        lmt_pipeline_free(&p);
    }
}

/* Light caught in a mirror box (every face a perfect mirror, the light inside): every photon bounces
 * until the cap, is counted and dropped; nothing hangs. */
static void test_bounce_cap(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, room_scene("mirror_box.gltf", "{\"pbrMetallicRoughness\": {\"metallicFactor\": 1, "
                      "\"roughnessFactor\": 0}, \"doubleSided\": true}", "{\"type\": \"point\", \"intensity\": 1}", 0.0f, 1.0f),
                      0.5f);
    lm_caustic_frame_stats st;
    lm_caustics *c = make(&p, 4096, &st);
    print_message("mirror box: %u capped, %u landed of %u, %llu rays\n", st.capped, st.landed, st.traced,
                  (unsigned long long)st.rays);
    assert_int_equal(st.capped, st.traced - st.missed - st.absorbed);
    assert_true(st.capped > 3000);
    assert_int_equal(st.landed, 0);
    assert_int_equal(lm_caustics_landed(c), 0);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);
}

static void move(lmt_pipeline *p, int node, float dx)
{
    float w[16];
    memcpy(w, p->s->nodes[node].world, sizeof w);
    w[12] += dx;
    lm_error err;
    assert_true(lm_scene_set_node_world(p->s, node, w));
    if (lm_rt_set_node_transform(p->rt, node, w, &err) != LM_OK)
        fail_msg("%s", err.msg);
    lm_emitters_update(&p->em, p->s);
}

/* A still scene traces nothing; another node moving re-traces a quarter of each pair a frame for one
 * turn; the generator moving re-traces its pair whole at once. */
static void test_what_moves(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, lmt_mirror_scene("moves.gltf", "{\"lmgi\": {\"dynamic\": true}}", "{\"lmgi\": {\"dynamic\": true}}"),
                      0.2f);
    const uint32_t N = 4096;
    lm_caustics *c = make(&p, N, NULL);
    lm_caustic_frame_stats st;
    lm_error err;
    assert_int_equal(lm_caustics_frame(c, &st, &err), LM_OK);
    assert_int_equal(st.traced, 0);
    move(&p, 3, 0.1f); /* the cube */
    uint32_t traced[6];
    for (int f = 0; f < 6; f++) {
        assert_int_equal(lm_caustics_frame(c, &st, &err), LM_OK);
        traced[f] = st.traced;
    }
    print_message("cube moved: %u %u %u %u %u %u photons re-traced\n", traced[0], traced[1], traced[2], traced[3],
                  traced[4], traced[5]);
    for (int f = 0; f < 4; f++)
        assert_int_equal(traced[f], N / 4);
    assert_int_equal(traced[4], 0);
    uint64_t v = lm_caustics_version(c);
    move(&p, 1, 0.05f); /* the mirror */
    assert_int_equal(lm_caustics_frame(c, &st, &err), LM_OK);
    assert_int_equal(st.pairs_moved, 1);
    assert_true(st.traced >= N);
    assert_true(lm_caustics_version(c) > v);
    assert_float_equal(lm_caustics_generator(c, 0)->centre[0], 1.05, 1e-5);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);
}

/* The mirror scene's floor and mirror under two point lights (emitters 0 and 1). */
static const char *two_light_mirror_scene(void)
{
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-4, 0, 4}, (float[3]){8, 0, 0}, (float[3]){0, 0, -8});
    lmt_mesh_quad(&m[1], (float[3]){1, 0.75f, -0.25f}, (float[3]){0, 0, 0.5f}, (float[3]){0, 0.5f, 0});
    return lmt_write_scene("two_light_mirror.gltf", m, 2,
                           "[{\"mesh\": 0}, {\"mesh\": 1},"
                           " {\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
                           " {\"translation\": [-0.5, 1.5, 0.5], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]",
                           "[" LMT_DIFFUSE(0.8) ", " LMT_MIRROR(0.9) "], "
                           LMT_LIGHTS("{\"type\": \"point\", \"intensity\": 10}"));
}

static void set_removed(lmt_pipeline *p, int light, int removed)
{
    p->s->lights[light].removed = removed;
    lm_emitters_update(&p->em, p->s);
}

/* Frames until no whole re-trace is queued (each within the frame cap); returns how many. */
static int catch_up(lm_caustics *c, uint32_t cap)
{
    lm_caustic_frame_stats st;
    lm_error err;
    int frames = 0;
    while (lm_caustics_pending(c) > 0 && frames < 100) {
        assert_int_equal(lm_caustics_frame(c, &st, &err), LM_OK);
        assert_true(st.traced <= cap);
        frames++;
    }
    assert_int_equal(lm_caustics_pending(c), 0);
    return frames;
}

/* Lights come and go: a light that joins gets its pairs queued and traced over frames within the cap the
 * pairs at creation set (one light's: N x 1.25), ending with the same photons as caustics made with it
 * from the start; a removed light's pairs and slots go; a recoloured material's re-trace is queued and
 * spread the same way. */
static void test_lights_come_and_go(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, two_light_mirror_scene(), 0.2f);
    const uint32_t N = 2048, cap = N + N / 4;
    lm_caustics *both = make(&p, N, NULL);
    assert_int_equal(lm_caustics_photon_count(both), 2 * N);

    set_removed(&p, 1, 1); /* caustics made while light 1 is out: one pair */
    lm_caustics *c = make(&p, N, NULL);
    assert_int_equal(lm_caustics_photon_count(c), N);
    lm_error err;
    set_removed(&p, 1, 0); /* it joins (an added light, as the layout sees it) */
    assert_int_equal(lm_caustics_follow_emitters(c, &err), LM_OK);
    assert_int_equal(lm_caustics_photon_count(c), 2 * N);
    assert_int_equal(lm_caustics_pending(c), N);
    int frames = catch_up(c, cap);
    assert_memory_equal(lm_caustics_hits(c), lm_caustics_hits(both), sizeof(lm_caustic_hit) * 2 * N);
    assert_int_equal(frames, 1); /* N fit in one frame's cap */

    lm_caustics_retrace_all_later(c); /* a material recoloured: both pairs, more than one frame's cap */
    assert_int_equal(lm_caustics_pending(c), 2 * N);
    int again = catch_up(c, cap);
    assert_int_equal(again, 2);
    assert_memory_equal(lm_caustics_hits(c), lm_caustics_hits(both), sizeof(lm_caustic_hit) * 2 * N);

    set_removed(&p, 0, 1); /* light 0 leaves: its slots go, light 1's keep their photons */
    assert_int_equal(lm_caustics_follow_emitters(c, &err), LM_OK);
    assert_int_equal(lm_caustics_photon_count(c), N);
    assert_int_equal(lm_caustics_pending(c), 0);
    const lm_caustic_hit *h = lm_caustics_hits(c);
    uint32_t landed = 0;
    for (uint32_t k = 0; k < N; k++)
        if (h[k].flux[0] > 0.0f) {
            assert_int_equal(h[k].emitter, 1);
            assert_memory_equal(&h[k], &lm_caustics_hits(both)[N + k], sizeof *h);
            landed++;
        }
    assert_true(landed > N / 4);
    assert_int_equal(lm_caustics_landed(c), landed);

    print_message("a light joined: %u photons queued, traced in %d frame of at most %u; a recolour's %u in %d "
                  "frames; a light left: %u slots kept, %u photons landed as before\n", N, frames, cap, 2 * N, again,
                  lm_caustics_photon_count(c), landed);
    lm_caustics_free(both);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);
}

/* Extras "caustics": false makes a mirror no generator; a spot aimed away from the mirror lands nothing;
 * a scene with no specular material has no pairs and costs nothing. */
static void test_switches_and_empty(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, lmt_mirror_scene("off.gltf", "{\"lmgi\": {\"caustics\": false}}", NULL), 0.2f);
    lm_caustic_frame_stats st;
    lm_caustics *c = make(&p, 1024, &st);
    assert_int_equal(lm_caustics_pair_count(c), 0);
    assert_int_equal(lm_caustics_photon_count(c), 0);
    assert_int_equal(st.traced, 0);
    lm_error err;
    assert_int_equal(lm_caustics_frame(c, &st, &err), LM_OK);
    assert_int_equal(st.traced, 0);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);

    /* a spot at (0, 2, 0) pointing -x (away from the mirror at +x) */
    const char *spot = "{\"type\": \"spot\", \"intensity\": 10, \"spot\": {\"outerConeAngle\": 0.5}}";
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-4, 0, 4}, (float[3]){8, 0, 0}, (float[3]){0, 0, -8});
    lmt_mesh_quad(&m[1], (float[3]){1, 0.75f, -0.25f}, (float[3]){0, 0, 0.5f}, (float[3]){0, 0.5f, 0});
    /* a node's light shines down its -Z: rotated +90 degrees about y, -Z becomes -x */
    const char *path = lmt_write_scene("spot.gltf", m, 2, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"translation\": [0, 2, 0], "
                                       "\"rotation\": [0, 0.7071068, 0, 0.7071068], \"extensions\": "
                                       "{\"KHR_lights_punctual\": {\"light\": 0}}}]",
                                       "[" LMT_DIFFUSE(0.8) ", " LMT_MIRROR(0.9) "], " LMT_LIGHTS("{\"type\": \"spot\", \"intensity\": 10, "
                                       "\"spot\": {\"outerConeAngle\": 0.5}}"));
    (void)spot;
    lmt_pipeline_load(&p, path, 0.2f);
    c = make(&p, 1024, &st);
    assert_int_equal(lm_caustics_pair_count(c), 1);
    assert_int_equal(lm_caustics_landed(c), 0);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);
}

/* The sun on the mirror: received = E x area x cos, stored = 0.9 of it. */
static void test_directional(void **state)
{
    (void)state;
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-4, 0, 4}, (float[3]){8, 0, 0}, (float[3]){0, 0, -8});
    lmt_mesh_quad(&m[1], (float[3]){1, 0.75f, -0.25f}, (float[3]){0, 0, 0.5f}, (float[3]){0, 0.5f, 0});
    /* the node's -Z turned to (1, -1, 0) / sqrt 2: columns x' = (0, 0, 1), y' = (1, 1, 0) / sqrt 2,
     * z' = (-1, 1, 0) / sqrt 2 */
    const char *path = lmt_write_scene("sun.gltf", m, 2, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"matrix\": "
                                       "[0, 0, 1, 0, 0.7071068, 0.7071068, 0, 0, -0.7071068, 0.7071068, 0, 0, 0, 0, 0, 1], "
                                       "\"extensions\": "
                                       "{\"KHR_lights_punctual\": {\"light\": 0}}}]",
                                       "[" LMT_DIFFUSE(0.8) ", " LMT_MIRROR(0.9) "], " LMT_LIGHTS("{\"type\": \"directional\", \"intensity\": 3}"));
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 0.2f);
    const float *d = p.em.e[0].dir;
    lm_caustics *c = make(&p, 1u << 14, NULL);
    double stored[3], emitted[3];
    lm_caustics_flux(c, stored, emitted);
    double cos = d[0] / sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), want = 3.0 * 0.25 * cos;
    print_message("sun: direction (%.3f %.3f %.3f), received %.5f of E A cos %.5f, stored %.5f\n", (double)d[0],
                  (double)d[1], (double)d[2], emitted[1], want, stored[1]);
    assert_true(cos > 0.6);
    assert_true(fabs(emitted[1] / want - 1.0) < 0.01);
    assert_true(fabs(unreflected(c) - emitted[1]) <= 1e-5 * emitted[1]);
    assert_true(fabs(stored[1] / emitted[1] - lmt_mirror_fresnel(0.9, 1.0 - cos)) < 1e-5);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);
}

/* One thread or two: the same photons, bit for bit. */
static void test_deterministic(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, room_scene("det.gltf", LMT_GLASS, "{\"type\": \"point\", \"intensity\": 10}", 2.0f, 0.3f), 0.5f);
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    lm_caustics *a = make(&p, 8192, NULL);
    omp_set_num_threads(threads > 1 ? threads : 2);
    lm_caustics *b = make(&p, 8192, NULL);
    omp_set_num_threads(threads);
    assert_int_equal(lm_caustics_photon_count(a), lm_caustics_photon_count(b));
    assert_memory_equal(lm_caustics_hits(a), lm_caustics_hits(b), sizeof(lm_caustic_hit) * lm_caustics_photon_count(a));
    lm_caustics_free(a);
    lm_caustics_free(b);
    lmt_pipeline_free(&p);
}

/* The frame's trace casts 16 photons as one Embree packet a bounce; each photon lands where it lands traced
 * on its own, ray by ray, bit for bit (a glass ball: two refractions or a reflection). */
static void test_packets_as_one_by_one(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, room_scene("packets.gltf", LMT_GLASS, "{\"type\": \"point\", \"intensity\": 10}", 2.0f, 0.3f),
                      0.5f);
    lm_caustics *c = make(&p, 4096, NULL);
    const lm_caustic_hit *hits = lm_caustics_hits(c);
    uint32_t n = lm_caustics_photon_count(c), landed = 0, differ = 0;
    for (uint32_t s = 0; s < n; s++) {
        lm_caustic_hit h;
        landed += lm_caustics_trace_one(c, s, &h) == LM_CAUSTIC_LANDED;
        differ += memcmp(&h, &hits[s], sizeof h) != 0;
    }
    print_message("%u photons, %u landed one by one, %u differ from the packets'\n", n, landed, differ);
    assert_true(landed > n / 2);
    assert_int_equal(landed, lm_caustics_landed(c));
    assert_int_equal(differ, 0);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);
}

/* The photon stage's own photons mark the hits that came off mirrors and glass only (L S+ D): exactly those
 * whose path before them is all specular. Their light is the caustic pass's: the IIM's energy and delta_i
 * leave them out. */
static void test_regular_photons_mark_caustic_hits(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, room_scene("marks.gltf", LMT_MIRROR(0.9), "{\"type\": \"point\", \"intensity\": 10}", 2.0f,
                                     0.5f), 0.5f);
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    set.per_group = 100;
    set.min_total = 0;
    lm_photons *ph = NULL;
    lm_error err;
    if (lm_photons_create(p.s, &p.su, p.rt, &p.em, &set, &ph, &err) != LM_OK ||
        lm_photons_trace_all(ph, NULL, &err) != LM_OK)
        fail_msg("%s", err.msg);
    const lm_photon_store *ps = lm_photons_store(ph);
    uint32_t marked = 0, wrong = 0;
    double caustic_energy = 0.0, all = 0.0, iim = 0.0;
    for (uint32_t id = 0; id < lm_photons_count(ph); id++) {
        const lm_path_vertex *v = NULL;
        uint32_t n = lm_photons_path(ph, id, &v);
        int specular_before = 1;
        for (uint32_t i = 0; i < n; i++) {
            if (v[i].slot != LM_NONE) {
                const lm_hit *h = &ps->hits[v[i].slot];
                int want = i > 0 && specular_before;
                wrong += h->caustic != want;
                marked += h->caustic;
                caustic_energy += h->caustic ? lm_hit_energy(h) : 0.0;
            }
            specular_before = specular_before && lm_material_is_specular(p.s->materials[p.s->tri_material[v[i].tri]].cls);
        }
    }
    for (int k = 0; k < ps->surface_count; k++) {
        iim += lm_photon_store_iim_energy(ps, k);
        for (uint32_t j = 0; j < ps->surfaces[k].count; j++) {
            const lm_hit *h = &ps->hits[ps->surfaces[k].slots[j]];
            all += lm_hit_energy(h) * !(h->bounce == 0 && h->source == LM_HIT_FROM_PUNCTUAL);
        }
    }
    print_message("%u caustic hits marked (%.4f of the energy), %u marked wrong; IIM energy %.4f = all but first "
                  "punctual hits %.4f less caustic %.4f\n", marked, caustic_energy, wrong, iim, all, caustic_energy);
    assert_true(marked > 100);
    assert_true(iim > 0.5 * all); /* a closed room: most bounced light is not caustic */
    assert_int_equal(wrong, 0);
    assert_true(fabs(iim - (all - caustic_energy)) <= 1e-6 * all);
    lm_photons_free(ph);
    lmt_pipeline_free(&p);
}

/* KHR_materials_ior: 0 is the extension's "everything reflected" (the glass acts as a mirror: every
 * photon off it after one bounce, all its power); 1 bends nothing (every photon goes straight through,
 * in twice, out once: two bounces, its direction kept); 0.5 is refused naming the material. A mirror
 * whose triangles have no extent is no generator. */
static void test_odd_glass(void **state)
{
    (void)state;
    const char *point = "{\"type\": \"point\", \"intensity\": 10}";
    const char *ior0 = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0}, \"extensions\": {\"KHR_materials_transmission\": "
                       "{\"transmissionFactor\": 1}, \"KHR_materials_ior\": {\"ior\": 0}}}";
    const char *ior1 = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0}, \"extensions\": {\"KHR_materials_transmission\": "
                       "{\"transmissionFactor\": 1}, \"KHR_materials_ior\": {\"ior\": 1}}}";
    lmt_pipeline p;
    lmt_pipeline_load(&p, room_scene("ior0.gltf", ior0, point, 2.0f, 0.3f), 0.5f);
    lm_caustic_frame_stats st;
    lm_caustics *c = make(&p, 4096, &st);
    double stored[3], emitted[3];
    lm_caustics_flux(c, stored, emitted);
    uint32_t one = 0;
    for (uint32_t i = 0; i < lm_caustics_photon_count(c); i++)
        one += lm_caustics_hits(c)[i].flux[1] != 0.0f && lm_caustics_hits(c)[i].bounces == 1;
    print_message("ior 0: %u of %u landed after one bounce, stored %.5f of received %.5f\n", one, st.landed, stored[1],
                  emitted[1]);
    assert_true(st.landed > 1000);
    assert_int_equal(one, st.landed);
    assert_true(fabs(stored[1] - emitted[1]) <= 1e-5 * emitted[1]);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);

    lmt_pipeline_load(&p, room_scene("ior1.gltf", ior1, point, 2.0f, 0.3f), 0.5f);
    c = make(&p, 4096, &st);
    uint32_t straight = 0;
    for (uint32_t i = 0; i < lm_caustics_photon_count(c); i++) {
        const lm_caustic_hit *h = &lm_caustics_hits(c)[i];
        float to[3] = {h->pos[0], h->pos[1] - 2.0f, h->pos[2] - 0.01f}; /* from the light (0, 2, 0.01) */
        float l = sqrtf(to[0] * to[0] + to[1] * to[1] + to[2] * to[2]);
        straight += h->flux[1] != 0.0f && h->bounces == 2 && fabsf(to[0] / l - h->dir[0]) < 1e-3f &&
                    fabsf(to[1] / l - h->dir[1]) < 1e-3f && fabsf(to[2] / l - h->dir[2]) < 1e-3f;
    }
    print_message("ior 1: %u of %u landed straight on after two bounces\n", straight, st.landed);
    assert_true(st.landed > 1000);
    assert_int_equal(straight, st.landed);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);

    lm_scene *s = NULL;
    lm_load_options lo = {0};
    lm_error err;
    const char *bad = "{\"name\": \"thin glass\", \"pbrMetallicRoughness\": {\"metallicFactor\": 0}, \"extensions\": "
                      "{\"KHR_materials_transmission\": {\"transmissionFactor\": 1}, \"KHR_materials_ior\": {\"ior\": 0.5}}}";
    assert_int_equal(lm_scene_load_gltf(room_scene("ior05.gltf", bad, point, 2.0f, 0.3f), &lo, &s, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "thin glass"));
    assert_non_null(strstr(err.msg, "ior"));
    assert_null(s);

    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_cube_inward(&m[0], 3.0f);
    lmt_mesh_quad(&m[1], (float[3]){0, 1, 0}, (float[3]){0, 0, 0}, (float[3]){0, 0, 0});
    lmt_pipeline_load(&p, lmt_write_scene("flat.gltf", m, 2, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"translation\": [0, 2, 0], "
                                          "\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]",
                                          "[" LMT_DIFFUSE(0.5) ", " LMT_MIRROR(0.9) "], " LMT_LIGHTS("{\"type\": \"point\", \"intensity\": 10}")),
                      0.5f);
    c = make(&p, 1024, &st);
    assert_int_equal(lm_caustics_generator_count(c), 0);
    assert_int_equal(st.traced, 0);
    lm_caustics_free(c);
    lmt_pipeline_free(&p);
}

/* Bad settings are refused naming them. */
static void test_bad_settings(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, lmt_mirror_scene("bad.gltf", NULL, NULL), 0.2f);
    lm_caustic_settings set;
    lm_caustics *c = NULL;
    lm_error err;
    lm_caustic_settings_default(&set);
    set.retrace = 0.0f;
    assert_int_equal(lm_caustics_create(p.s, p.rt, &p.em, &set, &c, NULL, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "re-trace"));
    set.retrace = NAN;
    assert_int_equal(lm_caustics_create(p.s, p.rt, &p.em, &set, &c, NULL, &err), LM_ERR_INVALID);
    lm_caustic_settings_default(&set);
    set.photons = 0;
    assert_int_equal(lm_caustics_create(p.s, p.rt, &p.em, &set, &c, NULL, &err), LM_ERR_INVALID);
    assert_null(c);
    lmt_pipeline_free(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mirror_image),
        cmocka_unit_test(test_mirror_energy),
        cmocka_unit_test(test_glass_energy),
        cmocka_unit_test(test_bounce_cap),
        cmocka_unit_test(test_what_moves),
        cmocka_unit_test(test_lights_come_and_go),
        cmocka_unit_test(test_switches_and_empty),
        cmocka_unit_test(test_directional),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_packets_as_one_by_one),
        cmocka_unit_test(test_regular_photons_mark_caustic_hits),
        cmocka_unit_test(test_odd_glass),
        cmocka_unit_test(test_bad_settings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
