/* Small vector and matrix helpers. Matrices are 4x4, column-major (as in glTF and OpenGL):
 * element (row r, column c) is m[c * 4 + r]. */
#ifndef LM_VECMATH_H
#define LM_VECMATH_H

#include <math.h>

/* pi, once for every layer: double, and float for arithmetic that must stay in float. */
#define LM_PI 3.14159265358979323846
#define LM_PI_F 3.14159265358979323846f
#define LM_PI_GLSL "3.14159265358979" /* the same in shader source */

typedef struct { float x, y, z; } lm_vec3;

static inline lm_vec3 lm_v3(float x, float y, float z) { lm_vec3 v = {x, y, z}; return v; }
static inline lm_vec3 lm_v3_load(const float *p) { return lm_v3(p[0], p[1], p[2]); }
static inline void lm_v3_store(float *p, lm_vec3 v) { p[0] = v.x; p[1] = v.y; p[2] = v.z; }
static inline lm_vec3 lm_add(lm_vec3 a, lm_vec3 b) { return lm_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline lm_vec3 lm_sub(lm_vec3 a, lm_vec3 b) { return lm_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline lm_vec3 lm_scale(lm_vec3 a, float s) { return lm_v3(a.x * s, a.y * s, a.z * s); }
static inline float lm_dot(lm_vec3 a, lm_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline lm_vec3 lm_cross(lm_vec3 a, lm_vec3 b)
{
    return lm_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float lm_length(lm_vec3 a) { return sqrtf(lm_dot(a, a)); }
static inline lm_vec3 lm_normalize(lm_vec3 a)
{
    float l = lm_length(a);
    return l > 0.0f ? lm_scale(a, 1.0f / l) : lm_v3(0.0f, 0.0f, 0.0f);
}
static inline lm_vec3 lm_vmin(lm_vec3 a, lm_vec3 b)
{
    return lm_v3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z));
}
static inline lm_vec3 lm_vmax(lm_vec3 a, lm_vec3 b)
{
    return lm_v3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z));
}
/* Unit t and b with (t, b, n) orthonormal for unit n, from a fixed helper axis (the hemicube's plane axes). */
static inline void lm_tangents(lm_vec3 n, lm_vec3 *t, lm_vec3 *b)
{
    lm_vec3 helper = fabsf(n.x) < 0.9f ? lm_v3(1, 0, 0) : lm_v3(0, 1, 0);
    *t = lm_normalize(lm_cross(helper, n));
    *b = lm_cross(n, *t);
}
/* Relative luminance of linear Rec. 709 RGB (the weights every brightness figure of lmgi uses). */
static inline float lm_luminance(const float c[3]) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }
static inline int lm_v3_finite(lm_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
/* Unit t and b with (t, b, n) orthonormal for unit n, without a branch or a square root (Duff et al.
 * 2017, "Building an orthonormal basis, revisited"): the sampling frame of photons and BSDF lobes. */
static inline void lm_onb(lm_vec3 n, lm_vec3 *t, lm_vec3 *b)
{
    float sign = copysignf(1.0f, n.z), a = -1.0f / (sign + n.z), c = n.x * n.y * a;
    *t = lm_v3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
    *b = lm_v3(c, sign + n.y * n.y * a, -n.y);
}
/* x t + y b + z n: a direction given in the orthonormal frame (t, b, n), unit for unit (x, y, z) up to
 * rounding. */
static inline lm_vec3 lm_frame_dir(lm_vec3 t, lm_vec3 b, lm_vec3 n, float x, float y, float z)
{
    return lm_add(lm_add(lm_scale(t, x), lm_scale(b, y)), lm_scale(n, z));
}
/* lm_frame_dir in lm_onb's frame around unit n. */
static inline lm_vec3 lm_onb_dir(lm_vec3 n, float x, float y, float z)
{
    lm_vec3 t, b;
    lm_onb(n, &t, &b);
    return lm_frame_dir(t, b, n, x, y, z);
}
/* sin and cos of the angle 2 pi u, u in [0, 1) (a sampled azimuth), within 1e-7 of the exact values:
 * a quarter turn picked by rounding 4u, then Taylor polynomials to degree 9 and 8 on |r| <= pi / 4
 * (truncation below 3e-8). Several times cheaper than sincosf, which must reduce any argument, and
 * without branches: the quadrant is random for every photon. */
static inline void lm_sincos_turn(float u, float *s, float *c)
{
    float y = 4.0f * u;
    int q = (int)(y + 0.5f); /* nearest quarter turn, 0..4 */
    float r = (y - (float)q) * 1.57079632679489662f, r2 = r * r;
    float sn = r * (1.0f + r2 * (-1.0f / 6 + r2 * (1.0f / 120 + r2 * (-1.0f / 5040 + r2 * (1.0f / 362880)))));
    float cs = 1.0f + r2 * (-0.5f + r2 * (1.0f / 24 + r2 * (-1.0f / 720 + r2 * (1.0f / 40320))));
    float sa = q & 1 ? cs : sn, ca = q & 1 ? sn : cs; /* sin(r + q pi/2), cos(r + q pi/2) up to sign */
    *s = q & 2 ? -sa : sa;
    *c = (q + 1) & 2 ? -ca : ca;
}
/* Cosine-weighted direction around unit n (pdf cos / pi) from two uniform numbers: a diffuse bounce, a
 * look at the sky. Unit up to rounding. The sine of the polar angle comes straight from u0, so the two
 * roots are independent. */
static inline lm_vec3 lm_cosine_dir(lm_vec3 n, float u0, float u1)
{
    float s = sqrtf(u0), sn, cs;
    lm_sincos_turn(u1, &sn, &cs);
    return lm_onb_dir(n, s * cs, s * sn, sqrtf(1.0f - u0));
}

void lm_mat4_identity(float m[16]);
void lm_mat4_mul(float out[16], const float a[16], const float b[16]); /* out = a * b (out may alias) */
/* Builds T * R * S from translation, unit quaternion (x, y, z, w) and scale, as glTF defines. */
void lm_mat4_from_trs(float m[16], const float t[3], const float q[4], const float s[3]);
/* Inverse of a general affine matrix; returns 0 if singular. */
int lm_mat4_invert_affine(float out[16], const float m[16]);
/* Inverse of any 4 x 4 matrix (a projection too); returns 0 if singular. */
int lm_mat4_invert(float out[16], const float m[16]);
/* Inline: photon shading transforms every hit with these two, without a call per hit. */
static inline lm_vec3 lm_mat4_point(const float m[16], lm_vec3 p)
{
    return lm_v3(m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12],
                 m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
                 m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]);
}
lm_vec3 lm_mat4_dir(const float m[16], lm_vec3 d);
/* The world box (min x, y, z, max x, y, z) of a local box under m: its 8 corners placed. */
void lm_box_placed(const float local[6], const float m[16], float out[6]);
/* The matrix that takes normals to world space under m: the cofactors of m's upper 3x3 (its inverse
 * transpose times det), turned by det's sign so the normal keeps its side. Column-major 3x3. */
static inline void lm_mat4_normal_matrix(const float m[16], float out[9])
{
    lm_vec3 c0 = lm_v3(m[0], m[1], m[2]), c1 = lm_v3(m[4], m[5], m[6]), c2 = lm_v3(m[8], m[9], m[10]);
    lm_vec3 r0 = lm_cross(c1, c2), r1 = lm_cross(c2, c0), r2 = lm_cross(c0, c1);
    float sign = lm_dot(c0, r0) < 0.0f ? -1.0f : 1.0f;
    lm_v3_store(out, lm_scale(r0, sign));
    lm_v3_store(out + 3, lm_scale(r1, sign));
    lm_v3_store(out + 6, lm_scale(r2, sign));
}
/* A normal through a normal matrix (lm_mat4_normal_matrix), not normalized. */
static inline lm_vec3 lm_mat3_normal(const float nm[9], lm_vec3 n)
{
    return lm_add(lm_add(lm_scale(lm_v3_load(nm), n.x), lm_scale(lm_v3_load(nm + 3), n.y)),
                  lm_scale(lm_v3_load(nm + 6), n.z));
}
/* A shading normal: the local normal n through normal matrix nm, unit, turned to the side of the unit
 * geometric normal ng; ng itself where n degenerates (zero, or not finite). */
static inline lm_vec3 lm_shading_normal_of(const float nm[9], lm_vec3 n, lm_vec3 ng)
{
    lm_vec3 w = lm_normalize(lm_mat3_normal(nm, n));
    if (!lm_v3_finite(w) || lm_dot(w, w) < 0.5f)
        return ng;
    return lm_dot(w, ng) < 0.0f ? lm_scale(w, -1.0f) : w;
}
/* Normal transform: inverse-transpose of the upper 3x3, result normalized. The cofactor matrix is det
 * times the inverse-transpose: the scale drops out on normalization, and flipping by the sign of det
 * gives the true inverse-transpose for mirroring transforms too. */
static inline lm_vec3 lm_mat4_normal(const float m[16], lm_vec3 n)
{
    float nm[9];
    lm_mat4_normal_matrix(m, nm);
    return lm_normalize(lm_mat3_normal(nm, n));
}
int lm_mat4_finite(const float m[16]);
/* Whether the upper 3 x 3 is singular: |det| below 1e-6 of the product of its column lengths (a zero
 * scale, or columns so nearly parallel that normals and the inverse lose every digit). */
int lm_mat4_singular(const float m[16]);
/* Whether the upper 3 x 3 mirrors (a negative determinant: it turns a triangle's winding over). */
int lm_mat4_mirrors(const float m[16]);
void lm_mat4_perspective(float m[16], float yfov, float aspect, float znear, float zfar);
void lm_mat4_look_at(float m[16], lm_vec3 eye, lm_vec3 target, lm_vec3 up);

/* Quaternions (x, y, z, w). */
void lm_quat_normalize(float q[4]);
void lm_quat_slerp(float out[4], const float a[4], const float b[4], float t);

#endif
