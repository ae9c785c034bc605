/* The GPU gather (hemicube.h): tiled rendering of many texels' hemicube planes, then a compute
 * reduction per tile that writes straight into the IIM texture (Larsen & Christensen section 4). */
#include "hemicube.h"

#include "../gl/gl_api.h"
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "../../charts/atlas_dilate.h"
#include "../../core/hash.h"
#include "../../core/timing.h"
#include "../../core/vecmath.h"
#include "../gl/gl_context.h"
#include "../gl/gl_mesh.h"
#include "../gl/gl_shader.h"
#include "../gl/offscreen.h"
#include "gather_passes.h"
#include "hemicube_shaders.h"
#include "../../trace/emitter_light.h"
#include "../../photonmap/hemicube_rim.h"

/* Vertex: world position, lightmap UV (-1 when none), emitted radiance, face normal, single-sided,
 * surface (-1 when none), the UV's gradient (2 x vec3) and the chart's UV rectangle; a view: 4 vec4
 * (hemicube_shaders.c). */
#define VERTEX_FLOATS 23
#define VIEW_FLOATS 16

struct lm_gather {
    lm_hemicube_settings set;
    GLuint render_prog, reduce_prog;
    GLuint fbo, color, depth;
    GLuint ms_fbo, ms_color, ms_depth; /* with coverage_samples > 1: the multisampled target, resolved into color */
    GLuint weights_buf, targets_buf, views_buf, emit_buf;
    float *views;          /* a pass's views (schemes 1, 2), tiles^2 * VIEW_FLOATS */
    const lm_emitter_light *emitters; /* non-NULL: emitters' light in closed form, not drawn */
    const lm_rt *rt;       /* non-NULL (and rim_samples > 0): the rim traced (photonmap/hemicube_rim.h) */
    lm_direct_light direct; /* with has_direct: the direct light the AIM computes, at the rays' hits */
    int has_direct;
    float *aim_copy;       /* the dilated AIM as uploaded, for the rim's lookups (atlas-sized RGBA) */
    float *whole_copy;     /* with the direct light at the hits: the whole AIM for the far hits (NULL: none) */
    float *emit;           /* a pass's irradiance from the CPU per texel (emitters, rim), tiles^2 * 4 */
    int cpu_threads;       /* for it (settings' cpu_threads, 0 resolved at creation) */
    GLuint aim_tex;
    int aim_w, aim_h;
    lm_gl_mesh mesh;
    int has_mesh;
    uint64_t mesh_key;     /* with has_mesh: scene_key of what the mesh was made from */
    uint64_t mesh_uploads; /* how many times lm_gather_set_scene made the mesh */
    lm_proxy proxy;        /* with has_proxy: built for proxy_scene, proxy_atlas */
    int has_proxy;
    const lm_scene *proxy_scene;
    const lm_atlas *proxy_atlas;
    double coverage;
    float lift;            /* the eyes' lift off their texels in the pass being drawn (lm_gather_lift) */
    int round;             /* which of its footprint points a texel of the pass is gathered at (gather_points) */
    GLuint turn_tex[3];    /* where each turning texel's turn goes (lm_gather_set_turn); 0: nowhere */
    float *turn;           /* the rays gather's turns of a pass, tiles^2 * LM_TURN_FLOATS */
};

/* Schemes 0, 1: one (tiles R)^2 2D target; scheme 2: R x R x tiles^2 layers. */
static lm_status make_target(lm_gather *g, lm_error *err)
{
    int R = g->set.resolution, side = g->set.tiles * R, layers = g->set.tiles * g->set.tiles;
    int layered = g->set.scheme == LM_GATHER_LAYERED;
    GLenum kind = layered ? GL_TEXTURE_2D_ARRAY : GL_TEXTURE_2D;
    GLuint tex[2];
    glGenTextures(2, tex);
    g->color = tex[0], g->depth = tex[1];
    for (int k = 0; k < 2; k++) {
        GLenum format = k == 0 ? GL_RGBA32F : GL_DEPTH_COMPONENT32F;
        glBindTexture(kind, tex[k]);
        if (layered)
            glTexStorage3D(kind, 1, format, R, R, layers);
        else
            glTexStorage2D(kind, 1, format, side, side);
        glTexParameteri(kind, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(kind, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    glGenFramebuffers(1, &g->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo);
    glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, g->color, 0);
    glFramebufferTexture(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, g->depth, 0);
    GLenum fb = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (fb == GL_FRAMEBUFFER_COMPLETE && g->set.coverage_samples > 1) {
        GLuint ms[2];
        glGenTextures(2, ms);
        g->ms_color = ms[0], g->ms_depth = ms[1];
        for (int k = 0; k < 2; k++) {
            glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, ms[k]);
            glTexStorage2DMultisample(GL_TEXTURE_2D_MULTISAMPLE, g->set.coverage_samples,
                                      k ? GL_DEPTH_COMPONENT32F : GL_RGBA32F, side, side, GL_TRUE);
        }
        glGenFramebuffers(1, &g->ms_fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, g->ms_fbo);
        glFramebufferTexture(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, g->ms_color, 0);
        glFramebufferTexture(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, g->ms_depth, 0);
        fb = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    }
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
    size_t per_pass = (size_t)g->set.tiles * (size_t)g->set.tiles;
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(int) * 2 * per_pass), NULL, GL_DYNAMIC_DRAW);
    glGenBuffers(1, &g->views_buf);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->views_buf);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(float) * VIEW_FLOATS * per_pass), NULL, GL_DYNAMIC_DRAW);
    g->views = malloc(sizeof(float) * VIEW_FLOATS * per_pass);
    g->emit = calloc(4 * per_pass, sizeof(float));
    if (!g->views || !g->emit)
        return lm_fail(err, LM_ERR_NOMEM, "hemicube gather: no memory for views");
    glGenBuffers(1, &g->emit_buf); /* zeros until an emitter light is set */
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->emit_buf);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(float) * 4 * per_pass), g->emit, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    return lm_gl_check("hemicube gather: weight buffers", err);
}

static int has_extension(const char *name)
{
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; i++)
        if (strcmp((const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i), name) == 0)
            return 1;
    return 0;
}

static lm_status check_settings(const lm_hemicube_settings *s, lm_error *err)
{
    GLint max_side = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_side);
    if (s->resolution < 2 || s->tiles < 1 || !(s->enlargement > 0.0f) || !(s->offset >= 0.0f) ||
        !(s->proxy_error >= 0.0f && s->proxy_error < 1.0f) ||
        (s->scheme != LM_GATHER_LAYERED && (long)s->resolution * s->tiles > max_side) ||
        (unsigned)s->scheme > LM_GATHER_RAYS || (s->samples != 1 && s->samples != 4) ||
        (s->scheme == LM_GATHER_RAYS && (s->ray_samples < 1 || s->ray_samples > 65536)) ||
        !(s->adapt >= 0.0f && s->adapt <= 1.0f) ||
        s->coverage_samples < 1 || s->coverage_samples > 16 ||
        (s->coverage_samples > 1 && s->scheme == LM_GATHER_LAYERED) || s->rim_samples < 0 ||
        s->rim_samples > 65536)
        return lm_fail(err, LM_ERR_INVALID, "hemicube settings out of range (resolution %d, tiles %d, a %g, "
                       "samples %d: 1 or 4, coverage samples %d: 1 to 16, 1 with the layered scheme, rim samples %d: "
                       "0 to 65536)", s->resolution, s->tiles, (double)s->enlargement, s->samples,
                       s->coverage_samples, s->rim_samples);
    /* the multisampled target holds float colour and float depth: both limits bind (llvmpipe: 8) */
    GLint max_color = 0, max_depth = 0;
    glGetIntegerv(GL_MAX_COLOR_TEXTURE_SAMPLES, &max_color);
    glGetIntegerv(GL_MAX_DEPTH_TEXTURE_SAMPLES, &max_depth);
    int max_coverage = max_color < max_depth ? max_color : max_depth;
    if (s->coverage_samples > 1 && s->coverage_samples > max_coverage)
        return lm_fail(err, LM_ERR_INVALID, "hemicube coverage samples %d: this GL renders at most %d samples per "
                       "pixel into float targets", s->coverage_samples, max_coverage);
    GLint layers = 0;
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &layers);
    if (s->scheme == LM_GATHER_LAYERED && (!has_extension("GL_ARB_shader_viewport_layer_array") ||
                                           (long)s->tiles * s->tiles > layers))
        return lm_fail(err, LM_ERR_BACKEND, "hemicube gather: the layered scheme needs "
                       "GL_ARB_shader_viewport_layer_array and %d array layers; use the instanced scheme",
                       s->tiles * s->tiles);
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
    g->cpu_threads = set->cpu_threads > 0 ? set->cpu_threads : lm_gl_current_is_software() ? 1 : omp_get_max_threads();
    st = lm_hemicube_programs(set->scheme == LM_GATHER_RAYS ? LM_GATHER_VIEWPORTS : set->scheme, set->samples,
                              &g->render_prog, &g->reduce_prog, err);
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
    GLuint bufs[4] = {g->weights_buf, g->targets_buf, g->views_buf, g->emit_buf};
    glDeleteBuffers(4, bufs);
    free(g->views);
    free(g->emit);
    free(g->turn);
    free(g->aim_copy);
    free(g->whole_copy);
    GLuint tex[5] = {g->aim_tex, g->color, g->depth, g->ms_color, g->ms_depth};
    glDeleteTextures(5, tex);
    glDeleteFramebuffers(1, &g->ms_fbo);
    glDeleteFramebuffers(1, &g->fbo);
    glDeleteProgram(g->render_prog);
    glDeleteProgram(g->reduce_prog);
    free(g);
}


/* One triangle's three vertices (VERTEX_FLOATS each) from world positions, lightmap UVs (NULL: no
 * AIM, drawn black: mirror, glass), its material and its chart (rectangle in UV, -1 when none). */
static void write_triangle(const float p[3][3], const float *uv[3], const lm_material *m, int surface,
                           const float rect[4], int draw_emission, float *o)
{
    lm_vec3 n = lm_cross(lm_sub(lm_v3_load(p[1]), lm_v3_load(p[0])), lm_sub(lm_v3_load(p[2]), lm_v3_load(p[0])));
    float len = lm_length(n), gu[3], gv[3];
    n = len > 0.0f ? lm_scale(n, 1.0f / len) : lm_v3(0, 0, 0);
    lm_uv_gradient(p, uv, gu, gv);
    for (int k = 0; k < 3; k++) {
        float *v = o + VERTEX_FLOATS * k;
        memcpy(v, p[k], 3 * sizeof(float));
        v[3] = uv[k] ? uv[k][0] : -1.0f;
        v[4] = uv[k] ? uv[k][1] : -1.0f;
        for (int c = 0; c < 3; c++)
            v[5 + c] = draw_emission ? m->emissive[c] : 0.0f;
        lm_v3_store(v + 8, n);
        v[11] = m->double_sided ? 0.0f : m->split_sides ? 2.0f : 1.0f;
        v[12] = (float)surface;
        memcpy(v + 13, gu, sizeof gu);
        memcpy(v + 16, gv, sizeof gv);
        memcpy(v + 19, rect, 4 * sizeof(float));
    }
}

/* Where chart c's sub-samples stay (lm_chart_lookup_rect); -1s when c < 0. */
static void chart_rect(const lm_atlas *a, int c, float rect[4])
{
    if (c < 0)
        rect[0] = rect[1] = rect[2] = rect[3] = -1.0f;
    else
        lm_chart_lookup_rect(a, c, rect);
}

static void scene_triangle(const lm_gather *g, const lm_scene *s, const lm_atlas *a, uint32_t t, float *o)
{
    float p[3][3], rect[4];
    const float *uv[3];
    for (int k = 0; k < 3; k++) {
        lm_scene_vertex_world(s, s->tris[3 * (size_t)t + k], p[k]);
        uv[k] = a->corner_uv + 6 * (size_t)t + 2 * k;
        if (a->tri_chart[t] < 0 || !isfinite(uv[k][0]))
            uv[k] = NULL;
    }
    int c = a->tri_chart[t];
    chart_rect(a, uv[0] ? c : -1, rect);
    write_triangle(p, uv, &s->materials[s->tri_material[t]], c < 0 ? -1 : a->charts[c].surface, rect,
                   !g->emitters, o);
}

static void proxy_triangle(const lm_gather *g, const lm_scene *s, const lm_atlas *a, const lm_proxy *px, uint32_t t,
                           float *o)
{
    float p[3][3], rect[4];
    const float *uv[3];
    for (int k = 0; k < 3; k++) {
        uint32_t v = px->tris[3 * (size_t)t + k];
        lm_proxy_vertex_world(s, px, px->tri_node[t], v, p[k]);
        uv[k] = px->vertices[v].chart < 0 ? NULL : px->vertices[v].uv;
    }
    const lm_proxy_vertex *v0 = &px->vertices[px->tris[3 * (size_t)t]];
    chart_rect(a, v0->chart, rect);
    write_triangle(p, uv, &s->materials[v0->material], v0->chart < 0 ? -1 : a->charts[v0->chart].surface, rect,
                   !g->emitters, o);
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

uint64_t lm_gather_scene_uploads(const lm_gather *g) { return g->mesh_uploads; }

void lm_gather_set_emitter_light(lm_gather *g, const lm_emitter_light *el) { g->emitters = el; }

void lm_gather_set_tracer(lm_gather *g, const lm_rt *rt) { g->rt = rt; }

void lm_gather_set_direct_at_hits(lm_gather *g, const lm_direct_light *d)
{
    g->has_direct = d && (d->punctual != LM_DIRECT_NONE || d->area);
    if (!g->has_direct)
        return;
    g->direct = *d;
    g->direct.cover = 0.0f; /* a ray reached the point: it is not hidden */
}

int lm_gather_direct_at_hits(const lm_gather *g)
{
    return g->has_direct && g->set.direct_at_hits && g->set.scheme == LM_GATHER_RAYS;
}

static int traces_rim(const lm_gather *g)
{
    return g->rt && (g->set.rim_samples > 0 || g->set.scheme == LM_GATHER_RAYS);
}
/* The rim is traced and the AIM's copy it looks up exists (lm_gather_set_aim after the tracer). */
static int rim_ready(const lm_gather *g) { return traces_rim(g) && g->aim_copy; }

/* What the gather's mesh is made from (write_triangle): the scene and atlas, the proxy, whether emission is
 * drawn, the nodes' world matrices and the materials' emission and sides. */
static uint64_t scene_key(const lm_gather *g, const lm_scene *s, const lm_atlas *a)
{
    const void *from[2] = {s, a};
    const uint32_t counts[3] = {s->tri_count, g->has_proxy ? g->proxy.tri_count : 0, g->emitters != NULL};
    uint64_t h = lm_hash_bytes(LM_HASH_SEED, from, sizeof from);
    h = lm_hash_bytes(h, counts, sizeof counts);
    h ^= lm_scene_world_hash(s);
    for (int m = 0; m < s->material_count; m++) {
        const lm_material *x = &s->materials[m];
        const int sides[2] = {x->double_sided, x->split_sides};
        h = lm_hash_bytes(lm_hash_bytes(h, x->emissive, sizeof x->emissive), sides, sizeof sides);
    }
    return h;
}

lm_status lm_gather_set_scene(lm_gather *g, const lm_scene *s, const lm_atlas *a, lm_error *err)
{
    lm_status st = ensure_proxy(g, s, a, err);
    if (st != LM_OK)
        return st;
    /* made again only when something it is made from changed: every triangle is transformed and uploaded
     * (on the shared room, 4.6% of an 8 ms budget's run, with nothing moving) */
    uint64_t key = scene_key(g, s, a);
    if (g->has_mesh && g->mesh_key == key)
        return LM_OK;
    uint32_t count = g->has_proxy ? g->proxy.tri_count : s->tri_count;
    float *v = malloc(sizeof(float) * 3 * VERTEX_FLOATS * (size_t)(count ? count : 1));
    if (!v)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the gather geometry", s->path);
    for (uint32_t t = 0; t < count; t++) {
        if (g->has_proxy)
            proxy_triangle(g, s, a, &g->proxy, t, v + 3 * VERTEX_FLOATS * (size_t)t);
        else
            scene_triangle(g, s, a, t, v + 3 * VERTEX_FLOATS * (size_t)t);
    }
    if (g->has_mesh)
        lm_gl_mesh_destroy(&g->mesh);
    const int sizes[9] = {3, 2, 3, 3, 1, 1, 3, 3, 4};
    g->has_mesh = lm_gl_mesh_create_indexed(&g->mesh, v, (int)(3 * count), sizes, 9);
    g->mesh_key = key;
    g->mesh_uploads++;
    free(v);
    if (!g->has_mesh)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the gather geometry", s->path);
    return lm_gl_check("hemicube gather: scene upload", err);
}

lm_status lm_gather_set_aim_dilated(lm_gather *g, const lm_atlas *a, const float *dilated_rgba, lm_error *err)
{
    if (!g->aim_tex || g->aim_w != a->width || g->aim_h != a->height) {
        glDeleteTextures(1, &g->aim_tex);
        glGenTextures(1, &g->aim_tex);
        glBindTexture(GL_TEXTURE_2D, g->aim_tex);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, a->width, a->height);
        lm_texture_linear_clamped();
        g->aim_w = a->width, g->aim_h = a->height;
    }
    glBindTexture(GL_TEXTURE_2D, g->aim_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, a->width, a->height, GL_RGBA, GL_FLOAT, dilated_rgba);
    if (traces_rim(g)) { /* the caller may change its AIM while this gathers (the frame loop's overlap) */
        size_t bytes = sizeof(float) * 4 * (size_t)a->width * (size_t)a->height;
        float *copy = realloc(g->aim_copy, bytes);
        if (!copy)
            return lm_fail(err, LM_ERR_NOMEM, "hemicube gather: no memory for the AIM's copy");
        g->aim_copy = memcpy(copy, dilated_rgba, bytes);
    }
    return lm_gl_check("hemicube gather: AIM upload", err);
}

lm_status lm_gather_set_aim_whole(lm_gather *g, const lm_atlas *a, const float *dilated_rgba, lm_error *err)
{
    if (!dilated_rgba) {
        free(g->whole_copy);
        g->whole_copy = NULL;
        return LM_OK;
    }
    size_t bytes = sizeof(float) * 4 * (size_t)a->width * (size_t)a->height;
    float *copy = realloc(g->whole_copy, bytes);
    if (!copy)
        return lm_fail(err, LM_ERR_NOMEM, "ray gather: no memory for the whole AIM's copy");
    g->whole_copy = memcpy(copy, dilated_rgba, bytes);
    return LM_OK;
}

lm_status lm_gather_set_aim(lm_gather *g, const lm_atlas *a, const float *aim_rgb, lm_error *err)
{
    float *d = malloc(sizeof(float) * 4 * (size_t)a->width * (size_t)a->height);
    if (!d)
        return lm_fail(err, LM_ERR_NOMEM, "no memory to dilate the AIM");
    lm_atlas_dilated_rgba(a, aim_rgb, d); /* chart edges must not blend in black */
    lm_status st = lm_gather_set_aim_dilated(g, a, d, err);
    free(d);
    return st;
}

/* The texel's centre, shading normal and geometric normal (its triangle's, turned to the shading
 * normal's side) under the current node matrices (barycentric on its triangle). */
static void texel_frame(const lm_scene *s, const lm_texel *tx, lm_vec3 *pos, lm_vec3 *n, lm_vec3 *ng)
{
    float p[3], nn[3];
    lm_texel_world(s, tx, p, nn);
    *pos = lm_v3_load(p), *n = lm_v3_load(nn);
    lm_vec3 c[3];
    for (int k = 0; k < 3; k++) {
        float v[3];
        lm_scene_vertex_world(s, s->tris[3 * (size_t)tx->tri + k], v);
        c[k] = lm_v3_load(v);
    }
    lm_vec3 g = lm_cross(lm_sub(c[1], c[0]), lm_sub(c[2], c[0]));
    g = lm_length(g) > 0.0f ? lm_normalize(g) : *n;
    *ng = lm_dot(g, *n) < 0.0f ? lm_scale(g, -1.0f) : g;
}

/* The plane's axes scaled to clip space: b / a, t / a (x, y in [-w, w] on the plane) and n (w). */
static void plane_axes(lm_vec3 n, float a, lm_vec3 axes[3])
{
    lm_vec3 t, b;
    lm_tangents(n, &t, &b);
    axes[0] = lm_scale(b, 1.0f / a), axes[1] = lm_scale(t, 1.0f / a), axes[2] = n;
}

/* Reversed-depth projection (column-major): clip = (b.q / a, t.q / a, near, n.q) for q = p - e, so
 * depth = near / distance, no far plane. */
static void plane_view_proj(lm_vec3 e, const lm_vec3 axes[3], float near, float m[16])
{
    const int at[3] = {0, 1, 3};
    memset(m, 0, 16 * sizeof(float));
    for (int r = 0; r < 3; r++) {
        m[0 + at[r]] = axes[r].x, m[4 + at[r]] = axes[r].y, m[8 + at[r]] = axes[r].z;
        m[12 + at[r]] = -lm_dot(axes[r], e);
    }
    m[12 + 2] = near;
}

typedef struct {
    lm_vec3 eye, axes[3];
    lm_vec3 ng; /* geometric normal: directions below its plane are blocked by the texel's own surface */
    float surface;
} texel_view;

float lm_gather_lift(const lm_hemicube_settings *set, const lm_scene *s, const lm_atlas *a)
{
    /* at most a share of a texel: a level's size is its open ground's, and 1e-4 of truck-town's 2.9 km lifted
     * a house wall's eyes 29 cm off it, its foot's row 7-29% bright (docs/gather.md, "Eye lift") */
    return fminf(set->offset * lm_scene_size(s), LM_GATHER_TEXEL_LIFT * a->texel_size);
}

/* The view of texel tx, its eye lifted `lift` (lm_gather_lift) off it. */
static texel_view view_of(const lm_hemicube_settings *set, const lm_scene *s, float lift, const lm_texel *tx)
{
    lm_vec3 p, n;
    texel_view v;
    texel_frame(s, tx, &p, &n, &v.ng);
    v.eye = lm_add(p, lm_scale(n, lift));
    plane_axes(n, set->enlargement, v.axes);
    v.surface = (float)tx->surface;
    return v;
}

/* The eye, normal and geometric normal of the view of tx (a texel or one of its footprint points). */
static void point_frame(const lm_hemicube_settings *set, const lm_scene *s, const lm_atlas *a, const lm_texel *tx,
                        float eye[3], float n[3], float ng[3])
{
    texel_view v = view_of(set, s, lm_gather_lift(set, s, a), tx);
    lm_v3_store(eye, v.eye);
    lm_v3_store(n, v.axes[2]);
    lm_v3_store(ng, v.ng);
}

void lm_gather_texel_frame(const lm_hemicube_settings *set, const lm_scene *s, const lm_atlas *a, uint32_t texel,
                           float eye[3], float n[3], float ng[3])
{
    point_frame(set, s, a, &a->texels[texel], eye, n, ng);
}

/* Whether the texel is covered (lm_texel_covered): straight out from its centre along the shading normal
 * there (lm_texel_centre_normal, not the mean its view faces), from the view's eye offset, other geometry
 * within a texel's width, or the inside of a solid (the back of a triangle by its winding: the texel is
 * inside a closed mesh, such as the floor under a box that stands on it). tx: a texel or one of its
 * footprint points. */
static int covered_point(const lm_rt *rt, const lm_hemicube_settings *set, const lm_scene *s, const lm_atlas *a,
                         const lm_texel *tx)
{
    float p[3], n[3], eye[3];
    lm_texel_centre_normal(s, tx, p, n);
    lm_v3_store(eye, lm_add(lm_v3_load(p), lm_scale(lm_v3_load(n), lm_gather_lift(set, s, a))));
    lm_rt_hit h;
    if (!lm_rt_intersect(rt, eye, n, 0.0f, INFINITY, &h))
        return 0;
    /* the texel's own width: a wall given finer texels than the atlas's (wall_texels) is not covered by
     * a slope metres in front of it */
    return h.t <= a->surface_texel_size[tx->surface] || lm_dot(lm_v3_load(h.ng), lm_v3_load(n)) > 0.0f;
}

static int covered_at(const lm_rt *rt, const lm_hemicube_settings *set, const lm_scene *s, const lm_atlas *a,
                      uint32_t texel)
{
    return covered_point(rt, set, s, a, &a->texels[texel]);
}

int lm_texel_covered(const lm_rt *rt, const lm_scene *s, const lm_atlas *a, const lm_hemicube_settings *set,
                     uint32_t texel)
{
    return covered_at(rt, set, s, a, texel);
}

/* Texel t's footprint points that are not covered (covered_point; all of them without a tracer), into
 * out; how many. 0 where it has none, or all are covered: then it is gathered at its own point, and
 * covered_at says whether that is covered. With n > 0 its light is the mean of the n points'. */
static int gather_points(const lm_gather *g, const lm_scene *s, const lm_atlas *a, uint32_t t,
                         const lm_texel *out[LM_FOOTPRINT_POINTS])
{
    const lm_texel *pts;
    uint32_t m = lm_texel_footprint(a, t, &pts);
    int n = 0;
    for (uint32_t k = 0; k < m && n < LM_FOOTPRINT_POINTS; k++)
        if (!g->rt || !covered_point(g->rt, &g->set, s, a, &pts[k]))
            out[n++] = &pts[k];
    return n;
}

void lm_gather_emitted_at(const lm_gather *g, const lm_scene *s, const lm_atlas *a, uint32_t texel, float e[3])
{
    e[0] = e[1] = e[2] = 0.0f;
    if (!g->emitters)
        return;
    const lm_texel *pts[LM_FOOTPRINT_POINTS];
    int m = gather_points(g, s, a, texel, pts);
    if (m == 0) /* gathered at its own point, else over its footprint's open points: their mean, as gathered */
        pts[0] = &a->texels[texel], m = 1;
    for (int k = 0; k < m; k++) {
        float eye[3], n[3], ng[3], ek[3]; /* the view fill_views gives the point */
        point_frame(&g->set, s, a, pts[k], eye, n, ng);
        lm_emitter_irradiance(g->emitters, eye, n, ng, lm_gather_texel_seed(&g->set, texel), ek);
        for (int c = 0; c < 3; c++)
            e[c] += ek[c] / (float)m;
    }
}

/* Whether texel t is covered: only where it is gathered at its own point (gather_points found none open). */
static int covered_in_round(const lm_gather *g, const lm_scene *s, const lm_atlas *a, uint32_t t)
{
    const lm_texel *pts[LM_FOOTPRINT_POINTS];
    return g->rt && gather_points(g, s, a, t, pts) == 0 && covered_at(g->rt, &g->set, s, a, t);
}

static float near_plane(const lm_gather *g)
{
    float near = 0.5f * g->lift;
    return near > 0.0f ? near : 1e-6f;
}

void lm_gather_set_turn(lm_gather *g, const unsigned tex[3])
{
    for (int c = 0; c < 3; c++)
        g->turn_tex[c] = tex ? tex[c] : 0;
}

void lm_gather_set_sky(lm_gather *g, const float sky[3])
{
    memcpy(g->set.sky, sky, sizeof g->set.sky);
}

/* Whether a pass's tiles [0, count) are mostly empty (an update's few texels, spread over the target by
 * their fixed tiles): then they are cleared and resolved one by one instead of as whole rows. */
static int sparse_pass(const lm_gather *g, const uint32_t *texels, uint32_t count)
{
    uint32_t used = 0, T = (uint32_t)g->set.tiles, rows = (count + T - 1) / T;
    for (uint32_t i = 0; i < count; i++)
        used += texels[i] != LM_GATHER_NO_TEXEL;
    return 2 * used < rows * T;
}

/* Clears the tiles of the pass's texels (the rows or layers [0, count) that hold them, or each used
 * tile of a sparse pass): sky radiance, depth 0 (reversed). */
static void clear_target(lm_gather *g, const uint32_t *texels, uint32_t count, int sparse)
{
    int R = g->set.resolution, T = g->set.tiles;
    const float sky[4] = {g->set.sky[0], g->set.sky[1], g->set.sky[2], 0.0f}, zero = 0.0f;
    if (g->set.scheme == LM_GATHER_LAYERED) { /* layers [0, count), or each used one */
        for (uint32_t i = 0; i < (sparse ? count : 1); i++) {
            GLsizei n = sparse ? 1 : (GLsizei)count;
            if (sparse && texels[i] == LM_GATHER_NO_TEXEL)
                continue;
            glClearTexSubImage(g->color, 0, 0, 0, (GLint)i, R, R, n, GL_RGBA, GL_FLOAT, sky);
            glClearTexSubImage(g->depth, 0, 0, 0, (GLint)i, R, R, n, GL_DEPTH_COMPONENT, GL_FLOAT, &zero);
        }
        return;
    }
    glEnable(GL_SCISSOR_TEST);
    glClearColor(sky[0], sky[1], sky[2], 0.0f);
    glClearDepth(0.0);
    if (!sparse) {
        glScissor(0, 0, T * R, (int)((count + (uint32_t)T - 1) / (uint32_t)T) * R);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    }
    for (uint32_t i = 0; sparse && i < count; i++) {
        if (texels[i] == LM_GATHER_NO_TEXEL)
            continue;
        glScissor((int)(i % (uint32_t)T) * R, (int)(i / (uint32_t)T) * R, R, R);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    }
    glDisable(GL_SCISSOR_TEST);
}

/* View v as VIEW_FLOATS floats at o. */
static void store_view(texel_view v, float *o)
{
    lm_v3_store(o, v.eye);
    o[3] = v.surface;
    for (int k = 0; k < 3; k++) {
        lm_v3_store(o + 4 * (k + 1), v.axes[k]);
        o[4 * (k + 1) + 3] = k == 0 ? v.ng.x : k == 1 ? v.ng.y : v.ng.z;
    }
}

/* Every texel's view of a pass into g->views (VIEW_FLOATS each: eye and own surface, then the three
 * axes, whose fourth components hold the geometric normal), which every scheme draws from and the
 * emitter light and the rim read. An empty tile (LM_GATHER_NO_TEXEL) gets a zero view: every vertex
 * lands on one point with w = 0 in front of the near plane, so the instanced schemes draw nothing there. */
static void fill_views(lm_gather *g, const lm_scene *s, const lm_atlas *a, const uint32_t *texels, uint32_t count)
{
    g->lift = lm_gather_lift(&g->set, s, a);
    for (uint32_t i = 0; i < count; i++) {
        float *o = g->views + VIEW_FLOATS * (size_t)i;
        if (texels[i] == LM_GATHER_NO_TEXEL) {
            memset(o, 0, sizeof(float) * VIEW_FLOATS);
            continue;
        }
        const lm_texel *pts[LM_FOOTPRINT_POINTS];
        int n = gather_points(g, s, a, texels[i], pts);
        store_view(view_of(&g->set, s, g->lift, n > g->round ? pts[g->round] : &a->texels[texels[i]]), o);
    }
}

/* Scheme 0: one draw per texel, its view in uniforms, its tile a viewport; empty tiles are skipped. */
static void draw_viewports(lm_gather *g, const uint32_t *texels, uint32_t count)
{
    int R = g->set.resolution, T = g->set.tiles;
    GLint vp_loc = glGetUniformLocation(g->render_prog, "view_proj"), eye_loc = glGetUniformLocation(g->render_prog, "eye");
    GLint own_loc = glGetUniformLocation(g->render_prog, "own_surface");
    GLint ax_loc = glGetUniformLocation(g->render_prog, "axis_x"), ay_loc = glGetUniformLocation(g->render_prog, "axis_y");
    GLint ng_loc = glGetUniformLocation(g->render_prog, "geo_n");
    float near = near_plane(g);
    for (uint32_t i = 0; i < count; i++) {
        if (texels[i] == LM_GATHER_NO_TEXEL)
            continue;
        const float *o = g->views + VIEW_FLOATS * (size_t)i;
        lm_vec3 eye = lm_v3_load(o), axes[3] = {lm_v3_load(o + 4), lm_v3_load(o + 8), lm_v3_load(o + 12)};
        float m[16];
        plane_view_proj(eye, axes, near, m);
        glUniformMatrix4fv(vp_loc, 1, GL_FALSE, m);
        glUniform3f(eye_loc, eye.x, eye.y, eye.z);
        glUniform1f(own_loc, o[3]);
        glUniform3f(ng_loc, o[7], o[11], o[15]);
        for (int k = 0; k < 2; k++) { /* a b and a t: a clip-space step as a world direction per unit w */
            lm_vec3 ax = lm_scale(axes[k], 1.0f / lm_dot(axes[k], axes[k]));
            glUniform3f(k ? ay_loc : ax_loc, ax.x, ax.y, ax.z);
        }
        glViewport((int)(i % (uint32_t)T) * R, (int)(i / (uint32_t)T) * R, R, R);
        lm_gl_mesh_draw(&g->mesh);
    }
}

/* Schemes 1, 2: the views into a buffer, then one instanced draw. */
static void draw_instanced(lm_gather *g, uint32_t count)
{
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->views_buf);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(sizeof(float) * VIEW_FLOATS * count), g->views);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, g->views_buf);
    glUniform1i(glGetUniformLocation(g->render_prog, "tiles"), g->set.tiles);
    glUniform1f(glGetUniformLocation(g->render_prog, "near"), near_plane(g));
    int R = g->set.resolution, side = g->set.scheme == LM_GATHER_LAYERED ? R : g->set.tiles * R;
    glViewport(0, 0, side, side);
    int clip = g->set.scheme == LM_GATHER_INSTANCED;
    for (int k = 0; clip && k < 4; k++)
        glEnable(GL_CLIP_DISTANCE0 + k);
    lm_gl_mesh_draw_instanced(&g->mesh, (int)count);
    for (int k = 0; clip && k < 4; k++)
        glDisable(GL_CLIP_DISTANCE0 + k);
}

/* The multisampled target's rows in use (or a sparse pass's used tiles), averaged into the
 * single-sampled one the reduction reads. */
static void resolve(const lm_gather *g, const uint32_t *texels, uint32_t count, int sparse)
{
    int R = g->set.resolution, T = g->set.tiles, rows = (int)((count + (uint32_t)T - 1) / (uint32_t)T);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, g->ms_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, g->fbo);
    if (!sparse)
        glBlitFramebuffer(0, 0, T * R, rows * R, 0, 0, T * R, rows * R, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    for (uint32_t i = 0; sparse && i < count; i++) {
        int x = (int)(i % (uint32_t)T) * R, y = (int)(i / (uint32_t)T) * R;
        if (texels[i] != LM_GATHER_NO_TEXEL)
            glBlitFramebuffer(x, y, x + R, y + R, x, y, x + R, y + R, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }
}

static void render_tiles(lm_gather *g, const lm_scene *s, const lm_atlas *a, const uint32_t *texels, uint32_t count,
                         int *xy)
{
    glBindFramebuffer(GL_FRAMEBUFFER, g->ms_fbo ? g->ms_fbo : g->fbo);
    int sparse = sparse_pass(g, texels, count);
    clear_target(g, texels, count, sparse);
    glUseProgram(g->render_prog);
    glUniform1i(glGetUniformLocation(g->render_prog, "aim"), 0);
    glUniform1f(glGetUniformLocation(g->render_prog, "pixel"), 2.0f / (float)g->set.resolution);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g->aim_tex);
    fill_views(g, s, a, texels, count);
    if (g->set.scheme == LM_GATHER_VIEWPORTS)
        draw_viewports(g, texels, count);
    else
        draw_instanced(g, count);
    for (uint32_t i = 0; i < count; i++) { /* an empty tile's target (-1, -1) is skipped by the reduction */
        int empty = texels[i] == LM_GATHER_NO_TEXEL;
        xy[2 * i] = empty ? -1 : a->texels[texels[i]].x, xy[2 * i + 1] = empty ? -1 : a->texels[texels[i]].y;
    }
    if (g->ms_fbo)
        resolve(g, texels, count, sparse);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

/* What each texel of a pass gets from the CPU, for the reduction to add: the emitters' closed-form
 * irradiance and the rim's (from its view's eye and axes: g->views, filled by render_tiles); the sample
 * patterns are seeded by the texel's index (lm_gather_texel_seed), so the thread count changes nothing.
 * While the GL rasterizes the pass: on llvmpipe on this thread alone (about 8 us per texel for two
 * emissive triangles and 10 us for the rim, where an OpenMP team competing with the rasterizer's threads
 * cost ten times that); on a GPU on every core, where the rim was 99% of a bake (docs/architecture.md,
 * "On a GPU"). */
static void cpu_irradiance(lm_gather *g, const lm_scene *s, const lm_atlas *a, const uint32_t *texels,
                           uint32_t count)
{
    lm_rim rim = {s, a, g->rt, g->aim_copy, !g->emitters, {g->set.sky[0], g->set.sky[1], g->set.sky[2]},
                  g->set.enlargement, g->set.rim_samples, NULL, NULL, NULL, 0.0f, 0.0f, 0};
#pragma omp parallel num_threads(g->cpu_threads) if (g->cpu_threads > 1)
    {
        lm_rt_thread_init(); /* FTZ/DAZ as on this thread: the same numbers on any thread */
#pragma omp for schedule(dynamic, 8)
        for (long i = 0; i < (long)count; i++) {
            const float *o = g->views + VIEW_FLOATS * (size_t)i;
            float *e = g->emit + 4 * (size_t)i;
            e[0] = e[1] = e[2] = e[3] = 0.0f;
            if (texels[i] == LM_GATHER_NO_TEXEL)
                continue;
            float ng[3] = {o[7], o[11], o[15]}; /* the view's geometric normal */
            if (g->emitters)
                lm_emitter_irradiance(g->emitters, o, o + 12, ng, lm_gather_texel_seed(&g->set, texels[i]), e);
            if (covered_in_round(g, s, a, texels[i]))
                e[3] = 1.0f; /* counted as all back faces: invalid, never shown */
            if (rim_ready(g)) {
                float b[3], t[3], r[3];
                for (int k = 0; k < 3; k++) /* the views hold b / a and t / a */
                    b[k] = o[4 + k] * g->set.enlargement, t[k] = o[8 + k] * g->set.enlargement;
                lm_rim_irradiance(&rim, o, b, t, o + 12, ng, lm_gather_texel_seed(&g->set, texels[i]), r, NULL);
                for (int k = 0; k < 3; k++)
                    e[k] += r[k];
            }
        }
    }
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->emit_buf);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(sizeof(float) * 4 * count), g->emit);
}

/* Sums each tile of the pass into its texel of iim_tex, keeping `keep` of what the texel held (0: a new value). */
static void reduce_tiles(lm_gather *g, unsigned iim_tex, const int *xy, uint32_t count, float keep)
{
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->targets_buf);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(sizeof(int) * 2 * count), xy);
    glUseProgram(g->reduce_prog);
    glUniform1i(glGetUniformLocation(g->reduce_prog, "R"), g->set.resolution);
    glUniform1i(glGetUniformLocation(g->reduce_prog, "tiles_x"), g->set.tiles);
    /* with the rim traced the plane's sum is not extrapolated to the whole hemisphere */
    double scale = rim_ready(g) ? 1.0 : 1.0 / g->coverage;
    glUniform1f(glGetUniformLocation(g->reduce_prog, "scale"), (float)(LM_PI * scale));
    glUniform1f(glGetUniformLocation(g->reduce_prog, "inv_f"), (float)(1.0 / g->coverage));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(g->set.scheme == LM_GATHER_LAYERED ? GL_TEXTURE_2D_ARRAY : GL_TEXTURE_2D, g->color);
    glBindImageTexture(0, iim_tex, 0, GL_FALSE, 0, keep > 0.0f ? GL_READ_WRITE : GL_WRITE_ONLY, GL_RGBA32F);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, g->weights_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, g->targets_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, g->emit_buf);
    glUniform1i(glGetUniformLocation(g->reduce_prog, "count"), (GLint)count);
    glUniform1f(glGetUniformLocation(g->reduce_prog, "keep"), keep);
    glDispatchCompute((count + 7) / 8, 1, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

/* The rays' irradiance from view o (VIEW_FLOATS) of texel t into e, the back-face share into e[3]. */
static void ray_view(const lm_gather *g, const lm_rim *rim, const float *o, uint32_t t, float e[4])
{
    float b[3], tv[3], r[3], back = 0.0f, ng[3] = {o[7], o[11], o[15]};
    e[0] = e[1] = e[2] = e[3] = 0.0f;
    if (g->emitters)
        lm_emitter_irradiance(g->emitters, o, o + 12, ng, lm_gather_texel_seed(&g->set, t), e);
    for (int k = 0; k < 3; k++) /* the views hold b / a and t / a */
        b[k] = o[4 + k] * g->set.enlargement, tv[k] = o[8 + k] * g->set.enlargement;
    lm_rim_irradiance(rim, o, b, tv, o + 12, ng, lm_gather_texel_seed(&g->set, t), r, &back);
    for (int k = 0; k < 3; k++)
        e[k] += r[k];
    e[3] = back;
}

/* The turn of a texel gathered at m points (0: at its own point, no turn) of normals n and light e. */
static void turn_of(int m, const float n[][3], const float e[][4], float out[LM_TURN_FLOATS])
{
    float rgb[LM_FOOTPRINT_POINTS][3];
    for (int k = 0; k < m; k++)
        memcpy(rgb[k], e[k], sizeof rgb[k]);
    lm_footprint_turn(m, n, rgb, out);
}

/* The turns (LM_TURN_FLOATS a texel, in the order of texels) of the turning texels among texels into the
 * turn maps; every other texel's stays 0. */
static void write_turns(const lm_gather *g, const lm_atlas *a, const uint32_t *texels, uint32_t n, const float *turn)
{
    for (int c = 0; c < 3; c++) {
        glBindTexture(GL_TEXTURE_2D, g->turn_tex[c]);
        for (uint32_t i = 0; i < n; i++) {
            const lm_texel *tx = &a->texels[texels[i]];
            if (lm_texel_turns(a, texels[i]))
                glTexSubImage2D(GL_TEXTURE_2D, 0, tx->x, tx->y, 1, 1, GL_RGBA, GL_FLOAT,
                                turn + LM_TURN_FLOATS * (size_t)i + 4 * c);
        }
    }
}

/* LM_GATHER_RAYS: each texel's whole hemisphere by rays, in parallel (what the hemicube and its rim
 * together see: the AIM where a ray meets a surface, the back of a single-sided one black and counted
 * into the back-face share, the sky where nothing is met, the emitters in closed form or as met), a pass
 * of tiles^2 texels at a time, each written into the IIM texture at its texel. */
static lm_status gather_rays(lm_gather *g, const lm_scene *s, const lm_atlas *a, const uint32_t *texels,
                             uint32_t count, unsigned iim_tex, lm_error *err)
{
    if (!rim_ready(g))
        return lm_fail(err, LM_ERR_INVALID, "ray gather: it needs the scene's tracer (lm_gather_set_tracer)");
    /* far hits read the whole AIM only where emissive triangles' shadow rays are to be saved: with punctual
     * lights alone a hit costs one shadow ray a light, and the town's sunlit ground read from its texels
     * left the retaining wall darker (docs/gather.md, "Near and far hits") */
    int at_hits = lm_gather_direct_at_hits(g),
        near_only = at_hits && g->direct.area && g->whole_copy && g->set.direct_near > 0.0f;
    lm_rim rim = {s, a, g->rt, g->aim_copy, !g->emitters, {g->set.sky[0], g->set.sky[1], g->set.sky[2]}, 0.0f,
                  g->set.ray_samples, NULL, at_hits ? &g->direct : NULL, near_only ? g->whole_copy : NULL,
                  g->set.direct_near, g->set.adapt, 0};
    uint32_t per_pass = (uint32_t)(g->set.tiles * g->set.tiles);
    if (g->turn_tex[0] && !g->turn && !(g->turn = malloc(sizeof(float) * LM_TURN_FLOATS * per_pass)))
        return lm_fail(err, LM_ERR_NOMEM, "ray gather: no memory");
    float *turn = g->turn_tex[0] ? g->turn : NULL;
    glBindTexture(GL_TEXTURE_2D, iim_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    for (uint32_t first = 0; first < count; first += per_pass) {
        uint32_t n = count - first < per_pass ? count - first : per_pass;
        fill_views(g, s, a, texels + first, n);
#pragma omp parallel
        {
            lm_rt_thread_init();
#pragma omp for schedule(dynamic, 4)
            for (long i = 0; i < (long)n; i++) {
                uint32_t t = texels[first + (uint32_t)i];
                float *e = g->emit + 4 * (size_t)i;
                const lm_texel *pts[LM_FOOTPRINT_POINTS];
                int m = gather_points(g, s, a, t, pts);
                float nk[LM_FOOTPRINT_POINTS][3], ek[LM_FOOTPRINT_POINTS][4];
                if (m == 0) {
                    ray_view(g, &rim, g->views + VIEW_FLOATS * (size_t)i, t, e);
                    e[3] = covered_at(g->rt, &g->set, s, a, t) ? 1.0f : e[3];
                } else { /* a piece's footprint: the strata shared among its open points, their light averaged */
                    lm_rim part = rim;
                    part.samples = rim.samples / m > 1 ? rim.samples / m : 1;
                    e[0] = e[1] = e[2] = e[3] = 0.0f;
                    for (int k = 0; k < m; k++) {
                        float o[VIEW_FLOATS];
                        store_view(view_of(&g->set, s, g->lift, pts[k]), o);
                        memcpy(nk[k], o + 12, sizeof nk[k]); /* the view's third axis: the point's normal */
                        ray_view(g, &part, o, t, ek[k]);
                        for (int c = 0; c < 4; c++)
                            e[c] += ek[k][c] / (float)m;
                    }
                }
                if (turn && lm_texel_turns(a, t))
                    turn_of(m, nk, ek, turn + LM_TURN_FLOATS * (size_t)i);
            }
        }
        for (uint32_t i = 0; i < n; i++) {
            const lm_texel *tx = &a->texels[texels[first + i]];
            glTexSubImage2D(GL_TEXTURE_2D, 0, tx->x, tx->y, 1, 1, GL_RGBA, GL_FLOAT, g->emit + 4 * (size_t)i);
        }
        if (turn)
            write_turns(g, a, texels + first, n, turn);
        glBindTexture(GL_TEXTURE_2D, iim_tex);
    }
    return lm_gl_check("ray gather", err);
}

/* The turning texels of a hemicube gather, for their turns: the IIM's running mean of each after each
 * round r, read back (the light of its point r is then (r + 1) mean_r - r mean_(r-1)). */
typedef struct {
    uint32_t count, *texel;
    float (*mean)[LM_FOOTPRINT_POINTS][4];
} round_means;

static lm_status round_means_init(round_means *rm, const lm_atlas *a, const uint32_t *texels, uint32_t count,
                                  lm_error *err)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < count; i++)
        n += lm_texel_turns(a, texels[i]);
    if (n == 0)
        return LM_OK;
    rm->texel = malloc(sizeof *rm->texel * n);
    rm->mean = calloc(n, sizeof *rm->mean);
    if (!rm->texel || !rm->mean) {
        free(rm->texel), free(rm->mean);
        rm->texel = NULL, rm->mean = NULL;
        return lm_fail(err, LM_ERR_NOMEM, "hemicube gather: no memory for %u turning texels", n);
    }
    for (uint32_t i = 0; i < count; i++)
        if (lm_texel_turns(a, texels[i]))
            rm->texel[rm->count++] = texels[i];
    return LM_OK;
}

static void round_means_free(round_means *rm)
{
    free(rm->texel);
    free(rm->mean);
}

/* Each turning texel's value after round r (the texels gathered in it, and the others: their value
 * stays, and is not used). One read a texel: turning texels are few (a level's curved pieces). */
static void read_round(round_means *rm, unsigned iim_tex, const lm_atlas *a, int r)
{
    for (uint32_t i = 0; i < rm->count; i++) {
        const lm_texel *tx = &a->texels[rm->texel[i]];
        glGetTextureSubImage(iim_tex, 0, tx->x, tx->y, 0, 1, 1, 1, GL_RGBA, GL_FLOAT, sizeof rm->mean[i][r],
                             rm->mean[i][r]);
    }
}

/* The turning texels' turns from their rounds' running means, into the turn maps. */
static void round_turns(lm_gather *g, const lm_scene *s, const lm_atlas *a, const round_means *rm)
{
    float *turn = malloc(sizeof(float) * LM_TURN_FLOATS * rm->count);
    if (!turn) /* the turns stay as they were: the texels' means are right, only their turn is old */
        return;
    for (uint32_t i = 0; i < rm->count; i++) {
        const lm_texel *pts[LM_FOOTPRINT_POINTS];
        float n[LM_FOOTPRINT_POINTS][3], e[LM_FOOTPRINT_POINTS][4], eye[3], ng[3];
        int m = gather_points(g, s, a, rm->texel[i], pts);
        for (int k = 0; k < m; k++) {
            point_frame(&g->set, s, a, pts[k], eye, n[k], ng);
            for (int c = 0; c < 4; c++)
                e[k][c] = (float)(k + 1) * rm->mean[i][k][c] - (k > 0 ? (float)k * rm->mean[i][k - 1][c] : 0.0f);
        }
        turn_of(m, n, e, turn + LM_TURN_FLOATS * (size_t)i);
    }
    write_turns(g, a, rm->texel, rm->count, turn);
    free(turn);
}

/* The hemicube passes of rest[0, left) (which they use up), each texel at its point of round g->round;
 * a round past the first blends its light into the texel's mean so far (round / (round + 1) of it kept).
 * Returns how many passes. */
static int hemicube_passes(lm_gather *g, const lm_scene *s, const lm_atlas *a, uint32_t *rest, uint32_t left,
                           uint32_t *slots, int *xy, unsigned iim_tex)
{
    uint32_t per_pass = (uint32_t)(g->set.tiles * g->set.tiles);
    int passes = 0;
    for (; left > 0; passes++) {
        uint32_t n;
        left = lm_gather_place_pass(rest, left, slots, per_pass, &n); /* each texel in its own tile */
        render_tiles(g, s, a, slots, n, xy);
        if (g->emitters || g->rt) {
            glFlush(); /* llvmpipe rasterizes the pass on its threads while this one computes */
            cpu_irradiance(g, s, a, slots, n);
        }
        reduce_tiles(g, iim_tex, xy, n, (float)g->round / (float)(g->round + 1));
    }
    return passes;
}

lm_status lm_gather_texels(lm_gather *g, const lm_scene *s, const lm_atlas *a, const uint32_t *texels,
                           uint32_t count, unsigned iim_tex, lm_gather_stats *stats, lm_error *err)
{
    if (!g->has_mesh || !g->aim_tex)
        return lm_fail(err, LM_ERR_INVALID, "hemicube gather: set the scene and the AIM first");
    if (g->set.scheme == LM_GATHER_RAYS) {
        double t0 = lm_now();
        lm_status st = gather_rays(g, s, a, texels, count, iim_tex, err);
        if (stats) {
            glFinish();
            stats->texels = count, stats->passes = (int)((count + (uint32_t)(g->set.tiles * g->set.tiles) - 1) /
                                                         (uint32_t)(g->set.tiles * g->set.tiles));
            stats->seconds = lm_now() - t0;
        }
        return st;
    }
    double t0 = lm_now();
    uint32_t per_pass = (uint32_t)(g->set.tiles * g->set.tiles);
    int *xy = malloc(sizeof(int) * 2 * per_pass);
    uint32_t *slots = malloc(sizeof *slots * per_pass), *rest = malloc(sizeof *rest * (count ? count : 1));
    PFNGLCLIPCONTROLPROC clip_control = (PFNGLCLIPCONTROLPROC)lm_gl_get_proc("glClipControl");
    if (!xy || !slots || !rest || !clip_control) {
        free(xy);
        free(slots);
        free(rest);
        return clip_control ? lm_fail(err, LM_ERR_NOMEM, "hemicube gather: no memory")
                            : lm_fail(err, LM_ERR_BACKEND, "hemicube gather: glClipControl (GL 4.5) is missing");
    }
    if (count)
        memcpy(rest, texels, sizeof *rest * count);
    clip_control(GL_LOWER_LEFT, GL_ZERO_TO_ONE); /* reversed float depth */
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDisable(GL_CULL_FACE);
    round_means rm = {0};
    lm_status st = g->turn_tex[0] ? round_means_init(&rm, a, texels, count, err) : LM_OK;
    int passes = st == LM_OK ? hemicube_passes(g, s, a, rest, count, slots, xy, iim_tex) : 0;
    read_round(&rm, iim_tex, a, 0);
    /* a piece's footprint (gather_points): a round more for each open point past the first, each blended
     * into the mean of those before it */
    for (g->round = 1; st == LM_OK && g->round < LM_FOOTPRINT_POINTS; g->round++) {
        const lm_texel *first, *pts[LM_FOOTPRINT_POINTS];
        uint32_t left = 0;
        for (uint32_t i = 0; i < count; i++)
            if (lm_texel_footprint(a, texels[i], &first) > (uint32_t)g->round &&
                gather_points(g, s, a, texels[i], pts) > g->round)
                rest[left++] = texels[i];
        passes += hemicube_passes(g, s, a, rest, left, slots, xy, iim_tex);
        read_round(&rm, iim_tex, a, g->round);
    }
    g->round = 0;
    if (rm.count)
        round_turns(g, s, a, &rm);
    round_means_free(&rm);
    clip_control(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    glDepthFunc(GL_LESS);
    glClearDepth(1.0);
    free(xy);
    free(slots);
    free(rest);
    if (stats) { /* timed to the end of the GPU work; otherwise the caller's next commands queue behind it */
        glFinish();
        stats->texels = count;
        stats->passes = passes;
        stats->seconds = lm_now() - t0;
    }
    return st != LM_OK ? st : lm_gl_check("hemicube gather (hemicube_render, hemicube_reduce)", err);
}
