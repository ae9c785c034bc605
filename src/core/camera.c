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

/* Polygon poly (n points) clipped to the half-space pl . (x, 1) >= 0 (Sutherland-Hodgman) into out;
 * returns the new count (at most n + 1). */
static int clip_polygon(const double pl[4], const double (*poly)[3], int n, double (*out)[3])
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const double *a = poly[i], *b = poly[(i + 1) % n];
        double fa = pl[0] * a[0] + pl[1] * a[1] + pl[2] * a[2] + pl[3];
        double fb = pl[0] * b[0] + pl[1] * b[1] + pl[2] * b[2] + pl[3];
        if (fa >= 0.0)
            memcpy(out[m++], a, sizeof out[0]);
        if ((fa >= 0.0) != (fb >= 0.0)) {
            double t = fa / (fa - fb);
            for (int k = 0; k < 3; k++)
                out[m][k] = a[k] + t * (b[k] - a[k]);
            m++;
        }
    }
    return m;
}

int lm_view_box_part(const lm_view *v, const float lo[3], const float hi[3], float pts[][3])
{
    float vp[16];
    lm_mat4_mul(vp, v->proj, v->view);
    double planes[6][4]; /* w + x, w - x, w + y, ...: the clip-space half-spaces as world planes */
    for (int p = 0; p < 6; p++)
        for (int k = 0; k < 4; k++)
            planes[p][k] = (double)vp[k * 4 + 3] + (p % 2 ? -1.0 : 1.0) * (double)vp[k * 4 + p / 2];
    int n = 0;
    for (int face = 0; face < 6; face++) { /* face: axis face / 2, at lo (even) or hi (odd) */
        int axis = face / 2, u = (axis + 1) % 3, w = (axis + 2) % 3;
        double poly[2][12][3];
        for (int c = 0; c < 4; c++) {
            poly[0][c][axis] = face % 2 ? hi[axis] : lo[axis];
            poly[0][c][u] = c == 1 || c == 2 ? hi[u] : lo[u];
            poly[0][c][w] = c >= 2 ? hi[w] : lo[w];
        }
        int count = 4, cur = 0;
        for (int p = 0; p < 6 && count > 0; p++, cur ^= 1)
            count = clip_polygon(planes[p], (const double(*)[3])poly[cur], count, poly[cur ^ 1]);
        for (int c = 0; c < count && n < LM_VIEW_BOX_POINTS; c++, n++)
            for (int k = 0; k < 3; k++)
                pts[n][k] = (float)poly[cur][c][k];
    }
    float inv[16];
    if (!lm_mat4_invert(inv, vp))
        return n;
    for (int c = 0; c < 8 && n < LM_VIEW_BOX_POINTS; c++) { /* the frustum's corners inside the box */
        double ndc[4] = {c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1, 1}, q[4] = {0, 0, 0, 0};
        for (int r = 0; r < 4; r++)
            for (int k = 0; k < 4; k++)
                q[r] += (double)inv[k * 4 + r] * ndc[k];
        if (!(q[3] > 1e-12 * (fabs(q[0]) + fabs(q[1]) + fabs(q[2]) + 1e-30)))
            continue; /* at infinity */
        int inside = 1;
        for (int k = 0; k < 3; k++) {
            double x = q[k] / q[3];
            inside &= x >= lo[k] && x <= hi[k];
            pts[n][k] = (float)x;
        }
        n += inside;
    }
    return n;
}
