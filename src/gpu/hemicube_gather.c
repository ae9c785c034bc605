/* The GPU gather (hemicube.h): tiled rendering of many texels' hemicube planes, then a compute
 * reduction per tile that writes straight into the IIM texture (Larsen & Christensen section 4). */
#include "hemicube.h"

#include "gl_api.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../charts/atlas_dilate.h"
#include "../core/timing.h"
#include "../core/vecmath.h"
#include "gl_context.h"
#include "gl_mesh.h"
#include "gl_shader.h"

/* Vertex: world position, lightmap UV (-1 when none), emitted radiance, face normal, single-sided,
 * surface (-1 when none). */
#define VERTEX_FLOATS 13

static const char *RENDER_VS =
    "#version 450 core\n"
    "layout(location = 0) in vec3 pos;\n"
    "layout(location = 1) in vec2 uv;\n"
    "layout(location = 2) in vec3 emit;\n"
    "layout(location = 3) in vec3 face_n;\n"
    "layout(location = 4) in float one_sided;\n"
    "layout(location = 5) in float surface;\n"
    "uniform mat4 view_proj;\n"
    "out vec3 v_pos; out vec2 v_uv; flat out vec3 v_emit; flat out vec3 v_n; flat out float v_one, v_surf;\n"
    "void main() {\n"
    "    v_pos = pos; v_uv = uv; v_emit = emit; v_n = face_n; v_one = one_sided; v_surf = surface;\n"
    "    gl_Position = view_proj * vec4(pos, 1.0);\n"
    "}\n";
/* rgb: what the plane sees; a: 1 on the back of a single-sided surface (counted, shown black). The back
 * of the texel's own surface is skipped: a surface stays within a 30 degree cone, so only a simplified
 * (proxy) copy of it can pass above the texel. */
static const char *RENDER_FS =
    "#version 450 core\n"
    "in vec3 v_pos; in vec2 v_uv; flat in vec3 v_emit; flat in vec3 v_n; flat in float v_one, v_surf;\n"
    "uniform sampler2D aim;\n"
    "uniform vec3 eye;\n"
    "uniform float own_surface;\n"
    "out vec4 frag;\n"
    "void main() {\n"
    "    if (dot(v_n, v_pos - eye) > 0.0) {\n"
    "        if (v_surf >= 0.0 && v_surf == own_surface) discard;\n"
    "        if (v_one > 0.5) { frag = vec4(0.0, 0.0, 0.0, 1.0); return; }\n"
    "    }\n"
    "    vec3 L = v_uv.x < 0.0 ? vec3(0.0) : texture(aim, v_uv).rgb;\n"
    "    frag = vec4(L + v_emit, 0.0);\n"
    "}\n";
/* One work group per tile: weighted sums in a fixed order, then a fixed tree (deterministic). */
static const char *REDUCE_CS =
    "#version 450 core\n"
    "layout(local_size_x = 64) in;\n"
    "layout(binding = 0) uniform sampler2D tiles;\n"
    "layout(binding = 0, rgba32f) uniform writeonly image2D iim;\n"
    "layout(std430, binding = 0) readonly buffer Weights { float w[]; };\n"
    "layout(std430, binding = 1) readonly buffer Targets { ivec2 xy[]; };\n"
    "uniform int R;\n"
    "uniform int tiles_x;\n"
    "uniform float scale;   /* pi / F(a) */\n"
    "uniform float inv_f;   /* 1 / F(a) */\n"
    "shared vec4 part[64];\n"
    "void main() {\n"
    "    int tile = int(gl_WorkGroupID.x), lid = int(gl_LocalInvocationID.x);\n"
    "    ivec2 origin = ivec2(tile % tiles_x, tile / tiles_x) * R;\n"
    "    vec4 s = vec4(0.0);\n"
    "    for (int p = lid; p < R * R; p += 64)\n"
    "        s += w[p] * texelFetch(tiles, origin + ivec2(p % R, p / R), 0);\n"
    "    part[lid] = s;\n"
    "    barrier();\n"
    "    for (int k = 32; k > 0; k >>= 1) {\n"
    "        if (lid < k) part[lid] += part[lid + k];\n"
    "        barrier();\n"
    "    }\n"
    "    if (lid == 0) imageStore(iim, xy[tile], vec4(scale * part[0].rgb, inv_f * part[0].a));\n"
    "}\n";

struct lm_gather {
    lm_hemicube_settings set;
    GLuint render_prog, reduce_prog;
    GLuint fbo, color, depth;
    GLuint weights_buf, targets_buf;
    GLuint aim_tex;
    int aim_w, aim_h;
    lm_gl_mesh mesh;
    int has_mesh;
    lm_proxy proxy;        /* with has_proxy: built for proxy_scene, proxy_atlas */
    int has_proxy;
    const lm_scene *proxy_scene;
    const lm_atlas *proxy_atlas;
    double coverage;
};

static lm_status make_target(lm_gather *g, lm_error *err)
{
    int side = g->set.tiles * g->set.resolution;
    glGenTextures(1, &g->color);
    glBindTexture(GL_TEXTURE_2D, g->color);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, side, side);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glGenRenderbuffers(1, &g->depth);
    glBindRenderbuffer(GL_RENDERBUFFER, g->depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, side, side);
    glGenFramebuffers(1, &g->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, g->color, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, g->depth);
    GLenum fb = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (fb != GL_FRAMEBUFFER_COMPLETE)
        return lm_fail(err, LM_ERR_BACKEND, "hemicube gather: render target incomplete (0x%04x)", (unsigned)fb);
    return lm_gl_check("hemicube gather: render target", err);
}

static lm_status upload_weights(lm_gather *g, lm_error *err)
{
    int R = g->set.resolution;
    float *w = malloc(sizeof(float) * (size_t)R * (size_t)R);
    if (!w)
        return lm_fail(err, LM_ERR_NOMEM, "hemicube gather: no memory for weights");
    for (int j = 0; j < R; j++)
        for (int i = 0; i < R; i++)
            w[j * R + i] = (float)lm_hemicube_pixel_weight(R, g->set.enlargement, i, j);
    glGenBuffers(1, &g->weights_buf);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->weights_buf);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(float) * (size_t)R * (size_t)R), w, GL_STATIC_DRAW);
    free(w);
    glGenBuffers(1, &g->targets_buf);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->targets_buf);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(int) * 2 * (size_t)g->set.tiles * (size_t)g->set.tiles),
                 NULL, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    return lm_gl_check("hemicube gather: weight buffers", err);
}

static lm_status check_settings(const lm_hemicube_settings *s, lm_error *err)
{
    GLint max_side = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_side);
    if (s->resolution < 2 || s->tiles < 1 || !(s->enlargement > 0.0f) || !(s->offset >= 0.0f) ||
        !(s->proxy_error >= 0.0f && s->proxy_error < 1.0f) ||
        (long)s->resolution * s->tiles > max_side)
        return lm_fail(err, LM_ERR_INVALID, "hemicube settings out of range (resolution %d, tiles %d, a %g)",
                       s->resolution, s->tiles, (double)s->enlargement);
    return LM_OK;
}

lm_status lm_gather_create(const lm_hemicube_settings *set, lm_gather **out, lm_error *err)
{
    *out = NULL;
    lm_status st = check_settings(set, err);
    if (st != LM_OK)
        return st;
    lm_gather *g = calloc(1, sizeof *g);
    if (!g)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the hemicube gather");
    g->set = *set;
    g->coverage = lm_hemicube_coverage(set->enlargement);
    st = lm_gl_program("hemicube_render", RENDER_VS, RENDER_FS, &g->render_prog, err);
    if (st == LM_OK)
        st = lm_gl_compute_program("hemicube_reduce", REDUCE_CS, &g->reduce_prog, err);
    if (st == LM_OK)
        st = make_target(g, err);
    if (st == LM_OK)
        st = upload_weights(g, err);
    if (st != LM_OK) {
        lm_gather_free(g);
        return st;
    }
    *out = g;
    return LM_OK;
}

void lm_gather_free(lm_gather *g)
{
    if (!g)
        return;
    if (g->has_mesh)
        lm_gl_mesh_destroy(&g->mesh);
    if (g->has_proxy)
        lm_proxy_free(&g->proxy);
    GLuint bufs[2] = {g->weights_buf, g->targets_buf};
    glDeleteBuffers(2, bufs);
    glDeleteTextures(1, &g->aim_tex);
    glDeleteTextures(1, &g->color);
    glDeleteRenderbuffers(1, &g->depth);
    glDeleteFramebuffers(1, &g->fbo);
    glDeleteProgram(g->render_prog);
    glDeleteProgram(g->reduce_prog);
    free(g);
}

const lm_hemicube_settings *lm_gather_settings(const lm_gather *g) { return &g->set; }

/* One triangle's three vertices (VERTEX_FLOATS each) from world positions, lightmap UVs (NULL: no
 * AIM, drawn black: mirror, glass) and its material. */
static void write_triangle(const float p[3][3], const float *uv[3], const lm_material *m, int surface, float *o)
{
    lm_vec3 n = lm_cross(lm_sub(lm_v3_load(p[1]), lm_v3_load(p[0])), lm_sub(lm_v3_load(p[2]), lm_v3_load(p[0])));
    float len = lm_length(n);
    n = len > 0.0f ? lm_scale(n, 1.0f / len) : lm_v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        float *v = o + VERTEX_FLOATS * k;
        memcpy(v, p[k], 3 * sizeof(float));
        v[3] = uv[k] ? uv[k][0] : -1.0f;
        v[4] = uv[k] ? uv[k][1] : -1.0f;
        memcpy(v + 5, m->emissive, 3 * sizeof(float));
        lm_v3_store(v + 8, n);
        v[11] = m->double_sided ? 0.0f : 1.0f;
        v[12] = (float)surface;
    }
}

static void scene_triangle(const lm_scene *s, const lm_atlas *a, uint32_t t, float *o)
{
    float p[3][3];
    const float *uv[3];
    for (int k = 0; k < 3; k++) {
        lm_scene_vertex_world(s, s->tris[3 * (size_t)t + k], p[k]);
        uv[k] = a->corner_uv + 6 * (size_t)t + 2 * k;
        if (a->tri_chart[t] < 0 || !isfinite(uv[k][0]))
            uv[k] = NULL;
    }
    int c = a->tri_chart[t];
    write_triangle(p, uv, &s->materials[s->tri_material[t]], c < 0 ? -1 : a->charts[c].surface, o);
}

static void proxy_triangle(const lm_scene *s, const lm_atlas *a, const lm_proxy *px, uint32_t t, float *o)
{
    float p[3][3];
    const float *uv[3];
    for (int k = 0; k < 3; k++) {
        uint32_t v = px->tris[3 * (size_t)t + k];
        lm_proxy_vertex_world(s, px, px->tri_node[t], v, p[k]);
        uv[k] = px->vertices[v].chart < 0 ? NULL : px->vertices[v].uv;
    }
    const lm_proxy_vertex *v0 = &px->vertices[px->tris[3 * (size_t)t]];
    write_triangle(p, uv, &s->materials[v0->material], v0->chart < 0 ? -1 : a->charts[v0->chart].surface, o);
}

/* Builds the proxy once per (scene, atlas); proxy_error 0 drops it. */
static lm_status ensure_proxy(lm_gather *g, const lm_scene *s, const lm_atlas *a, lm_error *err)
{
    if (g->has_proxy && g->proxy_scene == s && g->proxy_atlas == a && g->proxy.source_tris == s->tri_count)
        return LM_OK;
    if (g->has_proxy)
        lm_proxy_free(&g->proxy);
    g->has_proxy = 0;
    if (!(g->set.proxy_error > 0.0f))
        return LM_OK;
    lm_status st = lm_proxy_build(s, a, g->set.proxy_error, &g->proxy, err);
    if (st == LM_OK)
        g->has_proxy = 1, g->proxy_scene = s, g->proxy_atlas = a;
    return st;
}

const lm_proxy *lm_gather_proxy(const lm_gather *g) { return g->has_proxy ? &g->proxy : NULL; }

lm_status lm_gather_set_scene(lm_gather *g, const lm_scene *s, const lm_atlas *a, lm_error *err)
{
    lm_status st = ensure_proxy(g, s, a, err);
    if (st != LM_OK)
        return st;
    uint32_t count = g->has_proxy ? g->proxy.tri_count : s->tri_count;
    float *v = malloc(sizeof(float) * 3 * VERTEX_FLOATS * (size_t)(count ? count : 1));
    if (!v)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the gather geometry", s->path);
    for (uint32_t t = 0; t < count; t++) {
        if (g->has_proxy)
            proxy_triangle(s, a, &g->proxy, t, v + 3 * VERTEX_FLOATS * (size_t)t);
        else
            scene_triangle(s, a, t, v + 3 * VERTEX_FLOATS * (size_t)t);
    }
    if (g->has_mesh)
        lm_gl_mesh_destroy(&g->mesh);
    const int sizes[6] = {3, 2, 3, 3, 1, 1};
    lm_gl_mesh_create(&g->mesh, v, (int)(3 * count), sizes, 6);
    g->has_mesh = 1;
    free(v);
    return lm_gl_check("hemicube gather: scene upload", err);
}

lm_status lm_gather_set_aim(lm_gather *g, const lm_atlas *a, const float *aim_rgb, lm_error *err)
{
    size_t n = 3 * (size_t)a->width * (size_t)a->height;
    float *d = malloc(sizeof(float) * n);
    if (!d)
        return lm_fail(err, LM_ERR_NOMEM, "no memory to dilate the AIM");
    memcpy(d, aim_rgb, sizeof(float) * n);
    lm_atlas_dilate(a, d, 3, a->gutter > 1 ? a->gutter : 1); /* chart edges must not blend in black */
    if (!g->aim_tex || g->aim_w != a->width || g->aim_h != a->height) {
        glDeleteTextures(1, &g->aim_tex);
        glGenTextures(1, &g->aim_tex);
        glBindTexture(GL_TEXTURE_2D, g->aim_tex);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGB32F, a->width, a->height);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        g->aim_w = a->width, g->aim_h = a->height;
    }
    glBindTexture(GL_TEXTURE_2D, g->aim_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, a->width, a->height, GL_RGB, GL_FLOAT, d);
    free(d);
    return lm_gl_check("hemicube gather: AIM upload", err);
}

/* The texel's centre and normal under the current node matrices (barycentric on its triangle). */
static void texel_frame(const lm_scene *s, const lm_texel *tx, lm_vec3 *pos, lm_vec3 *n)
{
    lm_vec3 p = lm_v3(0, 0, 0), nn = lm_v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        float v[3], vn[3];
        lm_scene_vertex_world(s, s->tris[3 * (size_t)tx->tri + k], v);
        lm_scene_normal_world(s, s->tris[3 * (size_t)tx->tri + k], vn);
        p = lm_add(p, lm_scale(lm_v3_load(v), tx->bary[k]));
        nn = lm_add(nn, lm_scale(lm_v3_load(vn), tx->bary[k]));
    }
    *pos = p;
    *n = lm_length(nn) > 0.0f ? lm_normalize(nn) : lm_normalize(lm_v3_load(tx->normal));
}

/* Reversed-depth projection through the plane [-a, a]^2 at distance 1 along n, from eye e (column-major):
 * clip = (b.q / a, t.q / a, near, n.q) for q = p - e, so depth = near / distance, no far plane. */
static void plane_view_proj(lm_vec3 e, lm_vec3 n, float a, float near, float m[16])
{
    lm_vec3 helper = fabsf(n.x) < 0.9f ? lm_v3(1, 0, 0) : lm_v3(0, 1, 0);
    lm_vec3 t = lm_normalize(lm_cross(helper, n)), b = lm_cross(n, t);
    const lm_vec3 rows[3] = {lm_scale(b, 1.0f / a), lm_scale(t, 1.0f / a), n};
    const int at[3] = {0, 1, 3};
    memset(m, 0, 16 * sizeof(float));
    for (int r = 0; r < 3; r++) {
        m[0 + at[r]] = rows[r].x, m[4 + at[r]] = rows[r].y, m[8 + at[r]] = rows[r].z;
        m[12 + at[r]] = -lm_dot(rows[r], e);
    }
    m[12 + 2] = near;
}

static void render_tiles(lm_gather *g, const lm_scene *s, const lm_atlas *a, const uint32_t *texels, uint32_t count,
                         int *xy)
{
    int R = g->set.resolution, T = g->set.tiles;
    float size = lm_scene_size(s), lift = g->set.offset * size, near = 0.5f * g->set.offset * size;
    if (!(near > 0.0f))
        near = 1e-6f;
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo);
    glViewport(0, 0, T * R, T * R);
    glDisable(GL_SCISSOR_TEST);
    glClearColor(g->set.sky[0], g->set.sky[1], g->set.sky[2], 0.0f);
    glClearDepth(0.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUseProgram(g->render_prog);
    glUniform1i(glGetUniformLocation(g->render_prog, "aim"), 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g->aim_tex);
    GLint vp_loc = glGetUniformLocation(g->render_prog, "view_proj"), eye_loc = glGetUniformLocation(g->render_prog, "eye");
    GLint own_loc = glGetUniformLocation(g->render_prog, "own_surface");
    for (uint32_t i = 0; i < count; i++) {
        const lm_texel *tx = &a->texels[texels[i]];
        lm_vec3 p, n;
        texel_frame(s, tx, &p, &n);
        lm_vec3 e = lm_add(p, lm_scale(n, lift));
        float m[16];
        plane_view_proj(e, n, g->set.enlargement, near, m);
        glUniformMatrix4fv(vp_loc, 1, GL_FALSE, m);
        glUniform3f(eye_loc, e.x, e.y, e.z);
        glUniform1f(own_loc, (float)tx->surface);
        glViewport((int)(i % (uint32_t)T) * R, (int)(i / (uint32_t)T) * R, R, R);
        lm_gl_mesh_draw(&g->mesh);
        xy[2 * i] = tx->x, xy[2 * i + 1] = tx->y;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

static void reduce_tiles(lm_gather *g, unsigned iim_tex, const int *xy, uint32_t count)
{
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->targets_buf);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(sizeof(int) * 2 * count), xy);
    glUseProgram(g->reduce_prog);
    glUniform1i(glGetUniformLocation(g->reduce_prog, "R"), g->set.resolution);
    glUniform1i(glGetUniformLocation(g->reduce_prog, "tiles_x"), g->set.tiles);
    glUniform1f(glGetUniformLocation(g->reduce_prog, "scale"), (float)(3.14159265358979323846 / g->coverage));
    glUniform1f(glGetUniformLocation(g->reduce_prog, "inv_f"), (float)(1.0 / g->coverage));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g->color);
    glBindImageTexture(0, iim_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, g->weights_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, g->targets_buf);
    glDispatchCompute(count, 1, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

lm_status lm_gather_texels(lm_gather *g, const lm_scene *s, const lm_atlas *a, const uint32_t *texels,
                           uint32_t count, unsigned iim_tex, lm_gather_stats *stats, lm_error *err)
{
    if (!g->has_mesh || !g->aim_tex)
        return lm_fail(err, LM_ERR_INVALID, "hemicube gather: set the scene and the AIM first");
    double t0 = lm_now();
    uint32_t per_pass = (uint32_t)(g->set.tiles * g->set.tiles);
    int *xy = malloc(sizeof(int) * 2 * per_pass);
    if (!xy)
        return lm_fail(err, LM_ERR_NOMEM, "hemicube gather: no memory");
    PFNGLCLIPCONTROLPROC clip_control = (PFNGLCLIPCONTROLPROC)lm_gl_get_proc("glClipControl");
    if (!clip_control) {
        free(xy);
        return lm_fail(err, LM_ERR_BACKEND, "hemicube gather: glClipControl (GL 4.5) is missing");
    }
    clip_control(GL_LOWER_LEFT, GL_ZERO_TO_ONE); /* reversed float depth */
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDisable(GL_CULL_FACE);
    int passes = 0;
    for (uint32_t first = 0; first < count; first += per_pass, passes++) {
        uint32_t n = count - first < per_pass ? count - first : per_pass;
        render_tiles(g, s, a, texels + first, n, xy);
        reduce_tiles(g, iim_tex, xy, n);
    }
    clip_control(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    glDepthFunc(GL_LESS);
    glClearDepth(1.0);
    free(xy);
    glFinish();
    if (stats) {
        stats->texels = count;
        stats->passes = passes;
        stats->seconds = lm_now() - t0;
    }
    return lm_gl_check("hemicube gather (hemicube_render, hemicube_reduce)", err);
}
