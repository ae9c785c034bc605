/* The caustic photons' split between the lightmaps and the screen (photonmap/caustic_split.h) on the
 * 20 x 20 plane at 0.25 texels: a thin, even field of photons and a dense spot, the plane's other light
 * given as its AIM. Power kept to rounding, the spot the screen's, the field the lightmaps' at its analytic
 * irradiance, the fraction and the other light deciding, light gathered in a window left on screen, and the
 * same bits every run. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/core/qmc.h"
#include "../src/photonmap/caustic_split.h"
#include "support.h"

#define FIELD 40000         /* photons spread evenly over the plane */
#define SPOT 6000           /* photons within SPOT_R of (3, 0, 3) */
#define SPOT_R 0.3
#define FIELD_E 0.05        /* the field's irradiance, against the other light's 1 */
#define SPOT_E 50.0

static lmt_pipeline pipe_;
static lm_caustic_hit hits[FIELD + SPOT];

/* The plane's triangle under (x, z), -1 for none. */
static int triangle_at(const lm_scene *s, float x, float z)
{
    for (uint32_t t = 0; t < s->tri_count; t++) {
        float v[3][3];
        for (int k = 0; k < 3; k++)
            lm_scene_vertex_world(s, s->tris[3 * t + k], v[k]);
        int inside = 1;
        for (int k = 0; k < 3 && inside; k++) { /* the same side of each edge as the third corner (xz plane) */
            const float *a = v[k], *b = v[(k + 1) % 3], *c = v[(k + 2) % 3];
            float e = (b[0] - a[0]) * (z - a[2]) - (b[2] - a[2]) * (x - a[0]);
            float f = (b[0] - a[0]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[0] - a[0]);
            inside = e * f >= 0.0f;
        }
        if (inside)
            return (int)t;
    }
    return -1;
}

static void put(lm_caustic_hit *h, const lm_scene *s, float x, float z, float flux)
{
    memset(h, 0, sizeof *h);
    int t = triangle_at(s, x, z);
    assert_true(t >= 0);
    h->pos[0] = x, h->pos[2] = z;
    h->ng[1] = 1.0f, h->dir[1] = -1.0f;
    h->flux[0] = h->flux[1] = h->flux[2] = flux;
    h->tri = (uint32_t)t;
    h->bounces = 1;
    float v[3][3]; /* (x, z)'s barycentrics on t, as the tracer's hit gives them */
    for (int k = 0; k < 3; k++)
        lm_scene_vertex_world(s, s->tris[3 * (size_t)t + k], v[k]);
    float d = (v[1][0] - v[0][0]) * (v[2][2] - v[0][2]) - (v[2][0] - v[0][0]) * (v[1][2] - v[0][2]);
    h->bary[0] = ((x - v[0][0]) * (v[2][2] - v[0][2]) - (v[2][0] - v[0][0]) * (z - v[0][2])) / d;
    h->bary[1] = ((v[1][0] - v[0][0]) * (z - v[0][2]) - (x - v[0][0]) * (v[1][2] - v[0][2])) / d;
}

static int setup(void **state)
{
    (void)state;
    lm_qmc_init();
    lmt_pipeline_load(&pipe_, lmt_plane_scene(), 0.25f);
    const lm_scene *s = pipe_.s;
    const double area = 400.0;
    for (uint32_t i = 0; i < FIELD; i++) /* Halton points: an even field */
        put(&hits[i], s, -10.0f + 20.0f * (float)lm_halton(0, i + 1), -10.0f + 20.0f * (float)lm_halton(1, i + 1),
            (float)(FIELD_E * area / FIELD));
    for (uint32_t i = 0; i < SPOT; i++) {
        double r = SPOT_R * sqrt(lm_halton(0, i + 1)), phi = 2.0 * M_PI * lm_halton(1, i + 1);
        put(&hits[FIELD + i], s, (float)(3.0 + r * cos(phi)), (float)(3.0 + r * sin(phi)),
            (float)(SPOT_E * M_PI * SPOT_R * SPOT_R / SPOT));
    }
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    lmt_pipeline_free(&pipe_);
    return 0;
}

/* An AIM whose radiance is kd / pi x e on every covered texel (left: x < 0, e_left there): other light of
 * irradiance e. */
static float *aim_of2(double e, double e_left)
{
    const lm_atlas *a = &pipe_.atlas;
    float *rgb = calloc(3 * (size_t)a->width * a->height, sizeof *rgb);
    assert_non_null(rgb);
    for (uint32_t i = 0; i < a->texel_count; i++) {
        float kd[3];
        lm_texel_kd(pipe_.s, &a->texels[i], kd);
        for (int c = 0; c < 3; c++)
            rgb[3 * ((size_t)a->texels[i].y * a->width + a->texels[i].x) + c] =
                (float)(kd[c] / M_PI * (a->texels[i].pos[0] < 0.0f ? e_left : e));
    }
    return rgb;
}

static float *aim_of(double e) { return aim_of2(e, e); }

static void split_aim(float *aim, float fraction, lm_caustic_split *out)
{
    lm_error err;
    memset(out, 0, sizeof *out);
    assert_int_equal(lm_caustic_split_make(pipe_.s, &pipe_.atlas, aim, hits, FIELD + SPOT, fraction, out, &err), LM_OK);
    free(aim);
}

static void split(double other, float fraction, lm_caustic_split *out) { split_aim(aim_of(other), fraction, out); }

/* The lightmaps' power (E_thin x texel area) and the screen's (its photons' flux), green. */
static void powers(const lm_caustic_split *sp, double *lightmap, double *screen)
{
    const lm_atlas *a = &pipe_.atlas;
    *lightmap = *screen = 0.0;
    for (uint32_t i = 0; i < a->texel_count; i++)
        *lightmap += a->texels[i].area * sp->thin[4 * ((size_t)a->texels[i].y * a->width + a->texels[i].x) + 1];
    for (uint32_t i = 0; i < sp->count; i++)
        *screen += sp->screen[i].flux[1];
}

static void test_field_to_lightmaps_spot_to_screen(void **state)
{
    (void)state;
    lm_caustic_split sp;
    split(1.0, 1.0f, &sp);
    double total = 0.0, lightmap, screen, spot_on_screen = 0.0, field_thin = 0.0, field_far = 0.0, spot = 0.0;
    for (uint32_t i = 0; i < FIELD + SPOT; i++)
        total += hits[i].flux[1];
    powers(&sp, &lightmap, &screen);
    for (uint32_t i = 0; i < FIELD + SPOT; i++) {
        double dx = hits[i].pos[0] - 3.0, dz = hits[i].pos[2] - 3.0, d = sqrt(dx * dx + dz * dz);
        if (i >= FIELD)
            spot += hits[i].flux[1], spot_on_screen += sp.screen[i].flux[1];
        else if (d > 2.0)
            field_thin += sp.screen[i].flux[1] == 0.0f, field_far++;
    }
    /* the field away from the spot and the plane's edge: its analytic irradiance in the lightmap */
    const lm_atlas *a = &pipe_.atlas;
    double worst = 0.0, mean = 0.0;
    int n = 0;
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        double dx = t->pos[0] - 3.0, dz = t->pos[2] - 3.0;
        if (fabs(t->pos[0]) > 8.0 || fabs(t->pos[2]) > 8.0 || sqrt(dx * dx + dz * dz) < 2.0)
            continue;
        double e = sp.thin[4 * ((size_t)t->y * a->width + t->x) + 1] / FIELD_E - 1.0;
        worst = fmax(worst, fabs(e));
        mean += e;
        n++;
    }
    mean /= n;
    print_message("plane: %u photons landed, %u thin; power in the lightmaps %.6f + on screen %.6f = %.6f of %.6f; spot "
                  "on screen %.4f of its power; field photons 2 away from it thin %.4f; field's E_thin over %d texels: mean %+.4f, "
                  "worst %.4f off\n", sp.landed, sp.thin_photons, lightmap, screen, lightmap + screen, total,
                  spot_on_screen / spot, field_thin / field_far, n, mean, worst);
    assert_int_equal(sp.landed, FIELD + SPOT);
    assert_true(fabs((lightmap + screen) / total - 1.0) < 1e-4);
    assert_true(spot_on_screen / spot > 0.99);
    assert_true(field_thin == field_far); /* the field away from the spot is the lightmaps' */
    assert_true(fabs(mean) < 0.01);
    assert_true(worst < 0.06);
    lm_caustic_split_free(&sp);
}

/* The fraction and the other light decide: light over fraction x the other light, or with no other light,
 * is all the screen's. */
static void test_other_light_decides(void **state)
{
    (void)state;
    lm_caustic_split sp;
    split(1.0, 0.01f, &sp); /* the field's 0.05 is over 0.01 x 1 */
    assert_int_equal(sp.thin_photons, 0);
    lm_caustic_split_free(&sp);
    split(0.0, 1.0f, &sp); /* a dark plane: every caustic is concentrated */
    assert_int_equal(sp.thin_photons, 0);
    double lightmap, screen;
    powers(&sp, &lightmap, &screen);
    assert_true(lightmap == 0.0);
    lm_caustic_split_free(&sp);
    split(1000.0, 1.0f, &sp); /* the spot's 50 is thin next to 1000, but its rim is structure */
    print_message("next to 1000 times the field's light: %u of %u photons thin\n", sp.thin_photons, sp.landed);
    assert_true(sp.thin_photons > FIELD);
    assert_true(sp.thin_photons < FIELD + SPOT);
    lm_caustic_split_free(&sp);
    /* the texel's own light too: the plane's mean light is bright (0.54), but where it is 0.08 (x < 0) the
     * field's 0.05 is not under half of the rest, 0.015 */
    split_aim(aim_of2(1.0, 0.08), 0.5f, &sp);
    uint32_t left = 0, left_thin = 0, right = 0, right_thin = 0;
    for (uint32_t i = 0; i < FIELD; i++) {
        double dx = hits[i].pos[0] - 3.0, dz = hits[i].pos[2] - 3.0;
        int thin = sp.screen[i].flux[1] == 0.0f;
        if (hits[i].pos[0] < -1.0f)
            left++, left_thin += (uint32_t)thin;
        else if (hits[i].pos[0] > 1.0f && sqrt(dx * dx + dz * dz) > 2.0)
            right++, right_thin += (uint32_t)thin;
    }
    print_message("dark left half: %u of %u field photons thin there, %u of %u on the bright half\n", left_thin, left,
                  right_thin, right);
    assert_int_equal(left_thin, 0);
    assert_int_equal(right_thin, right);
    lm_caustic_split_free(&sp);
}

/* A fan a few texels across in sparse light: 80 photons within 0.3 m of (-4, -4) among 2,000 spread over
 * the plane (0.3 a texel, so a window gathers its 128 photons 6 texels out). Both are thin next to the
 * plane's light, but spread over the clump's window its power would leave the clump (the grazing hard
 * case's fan): the clump is the screen's, the sparse field away from it the lightmaps'. */
static void test_light_gathered_in_a_window_stays_on_screen(void **state)
{
    (void)state;
    enum { SPARSE = 2000, CLUMP = 80 };
    static lm_caustic_hit few[SPARSE + CLUMP];
    const lm_scene *s = pipe_.s;
    const double e = 0.005, flux = e * 400.0 / SPARSE;
    for (uint32_t i = 0; i < SPARSE; i++)
        put(&few[i], s, -10.0f + 20.0f * (float)lm_halton(0, i + 1), -10.0f + 20.0f * (float)lm_halton(1, i + 1),
            (float)flux);
    for (uint32_t i = 0; i < CLUMP; i++) {
        double r = 0.3 * sqrt(lm_halton(0, i + 1)), phi = 2.0 * M_PI * lm_halton(1, i + 1);
        put(&few[SPARSE + i], s, (float)(-4.0 + r * cos(phi)), (float)(-4.0 + r * sin(phi)), (float)flux);
    }
    lm_caustic_split sp;
    lm_error err;
    memset(&sp, 0, sizeof sp);
    float *aim = aim_of(1.0);
    assert_int_equal(lm_caustic_split_make(s, &pipe_.atlas, aim, few, SPARSE + CLUMP, 1.0f, &sp, &err), LM_OK);
    free(aim);
    uint32_t clump_on_screen = 0, far = 0, far_thin = 0;
    for (uint32_t i = 0; i < SPARSE + CLUMP; i++) {
        double dx = few[i].pos[0] + 4.0, dz = few[i].pos[2] + 4.0;
        int thin = sp.screen[i].flux[1] == 0.0f;
        if (i >= SPARSE)
            clump_on_screen += (uint32_t)!thin;
        else if (sqrt(dx * dx + dz * dz) > 2.0 && fabs(few[i].pos[0]) < 8.0f && fabs(few[i].pos[2]) < 8.0f)
            far++, far_thin += (uint32_t)thin;
    }
    print_message("a clump of %d photons in sparse light: %u of them on screen; %u of %u sparse photons 2 away thin\n",
                  CLUMP, clump_on_screen, far_thin, far);
    assert_int_equal(clump_on_screen, CLUMP);
    assert_int_equal(far_thin, far);
    lm_caustic_split_free(&sp);
}

static void test_deterministic(void **state)
{
    (void)state;
    lm_caustic_split a, b;
    split(1.0, 1.0f, &a);
    split(1.0, 1.0f, &b);
    size_t cells = (size_t)pipe_.atlas.width * pipe_.atlas.height;
    assert_memory_equal(a.thin, b.thin, 4 * cells * sizeof *a.thin);
    assert_memory_equal(a.screen, b.screen, (size_t)a.count * sizeof *a.screen);
    lm_caustic_split_free(&a);
    lm_caustic_split_free(&b);
}

/* A photon is placed by where it fell on its triangle, not by its world position: after the receiver
 * moved (a node placed 2 m away between the trace and the split) its photons keep their texels. */
static void test_moved_receiver_keeps_its_photons(void **state)
{
    (void)state;
    lm_caustic_split a, b;
    split(1.0, 1.0f, &a);
    lm_node *n = &((lm_scene *)pipe_.s)->nodes[pipe_.s->tri_node[hits[0].tri]];
    float saved[16];
    memcpy(saved, n->world, sizeof saved);
    n->world[12] += 2.0f;
    split(1.0, 1.0f, &b);
    memcpy(n->world, saved, sizeof saved);
    size_t cells = (size_t)pipe_.atlas.width * pipe_.atlas.height;
    assert_true(a.thin_photons > 0);
    assert_int_equal(a.thin_photons, b.thin_photons);
    assert_memory_equal(a.thin, b.thin, 4 * cells * sizeof *a.thin);
    lm_caustic_split_free(&a);
    lm_caustic_split_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_field_to_lightmaps_spot_to_screen),
        cmocka_unit_test(test_other_light_decides),
        cmocka_unit_test(test_light_gathered_in_a_window_stays_on_screen),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_moved_receiver_keeps_its_photons),
    };
    lmt_filter_from_env();
    return cmocka_run_group_tests(tests, setup, teardown);
}
