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

/* Clips the convex polygon poly (n points) by every half-space of planes and appends what is left to pts
 * (at *n_out, up to LM_VIEW_BOX_POINTS). */
static void clip_append(const double (*planes)[4], int plane_count, const double (*poly)[3], int n, float (*pts)[3],
                        int *n_out)
{
    double buf[2][4 + 8][3];
    memcpy(buf[0], poly, sizeof buf[0][0] * (size_t)n);
    int cur = 0;
    for (int p = 0; p < plane_count && n > 0; p++, cur ^= 1)
        n = clip_polygon(planes[p], (const double(*)[3])buf[cur], n, buf[cur ^ 1]);
    for (int c = 0; c < n && *n_out < LM_VIEW_BOX_POINTS; c++, (*n_out)++)
        for (int k = 0; k < 3; k++)
            pts[*n_out][k] = (float)buf[cur][c][k];
}

/* q = m (x, y, z, 1), in double. */
static void transform4(const float m[16], double x, double y, double z, double q[4])
{
    for (int r = 0; r < 4; r++)
        q[r] = (double)m[r] * x + (double)m[4 + r] * y + (double)m[8 + r] * z + (double)m[12 + r];
}

/* Depth in front of the eye of view matrix z: -(row 2 . (p, 1)). */
#define DEPTH(p) (-((double)z[2] * (p)[0] + (double)z[6] * (p)[1] + (double)z[10] * (p)[2] + (double)z[14]))

float lm_view_box_reach(const lm_view *v, const float lo[3], const float hi[3])
{
    const float *z = v->view;
    double reach = -INFINITY, q[4];
    for (int c = 0; c < 8; c++) {
        double corner[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        reach = fmax(reach, DEPTH(corner));
    }
    float vp[16], inv[16];
    lm_mat4_mul(vp, v->proj, v->view);
    if (lm_mat4_invert(inv, vp)) {
        transform4(inv, 0.0, 0.0, 1.0, q); /* the far plane's centre */
        if (q[3] > 1e-12 * (fabs(q[0]) + fabs(q[1]) + fabs(q[2]))) {
            double far[3] = {q[0] / q[3], q[1] / q[3], q[2] / q[3]};
            reach = fmin(reach, DEPTH(far));
        }
    }
    return (float)reach;
}

int lm_view_box_part(const lm_view *v, const float lo[3], const float hi[3], float max_depth, float pts[][3])
{
    float vp[16], inv[16];
    lm_mat4_mul(vp, v->proj, v->view);
    if (!lm_mat4_invert(inv, vp))
        return 0;
    const float *z = v->view;
    double reach = lm_view_box_reach(v, lo, hi); /* no farther than the box, the far plane and max_depth */
    if (max_depth > 0.0f)
        reach = fmin(reach, (double)max_depth);
    /* The frustum cut at depth `reach`: corners c = x + 2 y + 4 z (z 0 near, 1 cut). */
    double corner[8][3];
    for (int c = 0; c < 4; c++) {
        double x = c & 1 ? 1.0 : -1.0, y = c & 2 ? 1.0 : -1.0, n[4], f[4];
        transform4(inv, x, y, -1.0, n);
        transform4(inv, x, y, 1.0, f);
        if (!(n[3] > 0.0))
            return 0;
        for (int k = 0; k < 3; k++)
            corner[c][k] = n[k] / n[3];
        double dn = DEPTH(corner[c]), dir[3], dd;
        if (reach <= dn)
            return 0; /* the box lies nearer than the near plane */
        int finite = f[3] > 1e-12 * (fabs(f[0]) + fabs(f[1]) + fabs(f[2])); /* the far plane */
        for (int k = 0; k < 3; k++) /* towards the far corner, or along the ray to it at infinity */
            dir[k] = finite ? f[k] / f[3] - corner[c][k] : f[k];
        dd = DEPTH(dir) + (double)z[14]; /* the direction's depth, without the translation */
        double t = dd > 0.0 ? (reach - dn) / dd : 0.0;
        if (finite)
            t = fmin(t, 1.0);
        for (int k = 0; k < 3; k++)
            corner[c + 4][k] = corner[c][k] + t * dir[k];
    }
    double cut = DEPTH(corner[4]);
    double planes[6][4]; /* the frustum's sides and near plane (clip space's w + x, w - x, ...), the cut */
    for (int p = 0; p < 5; p++)
        for (int k = 0; k < 4; k++)
            planes[p][k] = (double)vp[k * 4 + 3] + (p % 2 ? -1.0 : 1.0) * (double)vp[k * 4 + p / 2];
    for (int k = 0; k < 3; k++) /* depth <= cut */
        planes[5][k] = (double)z[k * 4 + 2];
    planes[5][3] = (double)z[14] + cut;
    double box[6][4]; /* x >= lo, x <= hi, ... */
    for (int f = 0; f < 6; f++) {
        memset(box[f], 0, sizeof box[f]);
        box[f][f / 2] = f % 2 ? -1.0 : 1.0;
        box[f][3] = f % 2 ? hi[f / 2] : -lo[f / 2];
    }
    /* A vertex of the part lies on a face of the box or of the cut frustum, and that face clipped by the
     * other solid keeps it. */
    int n = 0;
    for (int face = 0; face < 6; face++) {
        int axis = face / 2, u = (axis + 1) % 3, w = (axis + 2) % 3;
        double poly[4][3];
        for (int c = 0; c < 4; c++) {
            poly[c][axis] = face % 2 ? hi[axis] : lo[axis];
            poly[c][u] = c == 1 || c == 2 ? hi[u] : lo[u];
            poly[c][w] = c >= 2 ? hi[w] : lo[w];
        }
        clip_append((const double(*)[4])planes, 6, (const double(*)[3])poly, 4, pts, &n);
    }
    static const int faces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    for (int f = 0; f < 6; f++) {
        double poly[4][3];
        for (int c = 0; c < 4; c++)
            memcpy(poly[c], corner[faces[f][c]], sizeof poly[c]);
        clip_append((const double(*)[4])box, 6, (const double(*)[3])poly, 4, pts, &n);
    }
    return n;
}
#undef DEPTH
