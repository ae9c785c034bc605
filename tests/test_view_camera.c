/* cli/view_camera: the viewer's orbit and fly camera. Made from a scene's camera it gives that camera's
 * matrices back; orbiting keeps the eye's distance to the target, panning moves the target across the
 * view and keeps the direction, zooming moves the eye along it, flying moves eye and target together. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <math.h>
#include <string.h>

#include "../src/cli/view_camera.h"

static double dist3(const float a[3], const float b[3])
{
    return sqrt((double)(a[0] - b[0]) * (a[0] - b[0]) + (double)(a[1] - b[1]) * (a[1] - b[1]) +
                (double)(a[2] - b[2]) * (a[2] - b[2]));
}

/* A camera at eye looking at `at` (up +y), fovy, near and far: GL's lookAt and perspective. */
static void look_at(lmgi_camera *c, const float eye[3], const float at[3], float fovy, float aspect, float n, float f)
{
    memset(c, 0, sizeof *c);
    float z[3] = {eye[0] - at[0], eye[1] - at[1], eye[2] - at[2]}, l = (float)dist3(eye, at);
    for (int k = 0; k < 3; k++)
        z[k] /= l;
    float x[3] = {z[2], 0.0f, -z[0]}, lx = sqrtf(x[0] * x[0] + x[2] * x[2]);
    x[0] /= lx, x[2] /= lx;
    float y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
    for (int k = 0; k < 3; k++)
        c->view[4 * k] = x[k], c->view[4 * k + 1] = y[k], c->view[4 * k + 2] = z[k];
    c->view[12] = -(x[0] * eye[0] + x[1] * eye[1] + x[2] * eye[2]);
    c->view[13] = -(y[0] * eye[0] + y[1] * eye[1] + y[2] * eye[2]);
    c->view[14] = -(z[0] * eye[0] + z[1] * eye[1] + z[2] * eye[2]);
    c->view[15] = 1.0f;
    float t = 1.0f / tanf(0.5f * fovy);
    c->proj[0] = t / aspect, c->proj[5] = t, c->proj[10] = (f + n) / (n - f), c->proj[11] = -1.0f;
    c->proj[14] = 2.0f * f * n / (n - f);
}

static void test_round_trip_and_moves(void **state)
{
    (void)state;
    const float eye[3] = {1.0f, 2.5f, 6.0f}, at[3] = {0.2f, 1.0f, 0.0f}, lo[3] = {-2, 0, -2}, hi[3] = {2, 3, 2};
    lmgi_camera scene_cam, got;
    look_at(&scene_cam, eye, at, 0.7f, 4.0f / 3.0f, 0.05f, 50.0f);
    lm_view_camera c;
    lm_view_camera_from(&c, &scene_cam, lo, hi);
    lm_view_camera_get(&c, 640, 480, &got);
    for (int k = 0; k < 16; k++) {
        assert_true(fabsf(got.view[k] - scene_cam.view[k]) < 1e-4f);
        if (k != 10 && k != 14) /* the far plane reaches past the scene: 50 here */
            assert_true(fabsf(got.proj[k] - scene_cam.proj[k]) < 1e-4f);
    }
    float e0[3], e1[3], t0[3];
    lm_view_camera_eye(&c, e0);
    assert_true(dist3(e0, eye) < 1e-4);
    /* orbit: the same target and distance, another eye */
    memcpy(t0, c.target, sizeof t0);
    lm_view_camera_orbit(&c, 100.0, -40.0, 480);
    lm_view_camera_eye(&c, e1);
    assert_true(dist3(c.target, t0) == 0.0);
    assert_true(fabs(dist3(e1, t0) - dist3(e0, t0)) < 1e-4 && dist3(e1, e0) > 0.5);
    /* pan: the target moves across the view, the direction stays */
    lm_view_camera p = c;
    lm_view_camera_pan(&p, 50.0, 0.0, 480);
    assert_true(dist3(p.target, c.target) > 0.01 && p.yaw == c.yaw && p.pitch == c.pitch && p.distance == c.distance);
    /* zoom: nearer by 15% a step */
    lm_view_camera z = c;
    lm_view_camera_zoom(&z, 2.0);
    assert_true(fabsf(z.distance - c.distance * 0.85f * 0.85f) < 1e-5f * c.distance);
    /* fly: eye and target together, a quarter of the scene's size a second */
    lm_view_camera f = c;
    lm_view_camera_fly(&f, 1.0f, 0.0f, 0.0f, 1.0f);
    float ef[3];
    lm_view_camera_eye(&f, ef);
    assert_true(fabs(dist3(f.target, c.target) - 0.25 * c.scene_size) < 1e-4);
    assert_true(fabs(dist3(ef, e1) - 0.25 * c.scene_size) < 1e-4);
    /* pitch stays short of straight up or down */
    lm_view_camera_orbit(&c, 0.0, 1e6, 480);
    assert_true(c.pitch < 1.56f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_and_moves),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
