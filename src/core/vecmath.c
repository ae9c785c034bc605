#include "vecmath.h"

#include <string.h>

void lm_mat4_identity(float m[16])
{
    memset(m, 0, 16 * sizeof(float));
    m[0] = m[5] = m[10] = m[15] = 1.0f;
}

void lm_mat4_mul(float out[16], const float a[16], const float b[16])
{
    float r[16];
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            float s = 0.0f;
            for (int k = 0; k < 4; k++)
                s += a[k * 4 + row] * b[c * 4 + k];
            r[c * 4 + row] = s;
        }
    memcpy(out, r, sizeof r);
}

void lm_mat4_from_trs(float m[16], const float t[3], const float q[4], const float s[3])
{
    float x = q[0], y = q[1], z = q[2], w = q[3];
    float r[9] = {
        1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
        2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
        2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y),
    }; /* column-major 3x3 */
    for (int c = 0; c < 3; c++) {
        for (int row = 0; row < 3; row++)
            m[c * 4 + row] = r[c * 3 + row] * s[c];
        m[c * 4 + 3] = 0.0f;
    }
    m[12] = t[0];
    m[13] = t[1];
    m[14] = t[2];
    m[15] = 1.0f;
}

int lm_mat4_invert_affine(float out[16], const float m[16])
{
    /* Inverse of the 3x3 part by cofactors, then the translation. */
    float a = m[0], b = m[4], c = m[8];
    float d = m[1], e = m[5], f = m[9];
    float g = m[2], h = m[6], i = m[10];
    float A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    float det = a * A + b * B + c * C;
    if (!(fabsf(det) > 1e-30f))
        return 0;
    float inv = 1.0f / det;
    float r[16];
    r[0] = A * inv;
    r[1] = B * inv;
    r[2] = C * inv;
    r[4] = -(b * i - c * h) * inv;
    r[5] = (a * i - c * g) * inv;
    r[6] = -(a * h - b * g) * inv;
    r[8] = (b * f - c * e) * inv;
    r[9] = -(a * f - c * d) * inv;
    r[10] = (a * e - b * d) * inv;
    r[3] = r[7] = r[11] = 0.0f;
    r[15] = 1.0f;
    for (int row = 0; row < 3; row++)
        r[12 + row] = -(r[row] * m[12] + r[4 + row] * m[13] + r[8 + row] * m[14]);
    memcpy(out, r, sizeof r);
    return 1;
}

lm_vec3 lm_mat4_dir(const float m[16], lm_vec3 d)
{
    return lm_v3(m[0] * d.x + m[4] * d.y + m[8] * d.z,
                 m[1] * d.x + m[5] * d.y + m[9] * d.z,
                 m[2] * d.x + m[6] * d.y + m[10] * d.z);
}

void lm_box_placed(const float b[6], const float m[16], float out[6])
{
    out[0] = out[1] = out[2] = INFINITY, out[3] = out[4] = out[5] = -INFINITY;
    for (int c = 0; c < 8; c++) {
        lm_vec3 p = lm_mat4_point(m, lm_v3(b[c & 1 ? 3 : 0], b[c & 2 ? 4 : 1], b[c & 4 ? 5 : 2]));
        const float q[3] = {p.x, p.y, p.z};
        for (int a = 0; a < 3; a++)
            out[a] = fminf(out[a], q[a]), out[3 + a] = fmaxf(out[3 + a], q[a]);
    }
}

int lm_mat4_singular(const float m[16])
{
    lm_vec3 a = lm_v3(m[0], m[1], m[2]), b = lm_v3(m[4], m[5], m[6]), c = lm_v3(m[8], m[9], m[10]);
    double det = lm_dot(a, lm_cross(b, c)), scale = (double)lm_length(a) * lm_length(b) * lm_length(c);
    return !(fabs(det) > 1e-6 * scale);
}

int lm_mat4_mirrors(const float m[16])
{
    lm_vec3 a = lm_v3(m[0], m[1], m[2]), b = lm_v3(m[4], m[5], m[6]), c = lm_v3(m[8], m[9], m[10]);
    return lm_dot(a, lm_cross(b, c)) < 0.0f;
}

int lm_mat4_finite(const float m[16])
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(m[i]))
            return 0;
    return 1;
}

void lm_mat4_perspective(float m[16], float yfov, float aspect, float znear, float zfar)
{
    float f = 1.0f / tanf(0.5f * yfov);
    memset(m, 0, 16 * sizeof(float));
    m[0] = f / aspect;
    m[5] = f;
    m[10] = (zfar + znear) / (znear - zfar);
    m[11] = -1.0f;
    m[14] = 2.0f * zfar * znear / (znear - zfar);
}

void lm_mat4_look_at(float m[16], lm_vec3 eye, lm_vec3 target, lm_vec3 up)
{
    lm_vec3 f = lm_normalize(lm_sub(target, eye));
    lm_vec3 s = lm_normalize(lm_cross(f, up));
    lm_vec3 u = lm_cross(s, f);
    lm_mat4_identity(m);
    m[0] = s.x; m[4] = s.y; m[8] = s.z;
    m[1] = u.x; m[5] = u.y; m[9] = u.z;
    m[2] = -f.x; m[6] = -f.y; m[10] = -f.z;
    m[12] = -lm_dot(s, eye);
    m[13] = -lm_dot(u, eye);
    m[14] = lm_dot(f, eye);
}

void lm_quat_normalize(float q[4])
{
    float l = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (l > 0.0f)
        for (int i = 0; i < 4; i++)
            q[i] /= l;
}

void lm_quat_slerp(float out[4], const float a[4], const float b[4], float t)
{
    float bb[4] = {b[0], b[1], b[2], b[3]};
    float d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    if (d < 0.0f) { /* take the short way round */
        d = -d;
        for (int i = 0; i < 4; i++)
            bb[i] = -bb[i];
    }
    float wa, wb;
    if (d > 0.9995f) { /* nearly parallel: lerp avoids dividing by sin(theta) ~ 0 */
        wa = 1.0f - t;
        wb = t;
    } else {
        float th = acosf(d), s = sinf(th);
        wa = sinf((1.0f - t) * th) / s;
        wb = sinf(t * th) / s;
    }
    for (int i = 0; i < 4; i++)
        out[i] = wa * a[i] + wb * bb[i];
    lm_quat_normalize(out);
}

int lm_mat4_invert(float out[16], const float m[16])
{
    /* Gauss-Jordan with partial pivoting, in double: a projection's rows differ by orders of magnitude. */
    double a[4][8];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            a[r][c] = m[c * 4 + r];
            a[r][4 + c] = r == c;
        }
    for (int c = 0; c < 4; c++) {
        int p = c;
        for (int r = c + 1; r < 4; r++)
            p = fabs(a[r][c]) > fabs(a[p][c]) ? r : p;
        if (!(fabs(a[p][c]) > 1e-300))
            return 0;
        for (int k = 0; k < 8; k++) {
            double t = a[c][k];
            a[c][k] = a[p][k];
            a[p][k] = t;
        }
        double inv = 1.0 / a[c][c];
        for (int k = 0; k < 8; k++)
            a[c][k] *= inv;
        for (int r = 0; r < 4; r++)
            if (r != c) {
                double f = a[r][c];
                for (int k = 0; k < 8; k++)
                    a[r][k] -= f * a[c][k];
            }
    }
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            out[c * 4 + r] = (float)a[r][4 + c];
    return 1;
}
