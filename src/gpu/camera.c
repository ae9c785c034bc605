#include "camera.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../core/vecmath.h"

static void ortho(float m[16], float xmag, float ymag, float znear, float zfar)
{
    lm_mat4_identity(m);
    m[0] = 1.0f / xmag;
    m[5] = 1.0f / ymag;
    m[10] = 2.0f / (znear - zfar);
    m[14] = (zfar + znear) / (znear - zfar);
}

static void from_file(const lm_scene *s, const lm_camera *c, float aspect, lm_view *out)
{
    const float *w = s->nodes[c->node].world;
    /* The camera looks down its node's -Z; the view matrix is the inverse of its world matrix,
     * with the scale removed so a scaled camera node does not squash the picture. */
    lm_vec3 eye = lm_v3(w[12], w[13], w[14]);
    lm_vec3 fwd = lm_normalize(lm_mat4_dir(w, lm_v3(0, 0, -1)));
    lm_vec3 up = lm_normalize(lm_mat4_dir(w, lm_v3(0, 1, 0)));
    lm_mat4_look_at(out->view, eye, lm_add(eye, fwd), up);
    lm_v3_store(out->eye, eye);
    float zfar = c->zfar > 0 ? c->zfar : 10.0f * lm_scene_size(s) + c->znear;
    float znear = c->znear > 0 ? c->znear : 1e-3f * lm_scene_size(s);
    if (c->perspective)
        lm_mat4_perspective(out->proj, c->yfov > 0 ? c->yfov : 0.8f, aspect, znear, zfar);
    else
        ortho(out->proj, c->xmag > 0 ? c->xmag : 1.0f, c->ymag > 0 ? c->ymag : 1.0f, znear, zfar);
    out->from_file = 1;
    snprintf(out->name, sizeof out->name, "%s", c->name[0] ? c->name : "camera");
}

int lm_view_sees_box(const lm_view *v, const float lo[3], const float hi[3])
{
    float vp[16], clip[8][4];
    lm_mat4_mul(vp, v->proj, v->view);
    for (int c = 0; c < 8; c++) {
        float p[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        for (int r = 0; r < 4; r++)
            clip[c][r] = vp[r] * p[0] + vp[4 + r] * p[1] + vp[8 + r] * p[2] + vp[12 + r];
    }
    for (int plane = 0; plane < 6; plane++) { /* -w <= x, y, z <= w, one side at a time */
        int axis = plane / 2, outside = 0;
        float sign = plane % 2 ? -1.0f : 1.0f;
        for (int c = 0; c < 8; c++)
            outside += !(sign * clip[c][axis] <= clip[c][3]); /* NaN counts as outside */
        if (outside == 8)
            return 0;
    }
    return 1;
}

static void automatic(const lm_scene *s, float aspect, lm_view *out)
{
    lm_vec3 lo = lm_v3_load(s->bounds_min), hi = lm_v3_load(s->bounds_max);
    lm_vec3 c = lm_scale(lm_add(lo, hi), 0.5f);
    float r = 0.5f * lm_length(lm_sub(hi, lo));
    if (!(r > 0.0f))
        r = 1.0f;
    const float yfov = 0.8f;
    float fov = aspect < 1.0f ? 2.0f * atanf(tanf(0.5f * yfov) * aspect) : yfov;
    float dist = r / sinf(0.5f * fov);
    lm_vec3 dir = lm_normalize(lm_v3(0.35f, 0.45f, 1.0f));
    lm_vec3 eye = lm_add(c, lm_scale(dir, dist));
    lm_mat4_look_at(out->view, eye, c, lm_v3(0, 1, 0));
    lm_mat4_perspective(out->proj, yfov, aspect, 0.01f * r, dist + 2.0f * r);
    lm_v3_store(out->eye, eye);
    out->from_file = 0;
    snprintf(out->name, sizeof out->name, "automatic");
}

void lm_view_cube_face(const float eye[3], int face, float znear, float zfar, lm_view *out)
{
    static const float fwd[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    static const float up[6][3] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    memset(out, 0, sizeof *out);
    lm_vec3 e = lm_v3_load(eye);
    lm_mat4_look_at(out->view, e, lm_add(e, lm_v3_load(fwd[face])), lm_v3_load(up[face]));
    lm_mat4_perspective(out->proj, 0.5f * LM_PI_F, 1.0f, znear, zfar);
    lm_v3_store(out->eye, e);
    snprintf(out->name, sizeof out->name, "cube face %d", face);
}

void lm_view_for_scene(const lm_scene *s, int camera, int width, int height, lm_view *out)
{
    memset(out, 0, sizeof *out);
    float aspect = (float)width / (float)(height > 0 ? height : 1);
    if (camera < 0 && s->camera_count > 0)
        camera = 0;
    if (camera >= 0 && camera < s->camera_count && s->cameras[camera].node >= 0 &&
        s->cameras[camera].node < s->node_count) {
        const lm_camera *c = &s->cameras[camera];
        from_file(s, c, aspect, out); /* the picture's aspect wins, as viewers do */
    } else {
        automatic(s, aspect, out);
    }
}

lm_status lm_view_ref_camera(const lm_view *v, int width, int height, lm_ref_camera *cam, lm_error *err)
{
    if (v->proj[11] != -1.0f)
        return lm_fail(err, LM_ERR_INVALID, "camera '%s' is orthographic; only perspective cameras are supported",
                       v->name);
    memcpy(cam->eye, v->eye, sizeof cam->eye);
    for (int k = 0; k < 3; k++) {
        cam->up[k] = v->view[4 * k + 1];
        cam->forward[k] = -v->view[4 * k + 2];
    }
    cam->yfov = 2.0f * atanf(1.0f / v->proj[5]);
    cam->width = width, cam->height = height;
    /* proj[10] = (f + n) / (n - f) and proj[14] = 2 f n / (n - f) give n = proj[14] / (proj[10] - 1) */
    float n = v->proj[14] / (v->proj[10] - 1.0f);
    cam->znear = isfinite(n) && n > 0.0f ? n : 0.0f;
    return LM_OK;
}

int lm_view_from_matrices(const float view[16], const float proj[16], lm_view *out)
{
    float inv[16];
    if (!lm_mat4_invert_affine(inv, view))
        return 0;
    memset(out, 0, sizeof *out);
    memcpy(out->view, view, sizeof out->view);
    memcpy(out->proj, proj, sizeof out->proj);
    for (int i = 0; i < 3; i++)
        out->eye[i] = inv[12 + i]; /* the camera's position: where view space's origin lies */
    snprintf(out->name, sizeof out->name, "application camera");
    return 1;
}
