/* The pinhole camera's geometry (camera.h): clip tests, an application's matrices, cube map faces, and
 * the pinhole ray casters read. */
#include "camera.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "vecmath.h"

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

lm_status lm_view_pinhole(lm_view *v, int width, int height, lm_error *err)
{
    if (v->proj[11] != -1.0f)
        return lm_fail(err, LM_ERR_INVALID, "camera '%s' is orthographic; only perspective cameras are supported",
                       v->name);
    for (int k = 0; k < 3; k++) {
        v->up[k] = v->view[4 * k + 1];
        v->forward[k] = -v->view[4 * k + 2];
    }
    v->yfov = 2.0f * atanf(1.0f / v->proj[5]);
    v->width = width, v->height = height;
    /* proj[10] = (f + n) / (n - f) and proj[14] = 2 f n / (n - f) give n = proj[14] / (proj[10] - 1) */
    float n = v->proj[14] / (v->proj[10] - 1.0f);
    v->znear = isfinite(n) && n > 0.0f ? n : 0.0f;
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
