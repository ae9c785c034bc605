#define _XOPEN_SOURCE 700
#include "support.h"

#include "../src/gpu/gl/gl_context.h"

#include <ftw.h>
#include <limits.h>
#include <math.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdint.h>
#include <unistd.h>

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

static const char *existing(char *buf, size_t n, const char *base, const char *sub, const char *rel)
{
    snprintf(buf, n, "%s/%s/%s", base, sub, rel);
    return access(buf, R_OK) == 0 ? buf : NULL;
}

const char *lmt_shared_scene(const char *relative)
{
    static char buf[2048];
    const char *env = getenv("LMGI_SHARED");
    if (env && existing(buf, sizeof buf, env, "scenes", relative))
        return buf;
    return existing(buf, sizeof buf, "..", "shared/scenes", relative);
}

const char *lmt_project_scene(const char *relative)
{
    static char buf[2048];
    return existing(buf, sizeof buf, ".", "scenes", relative);
}

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st;
    (void)flag;
    (void)ftw;
    return remove(path);
}

/* Directories made by lmt_tmpdir, removed when the test program exits. */
static char made[64][64];
static int made_count;

static void remove_tmpdirs(void)
{
    for (int i = 0; i < made_count; i++)
        nftw(made[i], remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

void lmt_filter_from_env(void)
{
    if (getenv("LMT_FILTER"))
        cmocka_set_test_filter(getenv("LMT_FILTER"));
}

const char *lmt_tmpdir(void)
{
    static char buf[64];
    snprintf(buf, sizeof buf, "/tmp/lmgi-test-XXXXXX");
    if (!mkdtemp(buf))
        return "/tmp";
    if (made_count == 0)
        atexit(remove_tmpdirs);
    if (made_count < 64)
        memcpy(made[made_count++], buf, sizeof buf);
    return buf;
}

const char *lmt_reference_cache(void)
{
    static char dir[64];
    if (!dir[0])
        snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    return dir;
}

unsigned char *lmt_read_file(const char *path, size_t *size, size_t extra)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    *size = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *data = malloc(*size + extra);
    assert_non_null(data);
    assert_int_equal(fread(data, 1, *size, f), *size);
    fclose(f);
    return data;
}

uint32_t lmt_xorshift(uint32_t *state)
{
    *state ^= *state << 13;
    *state ^= *state >> 17;
    *state ^= *state << 5;
    return *state;
}

void lmt_write_file(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

static void add_vertex(lmt_mesh *m, float x, float y, float z)
{
    float *p = m->pos + 3 * m->vertex_count++;
    p[0] = x;
    p[1] = y;
    p[2] = z;
}

void lmt_mesh_quad(lmt_mesh *m, const float c[3], const float u[3], const float v[3])
{
    uint16_t b = (uint16_t)m->vertex_count;
    add_vertex(m, c[0], c[1], c[2]);
    add_vertex(m, c[0] + u[0], c[1] + u[1], c[2] + u[2]);
    add_vertex(m, c[0] + u[0] + v[0], c[1] + u[1] + v[1], c[2] + u[2] + v[2]);
    add_vertex(m, c[0] + v[0], c[1] + v[1], c[2] + v[2]);
    uint16_t t[6] = {b, (uint16_t)(b + 1), (uint16_t)(b + 2), b, (uint16_t)(b + 2), (uint16_t)(b + 3)};
    memcpy(m->idx + m->index_count, t, sizeof t);
    m->index_count += 6;
}

void lmt_mesh_cube(lmt_mesh *m, float h)
{
    /* For each axis and sign: a corner and two edges whose cross product points outward. */
    for (int axis = 0; axis < 3; axis++)
        for (int sign = -1; sign <= 1; sign += 2) {
            int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
            float c[3], u[3] = {0, 0, 0}, v[3] = {0, 0, 0};
            c[axis] = sign * h;
            c[a1] = -h;
            c[a2] = -h;
            if (sign > 0) {
                u[a1] = 2 * h;
                v[a2] = 2 * h;
            } else {
                u[a2] = 2 * h;
                v[a1] = 2 * h;
            }
            lmt_mesh_quad(m, c, u, v);
        }
}

void lmt_mesh_cap(lmt_mesh *m, double alpha, double r, double cy)
{
    enum { SEG = 16 };
    memset(m, 0, sizeof *m);
    m->pos[1] = (float)(cy + r);
    for (int ring = 1; ring <= 2; ring++)
        for (int k = 0; k < SEG; k++) {
            double th = alpha * ring / 2.0, ph = 2.0 * 3.14159265358979323846 * k / SEG;
            float *p = m->pos + 3 * (1 + (ring - 1) * SEG + k);
            p[0] = (float)(r * sin(th) * cos(ph)), p[1] = (float)(cy + r * cos(th)), p[2] = (float)(r * sin(th) * sin(ph));
        }
    m->vertex_count = 1 + 2 * SEG;
    for (int k = 0; k < SEG; k++) { /* counter-clockwise seen from outside (above) */
        int a = 1 + k, b = 1 + (k + 1) % SEG, c = a + SEG, d = b + SEG;
        uint16_t tri[9] = {0, (uint16_t)b, (uint16_t)a, (uint16_t)a, (uint16_t)b, (uint16_t)d,
                           (uint16_t)a, (uint16_t)d, (uint16_t)c};
        memcpy(m->idx + m->index_count, tri, sizeof tri);
        m->index_count += 9;
    }
}

void lmt_mesh_cube_inward(lmt_mesh *m, float h)
{
    lmt_mesh_cube(m, h);
    for (int t = 0; t < m->index_count; t += 3) {
        uint16_t k = m->idx[t + 1];
        m->idx[t + 1] = m->idx[t + 2];
        m->idx[t + 2] = k;
    }
}

void lmt_base64(const void *data, size_t n, char *out)
{
    static const char *A = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const uint8_t *d = data;
    char *p = out;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)d[i] << 16 | (i + 1 < n ? (uint32_t)d[i + 1] << 8 : 0) | (i + 2 < n ? d[i + 2] : 0);
        *p++ = A[(v >> 18) & 63];
        *p++ = A[(v >> 12) & 63];
        *p++ = i + 1 < n ? A[(v >> 6) & 63] : '=';
        *p++ = i + 2 < n ? A[v & 63] : '=';
    }
    *p = '\0';
}

static char *base64(const uint8_t *d, size_t n)
{
    char *o = malloc(4 * ((n + 2) / 3) + 1);
    if (o)
        lmt_base64(d, n, o);
    return o;
}

int lmt_lmgi(const char *shell_prefix, const char *args, char *output, size_t size)
{
    const char *build = getenv("LMGI_BUILD");
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s%s/lmgi %s 2>&1", shell_prefix, build ? build : "build", args);
    return lmt_run(cmd, output, size);
}

static void float_min_max(const float *p, int count, float mn[3], float mx[3])
{
    for (int k = 0; k < 3; k++) {
        mn[k] = 1e30f;
        mx[k] = -1e30f;
    }
    for (int i = 0; i < count; i++)
        for (int k = 0; k < 3; k++) {
            mn[k] = p[3 * i + k] < mn[k] ? p[3 * i + k] : mn[k];
            mx[k] = p[3 * i + k] > mx[k] ? p[3 * i + k] : mx[k];
        }
}

static int comps(const char *type)
{
    return !strcmp(type, "VEC4") ? 4 : !strcmp(type, "VEC3") ? 3 : !strcmp(type, "VEC2") ? 2 : 1;
}

int lmt_write_gltf(const char *path, const lmt_mesh *meshes, int mesh_count, const char *nodes_json,
                   const lmt_accessor *extra, int extra_count, const char *extra_json)
{
    size_t size = 0;
    for (int i = 0; i < mesh_count; i++)
        size += (size_t)meshes[i].vertex_count * 12 + (((size_t)meshes[i].index_count * 2 + 3) & ~(size_t)3);
    for (int i = 0; i < extra_count; i++)
        size += (size_t)extra[i].count * comps(extra[i].type) * 4;
    uint8_t *buf = calloc(size ? size : 1, 1);
    FILE *f = fopen(path, "w");
    if (!buf || !f) {
        free(buf);
        if (f)
            fclose(f);
        return -1;
    }
    fprintf(f, "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],\n");
    fprintf(f, "\"nodes\": %s,\n", nodes_json);
    if (extra_json)
        fprintf(f, "%s\n", extra_json);
    size_t off = 0;
    int acc = 0;
    fprintf(f, "\"meshes\": [");
    for (int i = 0; i < mesh_count; i++)
        fprintf(f, "%s{\"primitives\": [{\"attributes\": {\"POSITION\": %d}, \"indices\": %d}]}", i ? "," : "",
                2 * i, 2 * i + 1);
    fprintf(f, "],\n\"accessors\": [");
    char views[8192] = "";
    for (int i = 0; i < mesh_count; i++) {
        const lmt_mesh *m = &meshes[i];
        float mn[3], mx[3];
        float_min_max(m->pos, m->vertex_count, mn, mx);
        size_t pb = (size_t)m->vertex_count * 12, ib = (size_t)m->index_count * 2;
        memcpy(buf + off, m->pos, pb);
        memcpy(buf + off + pb, m->idx, ib);
        fprintf(f, "%s{\"bufferView\": %d, \"componentType\": 5126, \"count\": %d, \"type\": \"VEC3\", "
                "\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]},", i ? "," : "", acc, m->vertex_count,
                (double)mn[0], (double)mn[1], (double)mn[2], (double)mx[0], (double)mx[1], (double)mx[2]);
        fprintf(f, "{\"bufferView\": %d, \"componentType\": 5123, \"count\": %d, \"type\": \"SCALAR\"}", acc + 1,
                m->index_count);
        snprintf(views + strlen(views), sizeof views - strlen(views),
                 "%s{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu},"
                 "{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}",
                 acc ? "," : "", off, pb, off + pb, ib);
        off += pb + ((ib + 3) & ~(size_t)3);
        acc += 2;
    }
    for (int i = 0; i < extra_count; i++) {
        size_t bytes = (size_t)extra[i].count * comps(extra[i].type) * 4;
        memcpy(buf + off, extra[i].data, bytes);
        fprintf(f, "%s{\"bufferView\": %d, \"componentType\": 5126, \"count\": %d, \"type\": \"%s\"", acc ? "," : "",
                acc, extra[i].count, extra[i].type);
        if (!strcmp(extra[i].type, "SCALAR")) { /* animation inputs need min/max */
            float lo = extra[i].data[0], hi = extra[i].data[extra[i].count - 1];
            fprintf(f, ", \"min\": [%g], \"max\": [%g]", (double)lo, (double)hi);
        }
        fprintf(f, "}");
        snprintf(views + strlen(views), sizeof views - strlen(views),
                 "%s{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}", acc ? "," : "", off, bytes);
        off += bytes;
        acc++;
    }
    char *b64 = base64(buf, size);
    fprintf(f, "],\n\"bufferViews\": [%s],\n", views);
    fprintf(f, "\"buffers\": [{\"byteLength\": %zu, \"uri\": \"data:application/octet-stream;base64,%s\"}]}\n", size,
            b64 ? b64 : "");
    free(b64);
    free(buf);
    return fclose(f) == 0 ? 0 : -1;
}

void lmt_pipeline_load(lmt_pipeline *p, const char *path, float texel_size)
{
    memset(p, 0, sizeof *p);
    lm_error err;
    lm_load_options lo = {0};
    lm_surface_options so;
    lm_atlas_options ao;
    lm_surface_options_default(&so);
    lm_atlas_options_default(&ao);
    ao.texel_size = texel_size;
    if (lm_scene_load_gltf(path, &lo, &p->s, &err) != LM_OK || lm_surfaces_build(p->s, &so, &p->su, &err) != LM_OK ||
        lm_atlas_build(p->s, &p->su, &ao, &p->atlas, &err) != LM_OK || lm_rt_build(p->s, &p->su, &p->rt, &err) != LM_OK ||
        lm_emitters_build(p->s, &p->em, &err) != LM_OK)
        fail_msg("loading %s: %s", path, err.msg);
    p->w = (lm_world){p->s, &p->su, &p->atlas, p->rt, NULL}; /* no edits staged: the tests move nodes themselves */
}

void lmt_pipeline_free(lmt_pipeline *p)
{
    lm_emitters_free(&p->em);
    lm_rt_free(p->rt);
    lm_atlas_free(&p->atlas);
    lm_surfaces_free(&p->su);
    lm_scene_free(p->s);
}

void lmt_reference_texels(const lmt_pipeline *p, float target_error, lm_ref_result *out)
{
    lm_ref_settings rs;
    lm_ref_settings_default(&rs);
    rs.target_error = target_error;
    rs.use_cache = 0;
    rs.progress = 0;
    lm_error err;
    if (lm_reference_texels(p->s, &p->atlas, p->rt, &p->em, &rs, out, &err) != LM_OK)
        fail_msg("reference: %s", err.msg);
}

static lm_gl_context *g_gl;

int lmt_gl_setup(void **state)
{
    (void)state;
    lm_error err;
    if (lm_gl_context_create(&g_gl, &err) != LM_OK) {
        fprintf(stderr, "GL context: %s\n", err.msg);
        return -1;
    }
    return 0;
}

int lmt_gl_teardown(void **state)
{
    (void)state;
    lm_gl_context_destroy(g_gl);
    g_gl = NULL;
    return 0;
}

const char *lmt_plane_scene(void) { return lmt_plane_scene_with("{\"type\": \"point\", \"intensity\": 10}"); }

const char *lmt_plane_scene_with(const char *light)
{
    static char path[512];
    static lmt_mesh m;
    memset(&m, 0, sizeof m);
    lmt_mesh_quad(&m, (float[3]){-10, 0, 10}, (float[3]){20, 0, 0}, (float[3]){0, 0, -20});
    const char *nodes = "[{\"children\": [1, 2]}, {\"mesh\": 0},"
                        " {\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]";
    char ext[512];
    snprintf(ext, sizeof ext,
             "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [%s]}},",
             light);
    snprintf(path, sizeof path, "%s/plane.gltf", lmt_tmpdir());
    if (lmt_write_gltf(path, &m, 1, nodes, NULL, 0, ext) != 0)
        fail_msg("cannot write %s", path);
    return path;
}

/* Gives every primitive material 0 (lmt_write_gltf writes none) by rewriting the file's text. */
void lmt_use_material_0(const char *path)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    static char in[1 << 18], out[1 << 19];
    size_t n = fread(in, 1, sizeof in - 1, f);
    fclose(f);
    in[n] = '\0';
    char *o = out;
    for (const char *p = in; *p;) {
        const char *q = strstr(p, "\"indices\": ");
        if (!q) {
            o += sprintf(o, "%s", p);
            break;
        }
        const char *close = strchr(q, '}');
        o += sprintf(o, "%.*s, \"material\": 0}", (int)(close - p), p);
        p = close + 1;
    }
    f = fopen(path, "wb");
    assert_non_null(f);
    fputs(out, f);
    fclose(f);
}

/* Writes the meshes with mesh i using material i (materials_json: the "materials" array's text). */
const char *lmt_write_scene(const char *name, const lmt_mesh *meshes, int count, const char *nodes,
                            const char *materials)
{
    static char path[512], extra[1 << 16];
    snprintf(path, sizeof path, "%s/%s", lmt_tmpdir(), name);
    if (snprintf(extra, sizeof extra, "\"materials\": %s,", materials) >= (int)sizeof extra)
        fail_msg("lmt_write_scene: the materials text is over %zu bytes", sizeof extra);
    assert_int_equal(lmt_write_gltf(path, meshes, count, nodes, NULL, 0, extra), 0);
    static char in[1 << 18], out[1 << 19];
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    size_t n = fread(in, 1, sizeof in - 1, f);
    fclose(f);
    in[n] = '\0';
    char *o = out;
    int prim = 0;
    for (const char *p = in; *p;) { /* "indices": K}  ->  "indices": K, "material": prim} */
        const char *q = strstr(p, "\"indices\": ");
        if (!q) {
            o += sprintf(o, "%s", p);
            break;
        }
        const char *close = strchr(q, '}');
        o += sprintf(o, "%.*s, \"material\": %d}", (int)(close - p), p, prim++);
        p = close + 1;
    }
    f = fopen(path, "wb");
    assert_non_null(f);
    fputs(out, f);
    fclose(f);
    return path;
}

const char *lmt_mirror_scene(const char *name, const char *mirror_extras, const char *cube_extras)
{
    static lmt_mesh m[3];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-4, 0, 4}, (float[3]){8, 0, 0}, (float[3]){0, 0, -8});
    lmt_mesh_quad(&m[1], (float[3]){1, 0.75f, -0.25f}, (float[3]){0, 0, 0.5f}, (float[3]){0, 0.5f, 0});
    lmt_mesh_cube(&m[2], 0.2f);
    char nodes[1024];
    snprintf(nodes, sizeof nodes,
             "[{\"mesh\": 0}, {\"mesh\": 1%s%s}, {\"translation\": [0, 2, 0], \"extensions\": "
             "{\"KHR_lights_punctual\": {\"light\": 0}}}%s%s%s, {\"camera\": 0, \"translation\": [-0.15, 4, 0], "
             "\"rotation\": [-0.7071068, 0, 0, 0.7071068]}]",
             mirror_extras ? ", \"extras\": " : "", mirror_extras ? mirror_extras : "",
             cube_extras ? ", {\"name\": \"cube\", \"mesh\": 2, \"translation\": [-2, 0.2, -2], \"extras\": " : "",
             cube_extras ? cube_extras : "", cube_extras ? "}" : "");
    return lmt_write_scene(name, m, cube_extras ? 3 : 2, nodes,
                           "[" LMT_DIFFUSE(0.8) ", " LMT_MIRROR(0.9) ", " LMT_DIFFUSE(0.5) "], "
                           "\"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 1.0472, "
                           "\"znear\": 0.1, \"aspectRatio\": 1}}], "
                           LMT_LIGHTS("{\"type\": \"point\", \"intensity\": 10}"));
}

double lmt_mirror_image(double x, double z, int *inside)
{
    double t = 1.0 / (2.0 - x), y = 2.0 - 2.0 * t, zz = z * t; /* where the line to it crosses x = 1 */
    *inside = x < 2.0 && y >= 0.75 && y <= 1.25 && fabs(zz) <= 0.25;
    double d = sqrt((2.0 - x) * (2.0 - x) + 4.0 + z * z);
    /* the light arrives at the mirror from (0, 2, 0) at cos = 1 / |(1, y - 2, zz)| */
    double cos_i = 1.0 / sqrt(1.0 + (y - 2.0) * (y - 2.0) + zz * zz), m = 1.0 - cos_i;
    return lmt_mirror_fresnel(0.9, m) * 10.0 * 2.0 / (d * d * d);
}

double lmt_mirror_fresnel(double albedo, double one_minus_cos) { return albedo + (1.0 - albedo) * pow(one_minus_cos, 5.0); }

const char *lmt_node_modules(const char *package, const char **why)
{
    static char abs[PATH_MAX];
    char dir[PATH_MAX], probe[PATH_MAX + 64];
    const char *npm = getenv("LMGI_NPM");
    snprintf(dir, sizeof dir, "%s/node_modules", npm ? npm : "build/npm");
    snprintf(probe, sizeof probe, "%s/%s/package.json", dir, package);
    if (system("command -v node > /dev/null 2>&1") != 0) {
        *why = "node is not installed (Debian: apt-get install nodejs npm)";
        return NULL;
    }
    if (access(probe, R_OK) != 0 || !realpath(dir, abs)) {
        *why = "the node package is not in build/npm (make test installs it with npm; was the registry reachable?)";
        return NULL;
    }
    return abs;
}

int lmt_run(const char *cmd, char *out, size_t size)
{
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t n = fread(out, 1, size - 1, p);
    out[n] = '\0';
    char sink[4096];
    while (fread(sink, 1, sizeof sink, p) > 0) {
    }
    int status = pclose(p);
    assert_true(WIFEXITED(status));
    return WEXITSTATUS(status);
}

void lmt_gltf_validate(const char *modules, const char *gltf)
{
    static char out[1 << 16];
    char cmd[3 * PATH_MAX];
    snprintf(cmd, sizeof cmd, "node tests/engines/validate.mjs '%s' '%s' 2>&1", modules, gltf);
    int rc = lmt_run(cmd, out, sizeof out);
    print_message("%s", out);
    assert_int_equal(rc, 0);
}

void lmt_hub_init(lmt_hub *h, int n)
{
    memset(h, 0, sizeof *h);
    assert_true(n > 0 && n <= 8);
    h->n = n;
    assert_int_equal(pthread_barrier_init(&h->barrier, NULL, (unsigned)n), 0);
}

void lmt_hub_free(lmt_hub *h) { pthread_barrier_destroy(&h->barrier); }

/* Each thread posts its bytes and waits; all read; all wait again before anyone may post the next. */
int lmt_hub_exchange(lmt_hub *h, int id, const void *mine, size_t size, size_t *sizes, void *all)
{
    h->mine[id] = mine, h->size[id] = size;
    h->calls[id]++;
    pthread_barrier_wait(&h->barrier);
    size_t at = 0;
    for (int q = 0; q < h->n; q++) {
        if (all)
            memcpy((unsigned char *)all + at, h->mine[q], h->size[q]);
        else
            sizes[q] = h->size[q];
        at += h->size[q];
    }
    pthread_barrier_wait(&h->barrier);
    return 1;
}
