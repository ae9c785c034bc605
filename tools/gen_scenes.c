/* gen_scenes — writes lmgi's own test scenes as binary glTF 2.0 (.glb).
 *
 * Usage:
 *   gen_scenes DIR                 writes DIR/cornell.glb, DIR/two_rooms.glb, DIR/many_rooms.glb,
 *                                  DIR/sunlit_room.glb
 *   gen_scenes --rooms N OUTFILE   writes a many_rooms variant with N rooms to OUTFILE (benchmark sizes)
 *   gen_scenes --cornell-cells N OUTFILE  writes cornell.glb with an N x N cell floor (benchmark sizes)
 *
 * Output is deterministic: a fixed pseudo-random seed, no clocks, fixed float formatting, so running it
 * twice gives identical bytes. Units are metres, +Y is up. lmgi conventions used here:
 *   - node extras {"lmgi": {"dynamic": true}} marks a node that may move (animated nodes get it too);
 *     {"lmgi": {"caustics": false}} switches caustics off for a node;
 *   - KHR_lights_punctual point lights (candela), KHR_materials_transmission + KHR_materials_ior glass;
 *   - every scene has a perspective camera node (looks down its local -Z, +Y up).
 * Only libc and libm. */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

/* ------------------------------------------------------------------------------------------------ */
/* Small vector maths                                                                                */

typedef struct { float x, y, z; } v3;

static v3 V(double x, double y, double z) { v3 r = {(float)x, (float)y, (float)z}; return r; }
static v3 vadd(v3 a, v3 b) { return V(a.x + b.x, a.y + b.y, a.z + b.z); }
static v3 vsub(v3 a, v3 b) { return V(a.x - b.x, a.y - b.y, a.z - b.z); }
static v3 vscale(v3 a, double s) { return V(a.x * s, a.y * s, a.z * s); }
static double vdot(v3 a, v3 b) { return (double)a.x * b.x + (double)a.y * b.y + (double)a.z * b.z; }
static v3 vcross(v3 a, v3 b)
{
    return V((double)a.y * b.z - (double)a.z * b.y, (double)a.z * b.x - (double)a.x * b.z,
             (double)a.x * b.y - (double)a.y * b.x);
}
static v3 vnorm(v3 a)
{
    double l = sqrt(vdot(a, a));
    return l > 0 ? vscale(a, 1.0 / l) : a;
}

/* Quaternion (x, y, z, w) for a rotation of deg degrees about +Y. */
static void quat_y(double deg, float q[4])
{
    double h = deg * PI / 360.0;
    q[0] = 0.0f; q[1] = (float)sin(h); q[2] = 0.0f; q[3] = (float)cos(h);
}

/* Quaternion turning a camera (looking down local -Z, +Y up) at eye to look at target. */
static void quat_look_at(v3 eye, v3 target, float q[4])
{
    v3 f = vnorm(vsub(target, eye));
    v3 x = vnorm(vcross(f, V(0, 1, 0)));
    v3 y = vcross(x, f);
    v3 z = vscale(f, -1.0);
    /* rotation matrix with columns x, y, z -> quaternion */
    double m00 = x.x, m11 = y.y, m22 = z.z, tr = m00 + m11 + m22, qx, qy, qz, qw;
    if (tr > 0) {
        double s = sqrt(tr + 1.0) * 2;
        qw = 0.25 * s; qx = (y.z - z.y) / s; qy = (z.x - x.z) / s; qz = (x.y - y.x) / s;
    } else if (m00 > m11 && m00 > m22) {
        double s = sqrt(1.0 + m00 - m11 - m22) * 2;
        qw = (y.z - z.y) / s; qx = 0.25 * s; qy = (y.x + x.y) / s; qz = (z.x + x.z) / s;
    } else if (m11 > m22) {
        double s = sqrt(1.0 + m11 - m00 - m22) * 2;
        qw = (z.x - x.z) / s; qx = (y.x + x.y) / s; qy = 0.25 * s; qz = (z.y + y.z) / s;
    } else {
        double s = sqrt(1.0 + m22 - m00 - m11) * 2;
        qw = (x.y - y.x) / s; qx = (z.x + x.z) / s; qy = (z.y + y.z) / s; qz = 0.25 * s;
    }
    double l = sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
    q[0] = (float)(qx / l); q[1] = (float)(qy / l); q[2] = (float)(qz / l); q[3] = (float)(qw / l);
}

/* Deterministic xorshift32 generator; the seed is fixed per scene. */
static uint32_t rng_state = 0x1234567u;
static double rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return (rng_state >> 8) * (1.0 / 16777216.0);
}

static void die(const char *msg)
{
    fprintf(stderr, "gen_scenes: %s\n", msg);
    exit(1);
}

static void *xrealloc(void *p, size_t n)
{
    void *q = realloc(p, n ? n : 1);
    if (!q) die("out of memory");
    return q;
}

/* ------------------------------------------------------------------------------------------------ */
/* Growable byte buffer (JSON text and the binary chunk)                                            */

typedef struct { char *p; size_t n, cap; } buf;

static void buf_put(buf *b, const void *data, size_t len)
{
    if (b->n + len + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (cap < b->n + len + 1) cap *= 2;
        b->p = xrealloc(b->p, cap);
        b->cap = cap;
    }
    memcpy(b->p + b->n, data, len);
    b->n += len;
    b->p[b->n] = 0; /* keeps text buffers NUL-terminated */
}

static void buf_printf(buf *b, const char *fmt, ...)
{
    char tmp[1024];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof tmp) die("JSON fragment too long");
    buf_put(b, tmp, (size_t)n);
}

static void buf_pad(buf *b, size_t align, char fill)
{
    while (b->n % align) buf_put(b, &fill, 1);
}

static void buf_free(buf *b)
{
    free(b->p);
    memset(b, 0, sizeof *b);
}

/* Appends the shortest decimal (6 to 9 significant digits) that reads back as the same float, so
 * accessor min/max match the data bit for bit and round numbers stay readable. */
static void buf_num(buf *b, double v)
{
    char tmp[32];
    float f = (float)v;
    for (int digits = 6; digits <= 9; digits++) {
        snprintf(tmp, sizeof tmp, "%.*g", digits, (double)f);
        if (strtof(tmp, NULL) == f) break;
    }
    buf_put(b, tmp, strlen(tmp));
}

/* Comma-separated numbers. */
static void buf_nums(buf *b, const float *v, int n)
{
    for (int i = 0; i < n; i++) {
        if (i) buf_put(b, ",", 1);
        buf_num(b, v[i]);
    }
}

/* Separator for JSON arrays built one item at a time. */
static void buf_sep(buf *b, int count)
{
    if (count > 0) buf_put(b, ",", 1);
}

/* ------------------------------------------------------------------------------------------------ */
/* Mesh builder: indexed triangles with position, normal, texcoord                                  */

typedef struct {
    float *pos, *nrm, *uv;
    uint32_t nv, capv;
    uint32_t *idx;
    uint32_t ntri, capt;
} mesh;

static uint32_t mesh_vert(mesh *m, v3 p, v3 n, double u, double v)
{
    if (m->nv == m->capv) {
        m->capv = m->capv ? m->capv * 2 : 64;
        m->pos = xrealloc(m->pos, m->capv * 3 * sizeof(float));
        m->nrm = xrealloc(m->nrm, m->capv * 3 * sizeof(float));
        m->uv = xrealloc(m->uv, m->capv * 2 * sizeof(float));
    }
    n = vnorm(n);
    float *P = m->pos + 3 * m->nv, *N = m->nrm + 3 * m->nv, *T = m->uv + 2 * m->nv;
    P[0] = p.x; P[1] = p.y; P[2] = p.z;
    N[0] = n.x; N[1] = n.y; N[2] = n.z;
    T[0] = (float)u; T[1] = (float)v;
    return m->nv++;
}

static v3 mesh_p(const mesh *m, uint32_t i) { return V(m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2]); }
static v3 mesh_n(const mesh *m, uint32_t i) { return V(m->nrm[3 * i], m->nrm[3 * i + 1], m->nrm[3 * i + 2]); }

/* Adds a triangle, wound counter-clockwise as seen from the side its vertex normals point to: the
 * builders below only have to get the normals right, the winding follows from them. */
static void mesh_tri(mesh *m, uint32_t a, uint32_t b, uint32_t c)
{
    v3 g = vcross(vsub(mesh_p(m, b), mesh_p(m, a)), vsub(mesh_p(m, c), mesh_p(m, a)));
    v3 n = vadd(vadd(mesh_n(m, a), mesh_n(m, b)), mesh_n(m, c));
    if (vdot(g, n) < 0) { uint32_t t = b; b = c; c = t; }
    if (m->ntri == m->capt) {
        m->capt = m->capt ? m->capt * 2 : 64;
        m->idx = xrealloc(m->idx, m->capt * 3 * sizeof(uint32_t));
    }
    m->idx[3 * m->ntri] = a; m->idx[3 * m->ntri + 1] = b; m->idx[3 * m->ntri + 2] = c;
    m->ntri++;
}

static void mesh_free(mesh *m)
{
    free(m->pos); free(m->nrm); free(m->uv); free(m->idx);
    memset(m, 0, sizeof *m);
}

/* A flat quad p0..p3 (in cyclic order) facing n, with its own four vertices. */
static void mesh_quad(mesh *m, v3 p0, v3 p1, v3 p2, v3 p3, v3 n)
{
    uint32_t a = mesh_vert(m, p0, n, 0, 0), b = mesh_vert(m, p1, n, 1, 0);
    uint32_t c = mesh_vert(m, p2, n, 1, 1), d = mesh_vert(m, p3, n, 0, 1);
    mesh_tri(m, a, b, c);
    mesh_tri(m, a, c, d);
}

/* A planar grid o + U*ub[i] + W*wb[j] facing n; cell (i, j) is left out when bit j*8+i of skip is set
 * (used for doorways). Vertices are shared, so the piece stays one connected surface. */
static void mesh_plane(mesh *m, v3 o, v3 U, v3 W, const float *ub, int nub, const float *wb, int nwb,
                       uint64_t skip, v3 n)
{
    uint32_t base = m->nv;
    for (int j = 0; j < nwb; j++)
        for (int i = 0; i < nub; i++)
            mesh_vert(m, vadd(o, vadd(vscale(U, ub[i]), vscale(W, wb[j]))), n, ub[i], wb[j]);
    for (int j = 0; j + 1 < nwb; j++)
        for (int i = 0; i + 1 < nub; i++) {
            if (skip >> (j * 8 + i) & 1) continue;
            uint32_t a = base + (uint32_t)(j * nub + i), b = a + 1, c = a + (uint32_t)nub + 1, d = a + (uint32_t)nub;
            mesh_tri(m, a, b, c);
            mesh_tri(m, a, c, d);
        }
}

/* Box faces, outward normals, separate vertices per face (flat shading, one surface per face). */
enum { F_PX = 1, F_NX = 2, F_PY = 4, F_NY = 8, F_PZ = 16, F_NZ = 32, F_ALL = 63 };
static void mesh_box(mesh *m, v3 lo, v3 hi, int faces)
{
    float X0 = lo.x, Y0 = lo.y, Z0 = lo.z, X1 = hi.x, Y1 = hi.y, Z1 = hi.z;
    if (faces & F_PX) mesh_quad(m, V(X1, Y0, Z0), V(X1, Y1, Z0), V(X1, Y1, Z1), V(X1, Y0, Z1), V(1, 0, 0));
    if (faces & F_NX) mesh_quad(m, V(X0, Y0, Z0), V(X0, Y0, Z1), V(X0, Y1, Z1), V(X0, Y1, Z0), V(-1, 0, 0));
    if (faces & F_PY) mesh_quad(m, V(X0, Y1, Z0), V(X0, Y1, Z1), V(X1, Y1, Z1), V(X1, Y1, Z0), V(0, 1, 0));
    if (faces & F_NY) mesh_quad(m, V(X0, Y0, Z0), V(X1, Y0, Z0), V(X1, Y0, Z1), V(X0, Y0, Z1), V(0, -1, 0));
    if (faces & F_PZ) mesh_quad(m, V(X0, Y0, Z1), V(X1, Y0, Z1), V(X1, Y1, Z1), V(X0, Y1, Z1), V(0, 0, 1));
    if (faces & F_NZ) mesh_quad(m, V(X0, Y0, Z0), V(X0, Y1, Z0), V(X1, Y1, Z0), V(X1, Y0, Z0), V(0, 0, -1));
}

/* Box with rounded edges and corners (radius r < every half extent), centred at c with half extents h.
 * Each face is a (2k+1)^2 grid: k cells across each rounded band, one across the flat middle. Band
 * breakpoints use tan() so the band's vertices are evenly spaced in angle. */
static void mesh_rounded_box(mesh *m, v3 c, v3 h, double r, int k)
{
    const float he[3] = {h.x, h.y, h.z};
    int nb = 2 * k + 2;
    for (int face = 0; face < 6; face++) {
        int a = face / 2, b = (a + 1) % 3, d = (a + 2) % 3;
        double sgn = face % 2 ? -1.0 : 1.0;
        double cb[16], cd[16];
        for (int i = 0; i < nb; i++) { /* coordinates along b and d on the unrounded box face */
            double t = i <= k ? tan(PI / 4 * (double)(k - i) / k) : tan(PI / 4 * (double)(i - k - 1) / k);
            double s = i <= k ? -1.0 : 1.0;
            cb[i] = s * (he[b] - r + r * t);
            cd[i] = s * (he[d] - r + r * t);
        }
        uint32_t base = m->nv;
        for (int j = 0; j < nb; j++)
            for (int i = 0; i < nb; i++) {
                double s[3], in[3];
                s[a] = sgn * he[a]; s[b] = cb[i]; s[d] = cd[j];
                for (int q = 0; q < 3; q++) {
                    double lim = he[q] - r;
                    in[q] = s[q] < -lim ? -lim : s[q] > lim ? lim : s[q];
                }
                v3 dir = vnorm(V(s[0] - in[0], s[1] - in[1], s[2] - in[2]));
                v3 p = vadd(c, vadd(V(in[0], in[1], in[2]), vscale(dir, r)));
                mesh_vert(m, p, dir, (double)i / (nb - 1), (double)j / (nb - 1));
            }
        for (int j = 0; j + 1 < nb; j++)
            for (int i = 0; i + 1 < nb; i++) {
                uint32_t v0 = base + (uint32_t)(j * nb + i), v1 = v0 + 1, v2 = v0 + (uint32_t)nb + 1, v3i = v0 + (uint32_t)nb;
                mesh_tri(m, v0, v1, v2);
                mesh_tri(m, v0, v2, v3i);
            }
    }
}

/* Vertical cylinder standing on base centre c; caps: bit 0 bottom, bit 1 top. */
static void mesh_cylinder(mesh *m, v3 c, double r, double hgt, int seg, int caps)
{
    uint32_t base = m->nv;
    for (int ring = 0; ring < 2; ring++)
        for (int i = 0; i <= seg; i++) {
            double a = 2 * PI * (i % seg) / seg;
            v3 n = V(cos(a), 0, sin(a));
            mesh_vert(m, vadd(c, V(r * cos(a), ring * hgt, r * sin(a))), n, (double)i / seg, ring);
        }
    for (int i = 0; i < seg; i++) {
        uint32_t a = base + (uint32_t)i, b = a + 1, d = a + (uint32_t)seg + 1, e = d + 1;
        mesh_tri(m, a, b, e);
        mesh_tri(m, a, e, d);
    }
    for (int cap = 0; cap < 2; cap++) {
        if (!(caps >> cap & 1)) continue;
        v3 n = V(0, cap ? 1 : -1, 0);
        double y = cap ? hgt : 0;
        uint32_t centre = mesh_vert(m, vadd(c, V(0, y, 0)), n, 0.5, 0.5);
        uint32_t rim = m->nv;
        for (int i = 0; i < seg; i++) {
            double a = 2 * PI * i / seg;
            mesh_vert(m, vadd(c, V(r * cos(a), y, r * sin(a))), n, 0.5 + 0.5 * cos(a), 0.5 + 0.5 * sin(a));
        }
        for (int i = 0; i < seg; i++)
            mesh_tri(m, centre, rim + (uint32_t)i, rim + (uint32_t)((i + 1) % seg));
    }
}

/* Surface of revolution about the vertical axis through c. The profile (pr[i], py[i]) starts and ends
 * on the axis (pr = 0), so the result is closed; its normal points to the right of the direction of
 * travel along the profile (outward for a profile that goes up the outside). */
static void mesh_lathe(mesh *m, v3 c, const float *pr, const float *py, int np, int seg)
{
    uint32_t base = m->nv;
    for (int j = 0; j < np; j++) {
        int j0 = j > 0 ? j - 1 : j, j1 = j + 1 < np ? j + 1 : j;
        double tr = pr[j1] - pr[j0], ty = py[j1] - py[j0];
        double nr = ty, ny = -tr; /* tangent turned -90 degrees */
        if (pr[j] == 0.0f) { nr = 0; ny = ny >= 0 ? 1 : -1; } /* poles: straight up or down */
        for (int i = 0; i <= seg; i++) {
            double a = 2 * PI * (i % seg) / seg;
            v3 n = V(nr * cos(a), ny, nr * sin(a));
            mesh_vert(m, vadd(c, V(pr[j] * cos(a), py[j], pr[j] * sin(a))), n, (double)i / seg, (double)j / (np - 1));
        }
    }
    for (int j = 0; j + 1 < np; j++)
        for (int i = 0; i < seg; i++) {
            uint32_t a = base + (uint32_t)(j * (seg + 1) + i), b = a + 1, d = a + (uint32_t)seg + 1, e = d + 1;
            if (pr[j] != 0.0f) mesh_tri(m, a, b, e);     /* a pole row would make this one degenerate */
            if (pr[j + 1] != 0.0f) mesh_tri(m, a, e, d);
        }
}

/* UV sphere: seg segments around, rings from pole to pole. */
static void mesh_sphere(mesh *m, v3 c, double r, int seg, int rings)
{
    float pr[129], py[129];
    if (rings > 128) die("sphere: too many rings");
    for (int j = 0; j <= rings; j++) { /* profile from the south pole up */
        double th = PI * j / rings;
        pr[j] = (float)(r * sin(th));
        py[j] = (float)(-r * cos(th));
    }
    pr[0] = pr[rings] = 0.0f;
    mesh_lathe(m, c, pr, py, rings + 1, seg); /* for a circle the lathe's normals come out radial */
}

/* ------------------------------------------------------------------------------------------------ */
/* glTF writer                                                                                       */

enum { GL_FLOAT = 5126, GL_U16 = 5123, GL_U32 = 5125, GL_ARRAY_BUFFER = 34962, GL_ELEMENT_ARRAY_BUFFER = 34963 };
enum { INTERP_LINEAR, INTERP_STEP, INTERP_CUBIC };
static const char *const INTERP_NAME[] = {"LINEAR", "STEP", "CUBICSPLINE"};

typedef struct {
    buf bin;
    buf views, accessors, meshes, materials, nodes, lights, cameras, anims;
    int nviews, naccessors, nmeshes, nmaterials, nnodes, nlights, ncameras, nanims;
    int glass; /* some material uses transmission + ior */
    uint64_t *mesh_tris; /* triangles per glTF mesh, for the summary */
    uint64_t tris;       /* triangles as loaded (instances counted) */
    int dynamic_nodes;
    const char *extras;  /* the root's extras (JSON object), or NULL */
    /* the animation being built */
    buf channels, samplers;
    int nchannels;
} gltf;

static int gl_view(gltf *g, const void *data, size_t len, int target)
{
    buf_pad(&g->bin, 4, 0);
    buf_sep(&g->views, g->nviews);
    buf_printf(&g->views, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu", g->bin.n, len);
    if (target) buf_printf(&g->views, ",\"target\":%d", target);
    buf_put(&g->views, "}", 1);
    buf_put(&g->bin, data, len);
    return g->nviews++;
}

/* An accessor over a whole bufferView; mn/mx (ncomp values each) are written when given. */
static int gl_accessor(gltf *g, int view, int ctype, uint32_t count, const char *type, const float *mn,
                       const float *mx, int ncomp)
{
    buf *b = &g->accessors;
    buf_sep(b, g->naccessors);
    buf_printf(b, "{\"bufferView\":%d,\"componentType\":%d,\"count\":%u,\"type\":\"%s\"", view, ctype, count, type);
    if (mn && mx) {
        buf_printf(b, ",\"min\":[");
        buf_nums(b, mn, ncomp);
        buf_printf(b, "],\"max\":[");
        buf_nums(b, mx, ncomp);
        buf_printf(b, "]");
    }
    buf_put(b, "}", 1);
    return g->naccessors++;
}

static int gl_float_accessor(gltf *g, const float *data, uint32_t count, int ncomp, int target, int with_bounds)
{
    static const char *const TYPES[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    float mn[4], mx[4];
    for (int c = 0; c < ncomp; c++) { mn[c] = INFINITY; mx[c] = -INFINITY; }
    for (uint32_t i = 0; i < count; i++)
        for (int c = 0; c < ncomp; c++) {
            float v = data[i * (uint32_t)ncomp + (uint32_t)c];
            if (v < mn[c]) mn[c] = v;
            if (v > mx[c]) mx[c] = v;
        }
    int view = gl_view(g, data, (size_t)count * (size_t)ncomp * sizeof(float), target);
    return gl_accessor(g, view, GL_FLOAT, count, TYPES[ncomp], with_bounds ? mn : NULL, with_bounds ? mx : NULL, ncomp);
}

/* A glTF mesh with one primitive per (part, material). Indices are u16 when they fit. */
static int gl_mesh(gltf *g, const char *name, const mesh *parts, const int *mats, int nparts)
{
    buf prims = {0};
    uint64_t tris = 0;
    int np = 0;
    for (int p = 0; p < nparts; p++) {
        const mesh *m = &parts[p];
        if (!m->ntri) continue;
        int apos = gl_float_accessor(g, m->pos, m->nv, 3, GL_ARRAY_BUFFER, 1);
        int anrm = gl_float_accessor(g, m->nrm, m->nv, 3, GL_ARRAY_BUFFER, 0);
        int auv = gl_float_accessor(g, m->uv, m->nv, 2, GL_ARRAY_BUFFER, 0);
        uint32_t ni = m->ntri * 3;
        int view, ctype;
        if (m->nv <= 65535) {
            uint16_t *s = xrealloc(NULL, ni * sizeof(uint16_t));
            for (uint32_t i = 0; i < ni; i++) s[i] = (uint16_t)m->idx[i];
            view = gl_view(g, s, ni * sizeof(uint16_t), GL_ELEMENT_ARRAY_BUFFER);
            ctype = GL_U16;
            free(s);
        } else {
            view = gl_view(g, m->idx, ni * sizeof(uint32_t), GL_ELEMENT_ARRAY_BUFFER);
            ctype = GL_U32;
        }
        int aidx = gl_accessor(g, view, ctype, ni, "SCALAR", NULL, NULL, 1);
        buf_sep(&prims, np++);
        buf_printf(&prims, "{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d,\"TEXCOORD_0\":%d},\"indices\":%d,\"material\":%d,\"mode\":4}",
                   apos, anrm, auv, aidx, mats[p]);
        tris += m->ntri;
    }
    if (!np) die("empty mesh");
    buf_sep(&g->meshes, g->nmeshes);
    buf_printf(&g->meshes, "{\"name\":\"%s\",\"primitives\":[", name);
    buf_put(&g->meshes, prims.p, prims.n);
    buf_put(&g->meshes, "]}", 2);
    buf_free(&prims);
    g->mesh_tris = xrealloc(g->mesh_tris, (size_t)(g->nmeshes + 1) * sizeof(uint64_t));
    g->mesh_tris[g->nmeshes] = tris;
    return g->nmeshes++;
}

/* Materials: diffuse/glossy via metallic+roughness; glass adds transmission 1 and ior 1.5. */
static int gl_material(gltf *g, const char *name, double r, double gr, double b, double metallic,
                       double roughness, int glass)
{
    buf *o = &g->materials;
    buf_sep(o, g->nmaterials);
    buf_printf(o, "{\"name\":\"%s\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[%.6g,%.6g,%.6g,1],"
                  "\"metallicFactor\":%.6g,\"roughnessFactor\":%.6g}", name, r, gr, b, metallic, roughness);
    if (glass) {
        buf_printf(o, ",\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
                      "\"KHR_materials_ior\":{\"ior\":1.5}}");
        g->glass = 1;
    }
    buf_put(o, "}", 1);
    return g->nmaterials++;
}

static int gl_point_light(gltf *g, const char *name, double r, double gr, double b, double candela)
{
    buf_sep(&g->lights, g->nlights);
    buf_printf(&g->lights, "{\"name\":\"%s\",\"type\":\"point\",\"color\":[%.6g,%.6g,%.6g],\"intensity\":%.6g}",
               name, r, gr, b, candela);
    return g->nlights++;
}

/* A sun: illuminance in lux (KHR_lights_punctual), shining along its node's -Z. */
static int gl_directional_light(gltf *g, const char *name, double r, double gr, double b, double lux)
{
    buf_sep(&g->lights, g->nlights);
    buf_printf(&g->lights, "{\"name\":\"%s\",\"type\":\"directional\",\"color\":[%.6g,%.6g,%.6g],\"intensity\":%.6g}",
               name, r, gr, b, lux);
    return g->nlights++;
}

static int gl_camera(gltf *g, const char *name, double yfov, double aspect, double znear, double zfar)
{
    buf_sep(&g->cameras, g->ncameras);
    buf_printf(&g->cameras, "{\"name\":\"%s\",\"type\":\"perspective\",\"perspective\":"
                            "{\"yfov\":%.6g,\"aspectRatio\":%.6g,\"znear\":%.6g,\"zfar\":%.6g}}",
               name, yfov, aspect, znear, zfar);
    return g->ncameras++;
}

typedef struct {
    int mesh, camera, light; /* -1 for none */
    v3 t;
    float q[4];              /* rotation (x, y, z, w); all zero means identity (omitted) */
    int dynamic;             /* extras lmgi.dynamic */
    int no_caustics;         /* extras lmgi.caustics = false */
} node_desc;

static node_desc node_none(void)
{
    node_desc d;
    memset(&d, 0, sizeof d);
    d.mesh = d.camera = d.light = -1;
    return d;
}

static int gl_node(gltf *g, const char *name, const node_desc *d)
{
    buf *b = &g->nodes;
    buf_sep(b, g->nnodes);
    buf_printf(b, "{\"name\":\"%s\"", name);
    if (d->mesh >= 0) {
        buf_printf(b, ",\"mesh\":%d", d->mesh);
        g->tris += g->mesh_tris[d->mesh];
    }
    if (d->camera >= 0) buf_printf(b, ",\"camera\":%d", d->camera);
    if (d->t.x != 0 || d->t.y != 0 || d->t.z != 0) {
        float t[3] = {d->t.x, d->t.y, d->t.z};
        buf_printf(b, ",\"translation\":[");
        buf_nums(b, t, 3);
        buf_put(b, "]", 1);
    }
    if (d->q[0] != 0 || d->q[1] != 0 || d->q[2] != 0 || (d->q[3] != 0 && d->q[3] != 1)) {
        buf_printf(b, ",\"rotation\":[");
        buf_nums(b, d->q, 4);
        buf_put(b, "]", 1);
    }
    if (d->light >= 0) buf_printf(b, ",\"extensions\":{\"KHR_lights_punctual\":{\"light\":%d}}", d->light);
    if (d->dynamic || d->no_caustics) {
        buf_printf(b, ",\"extras\":{\"lmgi\":{");
        if (d->dynamic) buf_printf(b, "\"dynamic\":true%s", d->no_caustics ? "," : "");
        if (d->no_caustics) buf_printf(b, "\"caustics\":false");
        buf_printf(b, "}}");
        g->dynamic_nodes += d->dynamic;
    }
    buf_put(b, "}", 1);
    return g->nnodes++;
}

/* One animation = gl_anim_channel calls followed by gl_anim_end. values holds keys * ncomp floats
 * (keys * 3 * ncomp for CUBICSPLINE: in-tangent, value, out-tangent per key). */
static void gl_anim_channel(gltf *g, int node, const char *path, int interp, const float *times, int keys,
                            const float *values, int ncomp)
{
    int in = gl_float_accessor(g, times, (uint32_t)keys, 1, 0, 1); /* animation input needs min/max */
    int nout = interp == INTERP_CUBIC ? keys * 3 : keys;
    int out = gl_float_accessor(g, values, (uint32_t)nout, ncomp, 0, 0);
    buf_sep(&g->samplers, g->nchannels);
    buf_printf(&g->samplers, "{\"input\":%d,\"interpolation\":\"%s\",\"output\":%d}", in, INTERP_NAME[interp], out);
    buf_sep(&g->channels, g->nchannels);
    buf_printf(&g->channels, "{\"sampler\":%d,\"target\":{\"node\":%d,\"path\":\"%s\"}}", g->nchannels, node, path);
    g->nchannels++;
}

static void gl_anim_end(gltf *g, const char *name)
{
    buf_sep(&g->anims, g->nanims);
    buf_printf(&g->anims, "{\"name\":\"%s\",\"channels\":[", name);
    buf_put(&g->anims, g->channels.p, g->channels.n);
    buf_put(&g->anims, "],\"samplers\":[", 14);
    buf_put(&g->anims, g->samplers.p, g->samplers.n);
    buf_put(&g->anims, "]}", 2);
    buf_free(&g->channels);
    buf_free(&g->samplers);
    g->nchannels = 0;
    g->nanims++;
}

static void put_array(buf *j, const char *key, const buf *items, int count)
{
    if (!count) return;
    buf_printf(j, ",\"%s\":[", key);
    buf_put(j, items->p, items->n);
    buf_put(j, "]", 1);
}

static void put_u32(FILE *f, uint32_t v)
{
    unsigned char b[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16), (unsigned char)(v >> 24)};
    fwrite(b, 1, 4, f);
}

/* Assembles the JSON, writes the GLB container (header, JSON chunk padded with spaces, BIN chunk padded
 * with zeros), prints the one-line summary and frees the writer. */
static void gl_write(gltf *g, const char *path)
{
    buf j = {0};
    buf_printf(&j, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"lmgi tools/gen_scenes\"}");
    if (g->nlights || g->glass) {
        buf_printf(&j, ",\"extensionsUsed\":[");
        int n = 0;
        if (g->nlights) buf_printf(&j, "%s\"KHR_lights_punctual\"", n++ ? "," : "");
        if (g->glass) buf_printf(&j, "%s\"KHR_materials_transmission\",\"KHR_materials_ior\"", n++ ? "," : "");
        buf_put(&j, "]", 1);
    }
    if (g->nlights) {
        buf_printf(&j, ",\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[");
        buf_put(&j, g->lights.p, g->lights.n);
        buf_put(&j, "]}}", 3);
    }
    if (g->extras)
        buf_printf(&j, ",\"extras\":%s", g->extras);
    buf_printf(&j, ",\"scene\":0,\"scenes\":[{\"name\":\"scene\",\"nodes\":[");
    for (int i = 0; i < g->nnodes; i++) buf_printf(&j, "%s%d", i ? "," : "", i);
    buf_put(&j, "]}]", 3);
    put_array(&j, "nodes", &g->nodes, g->nnodes);
    put_array(&j, "meshes", &g->meshes, g->nmeshes);
    put_array(&j, "materials", &g->materials, g->nmaterials);
    put_array(&j, "cameras", &g->cameras, g->ncameras);
    put_array(&j, "animations", &g->anims, g->nanims);
    put_array(&j, "accessors", &g->accessors, g->naccessors);
    put_array(&j, "bufferViews", &g->views, g->nviews);
    buf_pad(&g->bin, 4, 0);
    buf_printf(&j, ",\"buffers\":[{\"byteLength\":%zu}]}", g->bin.n);
    buf_pad(&j, 4, ' ');

    FILE *f = fopen(path, "wb");
    if (!f) { fprintf(stderr, "gen_scenes: cannot write %s\n", path); exit(1); }
    uint32_t total = (uint32_t)(12 + 8 + j.n + 8 + g->bin.n);
    put_u32(f, 0x46546C67u); /* "glTF" */
    put_u32(f, 2);
    put_u32(f, total);
    put_u32(f, (uint32_t)j.n);
    put_u32(f, 0x4E4F534Au); /* "JSON" */
    fwrite(j.p, 1, j.n, f);
    put_u32(f, (uint32_t)g->bin.n);
    put_u32(f, 0x004E4942u); /* "BIN\0" */
    fwrite(g->bin.p, 1, g->bin.n, f);
    if (fclose(f) != 0) { fprintf(stderr, "gen_scenes: error writing %s\n", path); exit(1); }

    printf("%s: %llu triangles, %d nodes (%d dynamic), %d meshes, %d lights, %d materials, %d animations, %u bytes\n",
           path, (unsigned long long)g->tris, g->nnodes, g->dynamic_nodes, g->nmeshes, g->nlights, g->nmaterials,
           g->nanims, total);

    buf_free(&j);
    buf *all[] = {&g->bin, &g->views, &g->accessors, &g->meshes, &g->materials, &g->nodes, &g->lights, &g->cameras, &g->anims};
    for (size_t i = 0; i < sizeof all / sizeof *all; i++) buf_free(all[i]);
    free(g->mesh_tris);
    memset(g, 0, sizeof *g);
}

/* Adds a camera node at eye looking at target. */
static void add_camera(gltf *g, v3 eye, v3 target, double yfov, double aspect, double zfar)
{
    node_desc d = node_none();
    d.camera = gl_camera(g, "camera", yfov, aspect, 0.05, zfar);
    d.t = eye;
    quat_look_at(eye, target, d.q);
    gl_node(g, "camera", &d);
}

static void add_light(gltf *g, const char *name, v3 at, double candela)
{
    node_desc d = node_none();
    d.light = gl_point_light(g, name, 1, 1, 1, candela);
    d.t = at;
    gl_node(g, name, &d);
}

/* ------------------------------------------------------------------------------------------------ */
/* Rooms                                                                                             */

typedef struct {
    v3 c;                  /* floor centre */
    double ax, az, height; /* interior half sizes and height */
    int door[4];           /* doorway in the wall at +X, -X, +Z, -Z */
    double wall_half;      /* half the wall thickness: each room builds its half of a doorway's reveal */
    double door_half, door_height;
} room_desc;

/* Inward-facing room shell: floor (part 0), walls with doorway reveals (part 1), ceiling (part 2).
 * Each wall is one connected planar piece; a doorway is a missing cell of its grid. */
static void build_room(mesh parts[3], const room_desc *r)
{
    v3 c = r->c;
    float H = (float)r->height;
    mesh_quad(&parts[0], vadd(c, V(-r->ax, 0, -r->az)), vadd(c, V(r->ax, 0, -r->az)), vadd(c, V(r->ax, 0, r->az)),
              vadd(c, V(-r->ax, 0, r->az)), V(0, 1, 0));
    mesh_quad(&parts[2], vadd(c, V(-r->ax, H, -r->az)), vadd(c, V(r->ax, H, -r->az)), vadd(c, V(r->ax, H, r->az)),
              vadd(c, V(-r->ax, H, r->az)), V(0, -1, 0));
    for (int side = 0; side < 4; side++) {
        /* out: outward axis of this wall; along: axis along the wall; half: half the wall's length */
        v3 out = side == 0 ? V(1, 0, 0) : side == 1 ? V(-1, 0, 0) : side == 2 ? V(0, 0, 1) : V(0, 0, -1);
        v3 along = side < 2 ? V(0, 0, 1) : V(1, 0, 0);
        double dist = side < 2 ? r->ax : r->az, half = side < 2 ? r->az : r->ax;
        v3 o = vadd(c, vscale(out, dist));
        v3 in = vscale(out, -1.0);
        if (!r->door[side]) {
            float ub[2] = {(float)-half, (float)half}, wb[2] = {0, H};
            mesh_plane(&parts[1], o, along, V(0, 1, 0), ub, 2, wb, 2, 0, in);
            continue;
        }
        float dw = (float)r->door_half, dh = (float)r->door_height, t = (float)r->wall_half;
        float ub[4] = {(float)-half, -dw, dw, (float)half}, wb[3] = {0, dh, H};
        mesh_plane(&parts[1], o, along, V(0, 1, 0), ub, 4, wb, 3, 1u << 1, in);
        /* reveal: jambs face the doorway's middle, lintel faces down, threshold (floor part) faces up */
        v3 d0 = o, d1 = vadd(o, vscale(out, t));
        for (int s = -1; s <= 1; s += 2) {
            v3 e = vscale(along, s * dw);
            mesh_quad(&parts[1], vadd(d0, e), vadd(d1, e), vadd(vadd(d1, e), V(0, dh, 0)), vadd(vadd(d0, e), V(0, dh, 0)),
                      vscale(along, -s));
        }
        v3 a0 = vscale(along, -dw), a1 = vscale(along, dw), up = V(0, dh, 0);
        mesh_quad(&parts[1], vadd(vadd(d0, a0), up), vadd(vadd(d1, a0), up), vadd(vadd(d1, a1), up), vadd(vadd(d0, a1), up),
                  V(0, -1, 0));
        mesh_quad(&parts[0], vadd(d0, a0), vadd(d1, a0), vadd(d1, a1), vadd(d0, a1), V(0, 1, 0));
    }
}

/* ------------------------------------------------------------------------------------------------ */
/* (a) Cornell box with a bumpy floor                                                                */

/* Floor grid cells per side: 80 for scenes/cornell.glb (13,790 triangles); --cornell-cells for the
 * gather benchmark's finer variants. */
static int CB_CELLS = 80;

/* Unscaled bump field; zero on the border (cos window), so the walls meet the floor at y = 0. */
static double bump_raw(double x, double z)
{
    double w = cos(PI * x / 2) * cos(PI * z / 2);
    double f = sin(3.1 * x + 0.4) * cos(2.3 * z - 0.2) + 0.3 * sin(4.0 * x + 3.3 * z)
             + 0.8 * exp(-((x - 0.3) * (x - 0.3) + (z - 0.45) * (z - 0.45)) / 0.08)
             - 0.6 * exp(-((x + 0.5) * (x + 0.5) + (z - 0.5) * (z - 0.5)) / 0.06);
    return w * f;
}

/* The floor grid's height field, scaled so that no face normal tilts more than max_tilt degrees from +Y.
 * 12 degrees keeps any two floor faces within 24 degrees of each other, inside lmgi's 30-degree
 * surface cone whatever face seeds the surface. */
static double bump_scale(double max_tilt)
{
    double gmax = 0, cell = 2.0 / CB_CELLS;
    for (int j = 0; j < CB_CELLS; j++)
        for (int i = 0; i < CB_CELLS; i++) {
            double x0 = -1 + i * cell, z0 = -1 + j * cell, x1 = x0 + cell, z1 = z0 + cell;
            double h00 = bump_raw(x0, z0), h10 = bump_raw(x1, z0), h01 = bump_raw(x0, z1), h11 = bump_raw(x1, z1);
            /* the two triangles (00,10,11) and (00,11,01): plane gradients */
            double ga[2] = {(h10 - h00) / cell, (h11 - h10) / cell}, gb[2] = {(h11 - h01) / cell, (h01 - h00) / cell};
            double a = hypot(ga[0], ga[1]), b = hypot(gb[0], gb[1]);
            if (a > gmax) gmax = a;
            if (b > gmax) gmax = b;
        }
    return tan(max_tilt * PI / 180) / gmax * 0.999;
}

static void gen_cornell(const char *path)
{
    gltf g = {0};
    int white = gl_material(&g, "white", 0.73, 0.73, 0.73, 0, 1, 0);
    int red = gl_material(&g, "red", 0.63, 0.065, 0.05, 0, 1, 0);
    int green = gl_material(&g, "green", 0.14, 0.45, 0.091, 0, 1, 0);
    int cube_mat = gl_material(&g, "cube", 0.75, 0.6, 0.25, 0, 1, 0);
    int mirror = gl_material(&g, "mirror", 0.95, 0.95, 0.95, 1, 0, 0);
    int glass = gl_material(&g, "glass", 1, 1, 1, 0, 0, 1);

    /* Room: white part (bumpy floor, ceiling, back wall), red left wall, green right wall; interior
     * x, z in [-1, 1], y in [0, 2], open towards +Z where the camera is. */
    mesh room[3] = {{0}};
    double A = bump_scale(12.0), hmin = 0, hmax = 0;
    uint32_t base = room[0].nv;
    for (int j = 0; j <= CB_CELLS; j++)
        for (int i = 0; i <= CB_CELLS; i++) {
            double x = -1 + 2.0 * i / CB_CELLS, z = -1 + 2.0 * j / CB_CELLS, e = 1e-4;
            int border = i == 0 || j == 0 || i == CB_CELLS || j == CB_CELLS;
            double h = border ? 0 : A * bump_raw(x, z);
            double dx = A * (bump_raw(x + e, z) - bump_raw(x - e, z)) / (2 * e);
            double dz = A * (bump_raw(x, z + e) - bump_raw(x, z - e)) / (2 * e);
            if (h < hmin) hmin = h;
            if (h > hmax) hmax = h;
            mesh_vert(&room[0], V(x, h, z), V(-dx, 1, -dz), (x + 1) / 2, (z + 1) / 2);
        }
    for (int j = 0; j < CB_CELLS; j++)
        for (int i = 0; i < CB_CELLS; i++) {
            uint32_t a = base + (uint32_t)(j * (CB_CELLS + 1) + i), b = a + 1, c = a + CB_CELLS + 2, d = a + CB_CELLS + 1;
            mesh_tri(&room[0], a, b, c);
            mesh_tri(&room[0], a, c, d);
        }
    mesh_quad(&room[0], V(-1, 2, -1), V(1, 2, -1), V(1, 2, 1), V(-1, 2, 1), V(0, -1, 0));  /* ceiling */
    mesh_quad(&room[0], V(-1, 0, -1), V(1, 0, -1), V(1, 2, -1), V(-1, 2, -1), V(0, 0, 1)); /* back */
    mesh_quad(&room[1], V(-1, 0, -1), V(-1, 0, 1), V(-1, 2, 1), V(-1, 2, -1), V(1, 0, 0)); /* left */
    mesh_quad(&room[2], V(1, 0, -1), V(1, 0, 1), V(1, 2, 1), V(1, 2, -1), V(-1, 0, 0));   /* right */
    int room_mats[3] = {white, red, green};
    node_desc d = node_none();
    d.mesh = gl_mesh(&g, "cornell_box", room, room_mats, 3);
    gl_node(&g, "cornell_box", &d);

    /* Tall block: 5 faces (no bottom), sunk 1 cm below the lowest bump so no gap shows. */
    mesh block = {0};
    mesh_box(&block, V(-0.3, hmin - 0.01, -0.3), V(0.3, 1.2, 0.3), F_ALL & ~F_NY);
    d = node_none();
    d.mesh = gl_mesh(&g, "tall_block", &block, &white, 1);
    d.t = V(-0.4, 0, -0.35);
    quat_y(17, d.q);
    gl_node(&g, "tall_block", &d);

    /* Cube: around an ellipse in front of the block (LINEAR, 17 keys over 8 s) while turning about Y
     * (LINEAR quaternions, 45 degrees per second); both loop: the last key equals the first. At each key
     * it rests on the highest bump under it (within its half diagonal), so it rides over the bumps. */
    float times[17], tr[17 * 3], rt[9 * 4], rtimes[9];
    for (int k = 0; k <= 16; k++) {
        double th = 2 * PI * k / 16, x = 0.55 * cos(th), z = 0.5 + 0.2 * sin(th), top = -1;
        for (int s = 0; s < 41; s++)
            for (int t = 0; t < 41; t++) {
                double dx = -0.22 + 0.011 * s, dz = -0.22 + 0.011 * t;
                if (dx * dx + dz * dz <= 0.22 * 0.22 && A * bump_raw(x + dx, z + dz) > top) top = A * bump_raw(x + dx, z + dz);
            }
        times[k] = (float)(k * 0.5);
        tr[3 * k] = (float)x;
        tr[3 * k + 1] = (float)(0.15 + top);
        tr[3 * k + 2] = (float)z;
    }
    for (int k = 0; k <= 8; k++) {
        rtimes[k] = (float)k;
        quat_y(45.0 * k, rt + 4 * k);
    }

    /* Dynamic cube, 0.3 m, all 6 faces, starting at its path's first key. */
    mesh cube = {0};
    mesh_box(&cube, V(-0.15, -0.15, -0.15), V(0.15, 0.15, 0.15), F_ALL);
    d = node_none();
    d.mesh = gl_mesh(&g, "cube", &cube, &cube_mat, 1);
    d.t = V(tr[0], tr[1], tr[2]);
    d.dynamic = 1;
    int cube_node = gl_node(&g, "dynamic_cube", &d);

    /* Dynamic mirror sphere. */
    mesh sph = {0};
    mesh_sphere(&sph, V(0, 0, 0), 0.22, 32, 16);
    d = node_none();
    d.mesh = gl_mesh(&g, "mirror_sphere", &sph, &mirror, 1);
    d.t = V(0.45, 0.25, -0.4);
    d.dynamic = 1;
    int sphere_node = gl_node(&g, "mirror_sphere", &d);

    add_light(&g, "ceiling_light", V(0, 1.9, 0), 20);
    add_camera(&g, V(0, 1, 3.6), V(0, 1, 0), 0.75, 1.0, 20);

    gl_anim_channel(&g, cube_node, "translation", INTERP_LINEAR, times, 17, tr, 3);
    gl_anim_channel(&g, cube_node, "rotation", INTERP_LINEAR, rtimes, 9, rt, 4);
    gl_anim_end(&g, "cube_path");

    /* Sphere: bobs between y = 0.25 and 0.75 every 4 s, CUBICSPLINE with zero tangents (eases in and out). */
    float st[5] = {0, 2, 4, 6, 8}, sv[5 * 9];
    memset(sv, 0, sizeof sv);
    for (int k = 0; k < 5; k++) {
        float *key = sv + 9 * k; /* in-tangent (3), value (3), out-tangent (3) */
        key[3] = 0.45f;
        key[4] = k % 2 ? 0.75f : 0.25f;
        key[5] = -0.4f;
    }
    gl_anim_channel(&g, sphere_node, "translation", INTERP_CUBIC, st, 5, sv, 3);
    gl_anim_end(&g, "sphere_bob");

    /* Dynamic glass sphere, r = 0.12 m, centre 0.22 m up: a ball lens that focuses the ceiling light near the
     * floor (a spot about 0.1 m across). It goes round the cube's ellipse half a turn behind the cube, so
     * the two never meet (0.4 m apart at least: the cube's half diagonal and the radius). Made after the
     * light and camera, so that the nodes before it keep their ids. */
    float gtr[17 * 3];
    for (int k = 0; k <= 16; k++) {
        double th = 2 * PI * k / 16 + PI;
        gtr[3 * k] = (float)(0.55 * cos(th));
        gtr[3 * k + 1] = 0.22f;
        gtr[3 * k + 2] = (float)(0.5 + 0.2 * sin(th));
    }
    mesh lens = {0};
    mesh_sphere(&lens, V(0, 0, 0), 0.12, 32, 16);
    d = node_none();
    d.mesh = gl_mesh(&g, "glass_sphere", &lens, &glass, 1);
    d.t = V(gtr[0], gtr[1], gtr[2]);
    d.dynamic = 1;
    int lens_node = gl_node(&g, "glass_sphere", &d);

    gl_anim_channel(&g, lens_node, "translation", INTERP_LINEAR, times, 17, gtr, 3);
    gl_anim_end(&g, "glass_path");

    gl_write(&g, path);
    for (int i = 0; i < 3; i++) mesh_free(&room[i]);
    mesh_free(&block); mesh_free(&cube); mesh_free(&sph); mesh_free(&lens);
}

/* ------------------------------------------------------------------------------------------------ */
/* (b) Two rooms with a door (paper Fig. 5)                                                          */

/* A simple table from boxes: top plus four legs (legs have no top/bottom faces: they touch top and floor). */
static void build_box_table(mesh *m, double w, double dpt, double hgt)
{
    double t = 0.04, l = 0.05;
    mesh_box(m, V(-w / 2, hgt - t, -dpt / 2), V(w / 2, hgt, dpt / 2), F_ALL);
    for (int sx = -1; sx <= 1; sx += 2)
        for (int sz = -1; sz <= 1; sz += 2) {
            double x = sx * (w / 2 - 0.08), z = sz * (dpt / 2 - 0.08);
            mesh_box(m, V(x - l / 2, 0, z - l / 2), V(x + l / 2, hgt - t, z + l / 2), F_PX | F_NX | F_PZ | F_NZ);
        }
}

static void gen_two_rooms(const char *path)
{
    gltf g = {0};
    int floor_mat = gl_material(&g, "floor", 0.55, 0.45, 0.35, 0, 1, 0);
    int wall_mat = gl_material(&g, "wall", 0.8, 0.8, 0.78, 0, 1, 0);
    int ceil_mat = gl_material(&g, "ceiling", 0.85, 0.85, 0.85, 0, 1, 0);
    int wood = gl_material(&g, "wood", 0.45, 0.3, 0.18, 0, 0.8, 0);
    int blue = gl_material(&g, "blue", 0.2, 0.3, 0.7, 0, 1, 0);

    /* Rooms A (x < 0) and B (x > 0), 4 x 3 x 4 m inside, sharing a 0.2 m wall at x in [-0.1, 0.1] with a
     * 1 m x 2.1 m doorway at z in [-0.5, 0.5]. */
    const double half = 2.0, t = 0.1, dw = 0.5, dh = 2.1;
    int mats[3] = {floor_mat, wall_mat, ceil_mat};
    for (int r = 0; r < 2; r++) {
        room_desc rd = {V(r ? half + t : -half - t, 0, 0), half, half, 3.0, {0, 0, 0, 0}, t, dw, dh};
        rd.door[r ? 1 : 0] = 1;
        mesh parts[3] = {{0}};
        build_room(parts, &rd);
        node_desc d = node_none();
        d.mesh = gl_mesh(&g, r ? "room_b" : "room_a", parts, mats, 3);
        gl_node(&g, r ? "room_b" : "room_a", &d);
        for (int i = 0; i < 3; i++) mesh_free(&parts[i]);
    }

    /* Door: 5 cm thick, covering the doorway with 5 cm overlap at the sides and top and reaching 1 cm
     * below the floor. It sits in room B and sinks 1 cm into the wall (x from 0.09), so no gap is left
     * between door and wall. The node origin is the hinge (x = 0.09, z = 0.55); the panel extends
     * along local -Z. */
    mesh door = {0};
    mesh_box(&door, V(0, -0.01, -(2 * dw + 0.1)), V(0.05, dh + 0.05, 0), F_ALL);
    node_desc d = node_none();
    d.mesh = gl_mesh(&g, "door", &door, &wood, 1);
    d.t = V(t - 0.01, 0, dw + 0.05);
    d.dynamic = 1;
    int door_node = gl_node(&g, "door", &d);

    mesh table = {0};
    build_box_table(&table, 1.2, 0.7, 0.75);
    int table_mesh = gl_mesh(&g, "table", &table, &wood, 1);
    d = node_none();
    d.mesh = table_mesh;
    d.t = V(-2.8, 0, -1.0);
    gl_node(&g, "table_a", &d);
    d.t = V(2.9, 0, 1.1);
    quat_y(90, d.q);
    gl_node(&g, "table_b", &d);

    mesh cube = {0};
    mesh_box(&cube, V(-0.15, 0, -0.15), V(0.15, 0.3, 0.15), F_ALL);
    d = node_none();
    d.mesh = gl_mesh(&g, "small_cube", &cube, &blue, 1);
    d.t = V(-2.5, 0, 1.0);
    d.dynamic = 1;
    int cube_node = gl_node(&g, "dynamic_cube", &d);

    add_light(&g, "light_a1", V(-3.0, 2.7, -1.2), 20);
    add_light(&g, "light_a2", V(-1.2, 2.7, 1.2), 20);
    add_light(&g, "light_b1", V(1.2, 2.7, -1.2), 20);
    add_light(&g, "light_b2", V(3.0, 2.7, 1.2), 20);
    add_camera(&g, V(-3.8, 1.7, 1.8), V(0, 1.0, -0.2), 1.0, 1.5, 30);

    /* Door: closed at 0 s, open (swung 90 degrees into room B) at 2 s, closed again at 4 s. */
    float dt[3] = {0, 2, 4}, dq[12];
    quat_y(0, dq);
    quat_y(-90, dq + 4);
    quat_y(0, dq + 8);
    gl_anim_channel(&g, door_node, "rotation", INTERP_LINEAR, dt, 3, dq, 4);
    gl_anim_end(&g, "door_swing");

    /* Small cube in room A: a square path (LINEAR) and quarter turns that snap once a second (STEP). */
    float ct[5] = {0, 1, 2, 3, 4}, cv[15] = {-2.5f, 0, 1.0f, -1.0f, 0, 1.0f, -1.0f, 0, 0.2f, -2.5f, 0, 0.2f, -2.5f, 0, 1.0f};
    float cq[20];
    for (int k = 0; k < 5; k++) quat_y(90.0 * k, cq + 4 * k);
    gl_anim_channel(&g, cube_node, "translation", INTERP_LINEAR, ct, 5, cv, 3);
    gl_anim_channel(&g, cube_node, "rotation", INTERP_STEP, ct, 5, cq, 4);
    gl_anim_end(&g, "cube_path");

    gl_write(&g, path);
    mesh_free(&door); mesh_free(&table); mesh_free(&cube);
}

/* ------------------------------------------------------------------------------------------------ */
/* (c) Many furnished rooms                                                                          */

typedef struct {
    int table, chair, bed, shelf, lamp, vase; /* glTF mesh indices */
} furniture;

/* Furniture meshes, each in its own local frame: origin on the floor, "front" towards +Z. */
static furniture build_furniture(gltf *g, int wood, int dark_wood, int fabric, int linen, int metal, int shade,
                                 int glass)
{
    furniture f;
    { /* table 1.2 x 0.8, 0.76 high: rounded top, four round legs */
        mesh p[1] = {{0}};
        mesh_rounded_box(&p[0], V(0, 0.735, 0), V(0.6, 0.025, 0.4), 0.02, 4);
        for (int sx = -1; sx <= 1; sx += 2)
            for (int sz = -1; sz <= 1; sz += 2)
                mesh_cylinder(&p[0], V(sx * 0.52, 0, sz * 0.32), 0.03, 0.711, 20, 1);
        f.table = gl_mesh(g, "table", p, &wood, 1);
        mesh_free(&p[0]);
    }
    { /* chair: seat and backrest (fabric), legs and back posts (dark wood); the sitter faces +Z */
        mesh p[2] = {{0}};
        mesh_rounded_box(&p[0], V(0, 0.45, 0), V(0.22, 0.025, 0.22), 0.02, 4);
        mesh_rounded_box(&p[0], V(0, 0.75, -0.19), V(0.2, 0.12, 0.022), 0.015, 3);
        for (int sx = -1; sx <= 1; sx += 2) {
            for (int sz = -1; sz <= 1; sz += 2) mesh_cylinder(&p[1], V(sx * 0.18, 0, sz * 0.18), 0.02, 0.426, 16, 1);
            mesh_cylinder(&p[1], V(sx * 0.18, 0.475, -0.19), 0.016, 0.42, 16, 2);
        }
        int m[2] = {fabric, dark_wood};
        f.chair = gl_mesh(g, "chair", p, m, 2);
        mesh_free(&p[0]); mesh_free(&p[1]);
    }
    { /* bed 1.3 x 1.9: frame and headboard (wood), mattress and pillow (linen); headboard at -Z */
        mesh p[2] = {{0}};
        mesh_rounded_box(&p[0], V(0, 0.2, 0), V(0.65, 0.1, 0.9), 0.03, 3);
        mesh_rounded_box(&p[0], V(0, 0.55, -0.92), V(0.65, 0.45, 0.03), 0.02, 3);
        for (int sx = -1; sx <= 1; sx += 2)
            for (int sz = -1; sz <= 1; sz += 2) mesh_cylinder(&p[0], V(sx * 0.58, 0, sz * 0.82), 0.04, 0.101, 16, 1);
        mesh_rounded_box(&p[1], V(0, 0.38, 0.02), V(0.62, 0.09, 0.86), 0.06, 4);
        mesh_rounded_box(&p[1], V(0, 0.51, -0.66), V(0.4, 0.05, 0.15), 0.045, 4);
        int m[2] = {wood, linen};
        f.bed = gl_mesh(g, "bed", p, m, 2);
        mesh_free(&p[0]); mesh_free(&p[1]);
    }
    { /* shelf 1.2 wide, 0.35 deep, 1.8 high, back towards -Z, with books (deterministic sizes) */
        mesh p[2] = {{0}};
        for (int s = -1; s <= 1; s += 2) mesh_rounded_box(&p[0], V(s * 0.585, 0.9, 0), V(0.015, 0.9, 0.175), 0.008, 2);
        const double boards[5] = {0.03, 0.45, 0.9, 1.35, 1.77};
        for (int i = 0; i < 5; i++) mesh_rounded_box(&p[0], V(0, boards[i], 0), V(0.57, 0.015, 0.17), 0.008, 2);
        mesh_box(&p[0], V(-0.57, 0.015, -0.175), V(0.57, 1.785, -0.165), F_PZ);
        for (int i = 0; i < 3; i++) {
            double x = -0.55, y0 = boards[i] + 0.015;
            while (x < 0.5) {
                double w = 0.025 + 0.03 * rnd(), hgt = 0.2 + 0.15 * rnd(), dpt = 0.18 + 0.1 * rnd();
                if (x + w > 0.55) break;
                mesh_box(&p[1], V(x, y0, -0.16), V(x + w, y0 + hgt, -0.16 + dpt), F_ALL & ~F_NY);
                x += w + 0.003 + (rnd() < 0.15 ? 0.08 : 0);
            }
        }
        int m[2] = {dark_wood, fabric};
        f.shelf = gl_mesh(g, "shelf", p, m, 2);
        mesh_free(&p[0]); mesh_free(&p[1]);
    }
    { /* floor lamp: base and pole (metal), spherical shade */
        mesh p[2] = {{0}};
        mesh_cylinder(&p[0], V(0, 0, 0), 0.15, 0.03, 24, 3);
        mesh_cylinder(&p[0], V(0, 0.03, 0), 0.015, 1.36, 16, 0);
        mesh_sphere(&p[1], V(0, 1.55, 0), 0.18, 32, 16);
        int m[2] = {metal, shade};
        f.lamp = gl_mesh(g, "floor_lamp", p, m, 2);
        mesh_free(&p[0]); mesh_free(&p[1]);
    }
    { /* glass vase: a closed thick-walled surface of revolution (outside up, over the lip, inside down) */
        static const float pr[] = {0, 0.05f, 0.065f, 0.08f, 0.085f, 0.07f, 0.045f, 0.04f, 0.046f,
                                   0.038f, 0.032f, 0.038f, 0.063f, 0.073f, 0.06f, 0.045f, 0};
        static const float py[] = {0, 0, 0.01f, 0.05f, 0.1f, 0.16f, 0.2f, 0.23f, 0.26f,
                                   0.26f, 0.23f, 0.2f, 0.16f, 0.1f, 0.04f, 0.02f, 0.02f};
        mesh p[1] = {{0}};
        mesh_lathe(&p[0], V(0, 0, 0), pr, py, (int)(sizeof pr / sizeof *pr), 32);
        f.vase = gl_mesh(g, "glass_vase", p, &glass, 1);
        mesh_free(&p[0]);
    }
    return f;
}

/* Places a piece of furniture in room (cx, cz) whose layout is turned by room_rot degrees about the
 * room centre; (x, z, rot) are in the unturned layout. */
static void place(gltf *g, const char *name, int mesh_idx, double cx, double cz, double room_rot, double x, double y,
                  double z, double rot, int no_caustics)
{
    double a = room_rot * PI / 180, ca = cos(a), sa = sin(a);
    node_desc d = node_none();
    d.mesh = mesh_idx;
    /* R_y(a) maps (x, z) to (x cos a + z sin a, -x sin a + z cos a) */
    d.t = V(cx + x * ca + z * sa, y, cz - x * sa + z * ca);
    quat_y(room_rot + rot, d.q);
    d.no_caustics = no_caustics;
    gl_node(g, name, &d);
}

static void gen_many_rooms(const char *path, int nrooms)
{
    gltf g = {0};
    rng_state = 0x5eed1234u;
    int floor_mat = gl_material(&g, "floor_wood", 0.5, 0.36, 0.22, 0, 0.45, 0);
    int wall_mat = gl_material(&g, "wall", 0.82, 0.8, 0.75, 0, 1, 0);
    int ceil_mat = gl_material(&g, "ceiling", 0.88, 0.88, 0.88, 0, 1, 0);
    int wood = gl_material(&g, "wood", 0.6, 0.42, 0.26, 0, 0.35, 0);
    int dark_wood = gl_material(&g, "dark_wood", 0.3, 0.18, 0.1, 0, 0.6, 0);
    int fabric = gl_material(&g, "fabric_red", 0.6, 0.15, 0.12, 0, 1, 0);
    int linen = gl_material(&g, "linen", 0.85, 0.85, 0.8, 0, 1, 0);
    int metal = gl_material(&g, "brushed_metal", 0.7, 0.7, 0.72, 1, 0.4, 0);
    int shade = gl_material(&g, "lamp_shade", 0.9, 0.88, 0.8, 0, 1, 0);
    int glass = gl_material(&g, "glass", 1, 1, 1, 0, 0, 1);
    furniture f = build_furniture(&g, wood, dark_wood, fabric, linen, metal, shade, glass);

    /* Rooms on a grid, row-major, 5 m apart: 4.8 x 3 x 4.8 m inside, 0.2 m walls, a doorway in every
     * wall shared with a neighbour (all rooms are connected). */
    const double pitch = 5.0, half = 2.4;
    int cols = (int)ceil(sqrt((double)nrooms)), nvase = 0;
    int mats[3] = {floor_mat, wall_mat, ceil_mat};
    char name[64];
    for (int r = 0; r < nrooms; r++) {
        int col = r % cols, row = r / cols;
        double cx = col * pitch, cz = row * pitch;
        room_desc rd = {V(cx, 0, cz), half, half, 3.0, {0, 0, 0, 0}, 0.1, 0.5, 2.1};
        rd.door[0] = col + 1 < cols && r + 1 < nrooms;     /* +X */
        rd.door[1] = col > 0;                              /* -X */
        rd.door[2] = r + cols < nrooms;                    /* +Z */
        rd.door[3] = row > 0;                              /* -Z */
        mesh parts[3] = {{0}};
        build_room(parts, &rd);
        snprintf(name, sizeof name, "room_%d", r);
        node_desc d = node_none();
        d.mesh = gl_mesh(&g, name, parts, mats, 3);
        gl_node(&g, name, &d);
        for (int i = 0; i < 3; i++) mesh_free(&parts[i]);

        /* The layout keeps the doorways (middle of each wall) clear, so any quarter turn works. */
        double rr = 90.0 * (int)(rnd() * 4);
        int item = 0;
#define PLACE(what, m, x, y, z, rot, nc) \
    (snprintf(name, sizeof name, "%s_%d_%d", what, r, item++), place(&g, name, m, cx, cz, rr, x, y, z, rot, nc))
        PLACE("bed", f.bed, 1.55, 0, 1.44, 180, 0);
        PLACE("table", f.table, -1.35, 0, 1.4, 0, 0);
        for (int c = 0; c < 4; c++) {
            double jit = 16 * (rnd() - 0.5);
            PLACE("chair", f.chair, -1.35 + (c % 2 ? 0.32 : -0.32), 0, 1.4 + (c < 2 ? -0.62 : 0.62), (c < 2 ? 0 : 180) + jit, 0);
        }
        PLACE("shelf", f.shelf, -2.2, 0, -1.4, 90, 0);
        PLACE("lamp", f.lamp, -1.7, 0, -2.05, 0, 0);
        PLACE("table", f.table, 1.4, 0, -1.45, 0, 0);
        for (int c = 0; c < 2; c++) PLACE("chair", f.chair, 1.4, 0, -1.45 + (c ? 0.62 : -0.62), c ? 180 : 0, 0);
        PLACE("lamp", f.lamp, 2.05, 0, -0.85, 0, 0);
        if (r % 3 == 0) { /* a glass vase on the first table; every other one has caustics switched off */
            PLACE("vase", f.vase, -1.15, 0.76, 1.35, 0, nvase % 2);
            nvase++;
        }
#undef PLACE
        snprintf(name, sizeof name, "light_%d", r);
        add_light(&g, name, V(cx, 2.8, cz), 25);
    }
    /* Room 0's -Z wall centre is clear whatever its layout turn (doorway clearance). */
    add_camera(&g, V(0, 1.8, -2.25), V(0.3, 0.7, 1.5), 1.1, 1.5, 200);
    gl_write(&g, path);
}

/* ------------------------------------------------------------------------------------------------ */
/* (d) A sunlit living room                                                                          */

/* A wall of one room face: the plane o + U u + W w for u in ub, w in wb, facing U x W, with the grid
 * cell (1, 1) left open when `window` (the breakpoints put the opening there). */
static void wall(mesh *m, v3 o, v3 U, v3 W, const float ub[4], const float wb[4], int window)
{
    mesh_plane(m, o, U, W, ub, window ? 4 : 2, wb, window ? 4 : 2, window ? 1u << 9 : 0, vcross(U, W));
}

/* The four faces lining an opening through a wall (jambs, sill and head): the opening spans a0..a1 along
 * `along` and y0..y1, between the wall's faces at `in` and in + thick (the outward axis `out`). */
static void reveal(mesh *m, v3 in, v3 along, v3 out, double a0, double a1, double y0, double y1, double thick)
{
    v3 d = vscale(out, thick);
    for (int s = 0; s < 2; s++) { /* jambs face the opening's middle */
        v3 p = vadd(in, vscale(along, s ? a1 : a0)), n = vscale(along, s ? -1.0 : 1.0);
        v3 q[4] = {vadd(p, V(0, y0, 0)), vadd(vadd(p, d), V(0, y0, 0)), vadd(vadd(p, d), V(0, y1, 0)), vadd(p, V(0, y1, 0))};
        if (vdot(vcross(vsub(q[1], q[0]), vsub(q[2], q[0])), n) < 0) mesh_quad(m, q[3], q[2], q[1], q[0], n);
        else mesh_quad(m, q[0], q[1], q[2], q[3], n);
    }
    for (int s = 0; s < 2; s++) { /* sill faces up, head faces down */
        v3 p0 = vadd(in, vadd(vscale(along, a0), V(0, s ? y1 : y0, 0))), p1 = vadd(in, vadd(vscale(along, a1), V(0, s ? y1 : y0, 0)));
        v3 n = V(0, s ? -1 : 1, 0), q[4] = {p0, p1, vadd(p1, d), vadd(p0, d)};
        if (vdot(vcross(vsub(q[1], q[0]), vsub(q[2], q[0])), n) < 0) mesh_quad(m, q[3], q[2], q[1], q[0], n);
        else mesh_quad(m, q[0], q[1], q[2], q[3], n);
    }
}

/* A living room lit in physical units, the way an architect's scene is (issue 30: "a sunlit interior"):
 * 6 x 5 x 2.8 m inside, 0.2 m walls, a 2 x 1.4 m window in the south (-z) wall and a 1.2 x 1.2 m one in
 * the west (-x) wall, open (no glass), a roof over it, on a 40 x 40 m lawn; a sun of 100,000 lux that
 * falls through both windows onto the floor, a clear sky (extras.lmgi.sky, a gradient giving about
 * 8,000 lux on open ground), two ceiling bulbs of 800 lm (63.7 cd) and furniture: a table, a sofa, a
 * bookshelf, a rug in the sun, a floor lamp, window frames and a coat stand of albedo 0.02. */
static void gen_sunlit_room(const char *path)
{
    gltf g = {0};
    rng_state = 0x51ed7001u;
    g.extras = "{\"lmgi\":{\"sky\":{\"zenith\":[1500,2200,3600],\"horizon\":[3000,3200,3500]}}}";
    int floor_mat = gl_material(&g, "oak_floor", 0.45, 0.3, 0.18, 0, 0.8, 0);
    int wall_mat = gl_material(&g, "wall_paint", 0.8, 0.78, 0.74, 0, 1, 0);
    int ceil_mat = gl_material(&g, "ceiling", 0.85, 0.85, 0.85, 0, 1, 0);
    int plaster = gl_material(&g, "plaster", 0.65, 0.6, 0.55, 0, 1, 0);
    int roof_mat = gl_material(&g, "roof", 0.25, 0.22, 0.2, 0, 1, 0);
    int grass = gl_material(&g, "grass", 0.18, 0.28, 0.1, 0, 1, 0);
    int wood = gl_material(&g, "wood", 0.55, 0.38, 0.22, 0, 0.8, 0);
    int fabric = gl_material(&g, "sofa_fabric", 0.25, 0.35, 0.6, 0, 1, 0);
    int rug_mat = gl_material(&g, "rug", 0.7, 0.2, 0.15, 0, 1, 0);
    int dark = gl_material(&g, "black_metal", 0.02, 0.02, 0.02, 0, 1, 0);
    int shade = gl_material(&g, "lamp_shade", 0.9, 0.88, 0.8, 0, 1, 0);
    const double X = 3.0, Z = 2.5, H = 2.8, T = 0.2, G = -0.05, TOP = 3.0;

    /* The house: the inside lining (floor, walls, ceiling), the outside (walls and the window reveals), the roof. */
    mesh in[3] = {{0}}, out[2] = {{0}};
    mesh_box(&in[0], V(-X, G, -Z), V(X, 0, Z), F_PY);
    mesh_box(&in[2], V(-X, H, -Z), V(X, TOP, Z), F_NY);
    const float full_x[4] = {(float)-X, (float)X}, full_z[4] = {(float)-Z, (float)Z}, in_h[4] = {0, (float)H};
    const float south_u[4] = {(float)-X, -1.5f, 0.5f, (float)X}, south_w[4] = {0, 0.8f, 2.2f, (float)H};
    const float west_u[4] = {(float)-Z, -0.6f, 0.6f, (float)Z}, west_w[4] = {0, 1.0f, 2.2f, (float)H};
    wall(&in[1], V(0, 0, -Z), V(1, 0, 0), V(0, 1, 0), south_u, south_w, 1); /* faces +z, into the room */
    wall(&in[1], V(-X, 0, 0), V(0, 0, -1), V(0, 1, 0), west_u, west_w, 1);  /* faces +x */
    wall(&in[1], V(X, 0, 0), V(0, 0, 1), V(0, 1, 0), full_z, in_h, 0);      /* faces -x */
    wall(&in[1], V(0, 0, Z), V(-1, 0, 0), V(0, 1, 0), full_x, in_h, 0);     /* faces -z */
    const float oX = (float)(X + T), oZ = (float)(Z + T), out_h[4] = {(float)G, (float)TOP};
    const float south_ou[4] = {-oX, -0.5f, 1.5f, oX}, south_ow[4] = {(float)G, 0.8f, 2.2f, (float)TOP};
    const float west_ou[4] = {-oZ, -0.6f, 0.6f, oZ}, west_ow[4] = {(float)G, 1.0f, 2.2f, (float)TOP};
    const float east_ou[4] = {-oZ, oZ}, north_ou[4] = {-oX, oX};
    wall(&out[0], V(0, 0, -oZ), V(-1, 0, 0), V(0, 1, 0), south_ou, south_ow, 1); /* faces -z */
    wall(&out[0], V(-oX, 0, 0), V(0, 0, 1), V(0, 1, 0), west_ou, west_ow, 1);     /* faces -x */
    wall(&out[0], V(oX, 0, 0), V(0, 0, -1), V(0, 1, 0), east_ou, out_h, 0);      /* faces +x */
    wall(&out[0], V(0, 0, oZ), V(1, 0, 0), V(0, 1, 0), north_ou, out_h, 0);      /* faces +z */
    reveal(&out[0], V(0, 0, -Z), V(1, 0, 0), V(0, 0, -1), -1.5, 0.5, 0.8, 2.2, T);
    reveal(&out[0], V(-X, 0, 0), V(0, 0, 1), V(-1, 0, 0), -0.6, 0.6, 1.0, 2.2, T);
    mesh_box(&out[1], V(-X - 0.4, TOP, -Z - 0.4), V(X + 0.4, TOP + 0.12, Z + 0.4), F_ALL);
    int in_mats[3] = {floor_mat, wall_mat, ceil_mat}, out_mats[2] = {plaster, roof_mat};
    node_desc d = node_none();
    d.mesh = gl_mesh(&g, "room", in, in_mats, 3);
    gl_node(&g, "room", &d);
    d.mesh = gl_mesh(&g, "house", out, out_mats, 2);
    gl_node(&g, "house", &d);
    for (int i = 0; i < 3; i++) mesh_free(&in[i]);
    for (int i = 0; i < 2; i++) mesh_free(&out[i]);

    mesh lawn = {0};
    mesh_box(&lawn, V(-20, G - 0.1, -20), V(20, G, 20), F_PY);
    d.mesh = gl_mesh(&g, "lawn", &lawn, &grass, 1);
    gl_node(&g, "lawn", &d);
    mesh_free(&lawn);

    /* Furniture, in place (one node each). */
    mesh table = {0}, sofa[2] = {{0}}, shelf = {0}, rug = {0}, lamp[2] = {{0}}, frames = {0};
    build_box_table(&table, 1.4, 0.8, 0.75);
    mesh_box(&sofa[0], V(-1.1, 0.12, 1.55), V(1.1, 0.45, 2.4), F_ALL & ~(F_NY | F_PX | F_NX)); /* seat */
    mesh_box(&sofa[0], V(-1.1, 0.45, 2.2), V(1.1, 0.9, 2.38), F_ALL & ~(F_NY | F_PX | F_NX)); /* back */
    for (int s = -1; s <= 1; s += 2) mesh_box(&sofa[0], V(s > 0 ? 1.1 : -1.3, 0.12, 1.55), V(s > 0 ? 1.3 : -1.1, 0.65, 2.4), F_ALL & ~F_NY);
    for (int s = -1; s <= 1; s += 2) /* feet */
        for (int t = 0; t < 2; t++) mesh_cylinder(&sofa[1], V(s * 1.2, 0, t ? 2.3 : 1.65), 0.03, 0.12, 12, 1);
    for (int i = 0; i < 5; i++) mesh_box(&shelf, V(2.62, 0.02 + 0.45 * i, -1.5), V(2.98, 0.05 + 0.45 * i, 0.5), F_ALL);
    for (int s = 0; s < 2; s++) mesh_box(&shelf, V(2.62, 0, s ? 0.5 : -1.53), V(2.98, 1.9, s ? 0.53 : -1.5), F_ALL & ~F_NY);
    mesh_box(&rug, V(-1.6, 0, -1.9), V(0.6, 0.01, -0.4), F_ALL & ~F_NY);
    mesh_cylinder(&lamp[0], V(-2.5, 0, 1.9), 0.15, 0.03, 24, 3);
    mesh_cylinder(&lamp[0], V(-2.5, 0.03, 1.9), 0.015, 1.4, 16, 0);
    mesh_sphere(&lamp[1], V(-2.5, 1.6, 1.9), 0.2, 32, 16);
    for (int s = 0; s < 2; s++) { /* window mullions: one upright in the middle of each opening */
        if (s == 0) mesh_box(&frames, V(-0.53, 0.8, -Z - 0.12), V(-0.47, 2.2, -Z - 0.08), F_ALL & ~(F_NY | F_PY));
        else mesh_box(&frames, V(-X - 0.12, 1.0, -0.03), V(-X - 0.08, 2.2, 0.03), F_ALL & ~(F_NY | F_PY));
    }
    mesh_cylinder(&frames, V(2.6, 0, 2.2), 0.02, 1.8, 12, 2); /* the coat stand */
    d = node_none();
    d.mesh = gl_mesh(&g, "table", &table, &wood, 1);
    d.t = V(0.9, 0, 0.2);
    gl_node(&g, "table", &d);
    d = node_none();
    int sofa_mats[2] = {fabric, dark}, lamp_mats[2] = {dark, shade};
    d.mesh = gl_mesh(&g, "sofa", sofa, sofa_mats, 2);
    gl_node(&g, "sofa", &d);
    d.mesh = gl_mesh(&g, "bookshelf", &shelf, &wood, 1);
    gl_node(&g, "bookshelf", &d);
    d.mesh = gl_mesh(&g, "rug", &rug, &rug_mat, 1);
    gl_node(&g, "rug", &d);
    d.mesh = gl_mesh(&g, "floor_lamp", lamp, lamp_mats, 2);
    gl_node(&g, "floor_lamp", &d);
    d.mesh = gl_mesh(&g, "black_metal", &frames, &dark, 1);
    gl_node(&g, "black_metal", &d);
    mesh_free(&table); mesh_free(&shelf); mesh_free(&rug); mesh_free(&frames);
    for (int i = 0; i < 2; i++) { mesh_free(&sofa[i]); mesh_free(&lamp[i]); }

    /* The sun from the south-west, 40 degrees up: through both windows onto the floor. Two bulbs of
     * 800 lm (800 / 4 pi cd) under the ceiling. */
    d = node_none();
    d.light = gl_directional_light(&g, "sun", 1.0, 0.96, 0.9, 100000);
    quat_look_at(V(0, 0, 0), V(0.45, -0.64, 0.62), d.q);
    gl_node(&g, "sun", &d);
    d = node_none();
    d.light = gl_point_light(&g, "bulb_1", 1.0, 0.85, 0.65, 800.0 / (4.0 * PI));
    d.t = V(-1.5, 2.5, 0.8);
    gl_node(&g, "bulb_1", &d);
    d.light = gl_point_light(&g, "bulb_2", 1.0, 0.85, 0.65, 800.0 / (4.0 * PI));
    d.t = V(1.6, 2.5, 1.0);
    gl_node(&g, "bulb_2", &d);
    add_camera(&g, V(2.6, 1.6, 2.1), V(-1.0, 0.5, -1.6), 1.1, 1.5, 100);
    gl_write(&g, path);
}

/* ------------------------------------------------------------------------------------------------ */

static void usage(void)
{
    fprintf(stderr,
            "usage: gen_scenes DIR                 write DIR/cornell.glb, DIR/two_rooms.glb, DIR/many_rooms.glb,\n"
            "                                      DIR/sunlit_room.glb\n"
            "       gen_scenes --rooms N OUTFILE   write a many_rooms variant with N rooms (1..100000) to OUTFILE\n"
            "       gen_scenes --cornell-cells N OUTFILE  write cornell.glb with N x N floor cells (2..1000; default 80)\n"
            "The default many_rooms has 16 rooms (about 22,100 triangles each); the benchmark uses --rooms\n"
            "for smaller and larger variants.\n");
    exit(2);
}

int main(int argc, char **argv)
{
    if (argc == 4 && strcmp(argv[1], "--rooms") == 0) {
        char *end;
        long n = strtol(argv[2], &end, 10);
        if (*end || n < 1 || n > 100000) usage();
        gen_many_rooms(argv[3], (int)n);
        return 0;
    }
    if (argc == 4 && strcmp(argv[1], "--cornell-cells") == 0) {
        char *end;
        long n = strtol(argv[2], &end, 10);
        if (*end || n < 2 || n > 1000) usage();
        CB_CELLS = (int)n;
        gen_cornell(argv[3]);
        return 0;
    }
    if (argc != 2 || argv[1][0] == '-') usage();
    char path[4096];
    const char *dir = argv[1];
    snprintf(path, sizeof path, "%s/cornell.glb", dir);
    gen_cornell(path);
    snprintf(path, sizeof path, "%s/two_rooms.glb", dir);
    gen_two_rooms(path);
    snprintf(path, sizeof path, "%s/many_rooms.glb", dir);
    gen_many_rooms(path, 16);
    snprintf(path, sizeof path, "%s/sunlit_room.glb", dir);
    gen_sunlit_room(path);
    return 0;
}
