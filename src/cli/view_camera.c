/* The viewer's orbit and fly camera (view_camera.h). */
#include "view_camera.h"

#include <math.h>
#include <string.h>

#define PI_F 3.14159265f
#define MAX_PITCH (89.0f * PI_F / 180.0f)

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* The unit direction from the target to the eye. */
static void back_dir(const lm_view_camera *c, float d[3])
{
    d[0] = cosf(c->pitch) * sinf(c->yaw);
    d[1] = sinf(c->pitch);
    d[2] = cosf(c->pitch) * cosf(c->yaw);
}

/* The view's right and up vectors (world, unit) for the current yaw and pitch. */
static void view_axes(const lm_view_camera *c, float right[3], float up[3])
{
    float b[3];
    back_dir(c, b);
    right[0] = cosf(c->yaw), right[1] = 0.0f, right[2] = -sinf(c->yaw);
    up[0] = b[1] * right[2] - b[2] * right[1];
    up[1] = b[2] * right[0] - b[0] * right[2];
    up[2] = b[0] * right[1] - b[1] * right[0];
}

void lm_view_camera_from(lm_view_camera *c, const lmgi_camera *cam, const float lo[3], const float hi[3])
{
    memset(c, 0, sizeof *c);
    const float *v = cam->view, *p = cam->proj;
    /* view = [R | -R eye]: eye = -R^T t; the camera looks down -z, whose world direction is -(row 2 of R) */
    float eye[3], fwd[3] = {-v[2], -v[6], -v[10]};
    for (int k = 0; k < 3; k++)
        eye[k] = -(v[4 * k] * v[12] + v[4 * k + 1] * v[13] + v[4 * k + 2] * v[14]);
    float len = sqrtf(dot3(fwd, fwd));
    for (int k = 0; k < 3; k++)
        fwd[k] = len > 0.0f ? fwd[k] / len : (k == 2 ? -1.0f : 0.0f);
    float mid[3], diag = 0.0f;
    for (int k = 0; k < 3; k++) {
        mid[k] = 0.5f * (lo[k] + hi[k]);
        diag += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    c->scene_size = sqrtf(diag) > 0.0f ? sqrtf(diag) : 1.0f;
    float to_mid[3] = {mid[0] - eye[0], mid[1] - eye[1], mid[2] - eye[2]};
    c->distance = fmaxf(dot3(to_mid, fwd), 0.05f * c->scene_size);
    for (int k = 0; k < 3; k++)
        c->target[k] = eye[k] + c->distance * fwd[k];
    c->pitch = asinf(fmaxf(-1.0f, fminf(1.0f, -fwd[1])));
    c->pitch = fmaxf(-MAX_PITCH, fminf(MAX_PITCH, c->pitch));
    c->yaw = atan2f(-fwd[0], -fwd[2]);
    c->fovy = p[5] > 0.0f ? 2.0f * atanf(1.0f / p[5]) : 0.8f;
    /* a perspective projection's p[10] = (f + n) / (n - f), p[14] = 2 f n / (n - f) */
    float n = p[14] / (p[10] - 1.0f), f = p[14] / (p[10] + 1.0f);
    c->near_plane = n > 0.0f && isfinite(n) ? n : 1e-3f * c->scene_size;
    c->far_plane = f > c->near_plane && isfinite(f) ? f : 10.0f * c->scene_size;
}

void lm_view_camera_eye(const lm_view_camera *c, float eye[3])
{
    float b[3];
    back_dir(c, b);
    for (int k = 0; k < 3; k++)
        eye[k] = c->target[k] + c->distance * b[k];
}

void lm_view_camera_get(const lm_view_camera *c, int width, int height, lmgi_camera *out)
{
    float eye[3], b[3], r[3], u[3];
    lm_view_camera_eye(c, eye);
    back_dir(c, b);
    view_axes(c, r, u);
    float *v = out->view, *p = out->proj;
    memset(out, 0, sizeof *out);
    for (int k = 0; k < 3; k++) { /* rows: right, up, back */
        v[4 * k] = r[k];
        v[4 * k + 1] = u[k];
        v[4 * k + 2] = b[k];
    }
    v[12] = -dot3(r, eye), v[13] = -dot3(u, eye), v[14] = -dot3(b, eye), v[15] = 1.0f;
    /* the far plane reaches past the scene wherever the eye has flown */
    float n = c->near_plane, f = fmaxf(c->far_plane, c->distance + 2.0f * c->scene_size);
    float t = 1.0f / tanf(0.5f * c->fovy), aspect = height > 0 ? (float)width / (float)height : 1.0f;
    p[0] = t / aspect, p[5] = t, p[10] = (f + n) / (n - f), p[11] = -1.0f, p[14] = 2.0f * f * n / (n - f);
}

void lm_view_camera_orbit(lm_view_camera *c, double dx, double dy, int h)
{
    float k = PI_F / (float)(h > 0 ? h : 1);
    c->yaw -= (float)dx * k;
    c->pitch = fmaxf(-MAX_PITCH, fminf(MAX_PITCH, c->pitch + (float)dy * k));
}

void lm_view_camera_pan(lm_view_camera *c, double dx, double dy, int h)
{
    float r[3], u[3];
    view_axes(c, r, u);
    float k = 2.0f * c->distance * tanf(0.5f * c->fovy) / (float)(h > 0 ? h : 1);
    for (int i = 0; i < 3; i++)
        c->target[i] += k * (-(float)dx * r[i] + (float)dy * u[i]);
}

void lm_view_camera_zoom(lm_view_camera *c, double steps)
{
    c->distance *= powf(0.85f, (float)steps);
    c->distance = fmaxf(c->distance, 2.0f * c->near_plane);
    c->distance = fminf(c->distance, 10.0f * c->scene_size);
}

void lm_view_camera_fly(lm_view_camera *c, float forward, float right, float up, float seconds)
{
    float b[3], r[3], u[3];
    back_dir(c, b);
    view_axes(c, r, u);
    float s = 0.25f * c->scene_size * seconds;
    for (int k = 0; k < 3; k++)
        c->target[k] += s * (-forward * b[k] + right * r[k] + (k == 1 ? up : 0.0f));
}
