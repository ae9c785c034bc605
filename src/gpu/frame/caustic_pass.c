/* The screen-space caustic pass: splat, tile queries, cone filter, composite (caustic_pass.h); the
 * shaders are glsl/caustic_*.glsl. */
#include "caustic_pass.h"

#include "../gl/gl_api.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../core/timing.h"
#include "../../core/vecmath.h"
#include "../gl/gl_shader.h"
#include "glsl.h"

void lm_caustic_pass_settings_default(lm_caustic_pass_settings *s)
{
    s->filter_k = 2;
    s->tile = 32;
    s->world_space = 0;
    s->filter_photons = 32;
    s->widen_levels = LM_CAUSTIC_FILTER_LEVELS;
    s->merge = 1;
}

/* A point as the splat reads it: position, receiver normal (arrival side), flux, the photons it stands for. */
#define POINT_FLOATS 10

/* One slot's targets: the splat (two RGBA32F + depth-stencil), the irradiance, the tiles' flags. */
typedef struct {
    int width, height;
    GLuint splat_fbo, splat_tex[2], stencil;
    GLuint irr_fbo, irr_tex;
    int tiles_x, tiles_y;
    uint8_t *lit;
    GLuint *queries;
    int lit_count, box[4];  /* the last run's lit tiles and the box of their grown squares */
    /* where the splat and the irradiance may hold anything but 0 (x0, y0, x1, y1): what the next run
     * clears, the last run's lit tiles (the whole target when new) */
    int splat_held[4], irr_held[4];
    /* the pixel rectangles (x0, y0, x1, y1) the filter may read this run, aligned to its coarsest mip
     * level's texels: where the receiver mask and the mipmaps are made (needed_rects) */
    int *read_rects, read_count;
} slot_targets;

/* The pixel box of the lit tiles (clamped to the target); empty (x1 <= x0) when none. */
static void lit_box(const slot_targets *t, int tile, int box[4])
{
    box[0] = t->width, box[1] = t->height, box[2] = box[3] = 0;
    for (int ty = 0; ty < t->tiles_y; ty++)
        for (int tx = 0; tx < t->tiles_x; tx++)
            if (t->lit[ty * t->tiles_x + tx]) {
                int x0 = tx * tile, y0 = ty * tile, x1 = (tx + 1) * tile, y1 = (ty + 1) * tile;
                box[0] = x0 < box[0] ? x0 : box[0], box[1] = y0 < box[1] ? y0 : box[1];
                box[2] = x1 > box[2] ? x1 : box[2], box[3] = y1 > box[3] ? y1 : box[3];
            }
    box[2] = box[2] > t->width ? t->width : box[2], box[3] = box[3] > t->height ? t->height : box[3];
}

/* Clears the bound framebuffer's colour attachments [0, colours) (and its stencil) inside box only: a pass
 * clears what its last run wrote, not the whole screen. */
static void clear_box(const int box[4], int colours, int stencil)
{
    if (box[2] <= box[0] || box[3] <= box[1])
        return;
    static const float zero[4] = {0, 0, 0, 0};
    static const GLint zero_stencil = 0;
    glEnable(GL_SCISSOR_TEST);
    glScissor(box[0], box[1], box[2] - box[0], box[3] - box[1]);
    for (int i = 0; i < colours; i++)
        glClearBufferfv(GL_COLOR, i, zero);
    if (stencil) {
        glStencilMask(0xFF);
        glClearBufferiv(GL_STENCIL, 0, &zero_stencil);
    }
    glDisable(GL_SCISSOR_TEST);
}

struct lm_caustic_pass {
    lm_caustic_pass_settings set;
    GLuint splat_prog, query_prog, filter_prog, composite_prog, mask_prog, mip_prog;
    GLuint vao, point_vbo, empty_vao, rect_vbo, mip_fbo;
    uint32_t photons;
    lm_caustic_hit *hits;   /* the landed photons, for each run's frustum test and points */
    /* scratch, sized for every photon: a run's photons in its view frustum (indices into hits) and the
     * pixel each projects into; its points (POINT_FLOATS each), their position sums and first photons;
     * the open-addressing table of points by key (table_size entries, -1 empty) */
    uint32_t *visible, *pixel, *first;
    float *points;
    double *sum;
    int32_t *table;
    uint32_t table_size;
    slot_targets slots[LM_CAUSTIC_SLOTS];
    float *rects;           /* scratch: 12 floats per grown tile */
    float clip[4];          /* photons with dot(clip, (p, 1)) < 0 are left out (lm_caustic_pass_set_clip) */
};

static void free_photons(lm_caustic_pass *cp);

static void free_slot(slot_targets *t)
{
    if (t->splat_fbo) {
        glDeleteFramebuffers(1, &t->splat_fbo);
        glDeleteTextures(2, t->splat_tex);
        glDeleteRenderbuffers(1, &t->stencil);
        glDeleteFramebuffers(1, &t->irr_fbo);
        glDeleteTextures(1, &t->irr_tex);
    }
    if (t->queries)
        glDeleteQueries(t->tiles_x * t->tiles_y, t->queries);
    free(t->lit);
    free(t->queries);
    free(t->read_rects);
    memset(t, 0, sizeof *t);
}

/* An RGBA32F texture, with its whole mipmap chain when `mipmaps` (read from the nearest level, bilinearly). */
static GLuint float_texture(int w, int h, int mipmaps)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    int levels = 1;
    while (mipmaps && ((w >> levels) > 0 || (h >> levels) > 0))
        levels++;
    glTexStorage2D(GL_TEXTURE_2D, levels, GL_RGBA32F, w, h);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, mipmaps ? GL_LINEAR_MIPMAP_NEAREST : GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, mipmaps ? GL_LINEAR : GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

static lm_status make_slot(lm_caustic_pass *cp, slot_targets *t, int w, int h, lm_error *err)
{
    if (t->splat_fbo && t->width == w && t->height == h)
        return LM_OK;
    free_slot(t);
    t->width = w, t->height = h;
    t->tiles_x = (w + cp->set.tile - 1) / cp->set.tile;
    t->tiles_y = (h + cp->set.tile - 1) / cp->set.tile;
    int n = t->tiles_x * t->tiles_y;
    t->lit = calloc((size_t)n, 1);
    t->queries = calloc((size_t)n, sizeof *t->queries);
    t->read_rects = malloc((size_t)n * 4 * sizeof *t->read_rects);
    if (!t->lit || !t->queries || !t->read_rects) {
        free_slot(t);
        return lm_fail(err, LM_ERR_NOMEM, "caustic pass: no memory for %d tiles", n);
    }
    glGenQueries(n, t->queries);
    static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glGenFramebuffers(1, &t->splat_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, t->splat_fbo);
    for (int i = 0; i < 2; i++) {
        t->splat_tex[i] = float_texture(w, h, cp->set.filter_photons > 0);
        glFramebufferTexture2D(GL_FRAMEBUFFER, bufs[i], GL_TEXTURE_2D, t->splat_tex[i], 0);
    }
    glGenRenderbuffers(1, &t->stencil);
    glBindRenderbuffer(GL_RENDERBUFFER, t->stencil);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, t->stencil);
    glDrawBuffers(2, bufs);
    const int all[4] = {0, 0, w, h}; /* new textures hold anything */
    memcpy(t->splat_held, all, sizeof all);
    memcpy(t->irr_held, all, sizeof all);
    int ok = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glGenFramebuffers(1, &t->irr_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, t->irr_fbo);
    t->irr_tex = float_texture(w, h, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t->irr_tex, 0);
    ok = ok && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (!ok) {
        free_slot(t);
        return lm_fail(err, LM_ERR_BACKEND, "caustic pass: targets of %dx%d are incomplete", w, h);
    }
    return lm_gl_check("caustic pass: targets", err);
}

static lm_status build_programs(lm_caustic_pass *cp, lm_error *err)
{
    char fs[8192];
    lm_status st = lm_gl_program("caustic splat", lm_glsl_caustic_splat_vs, lm_glsl_caustic_splat_fs, &cp->splat_prog, err);
    if (st == LM_OK)
        st = lm_gl_program("caustic tile query", lm_glsl_caustic_rect_vs, lm_glsl_caustic_query_fs, &cp->query_prog, err);
    int len = snprintf(fs, sizeof fs, "%s", cp->set.world_space ? lm_glsl_caustic_filter_world_fs : lm_glsl_caustic_filter_screen_fs);
    char *k = strstr(fs, "FILTER_K");
    if (st == LM_OK && (len < 0 || (size_t)len >= sizeof fs || !k))
        st = lm_fail(err, LM_ERR_BACKEND, "caustic pass: shader source buffer too small");
    if (st == LM_OK) {
        char digits[16];
        snprintf(digits, sizeof digits, "%-8d", cp->set.filter_k); /* "FILTER_K" is 8 characters */
        memcpy(k, digits, 8);
        st = lm_gl_program("caustic filter", lm_glsl_caustic_filter_vs, fs, &cp->filter_prog, err);
    }
    if (st == LM_OK)
        st = lm_gl_program("caustic composite", lm_glsl_caustic_rect_vs, lm_glsl_caustic_composite_fs, &cp->composite_prog, err);
    if (st == LM_OK)
        st = lm_gl_program("caustic mask", lm_glsl_caustic_rect_vs, lm_glsl_caustic_mask_fs, &cp->mask_prog, err);
    if (st == LM_OK)
        st = lm_gl_program("caustic mipmaps", lm_glsl_caustic_rect_vs, lm_glsl_caustic_mip_fs, &cp->mip_prog, err);
    return st;
}

lm_status lm_caustic_pass_create(const lm_caustic_pass_settings *set, lm_caustic_pass **out, lm_error *err)
{
    *out = NULL;
    lm_caustic_pass_settings def;
    if (!set) {
        lm_caustic_pass_settings_default(&def);
        set = &def;
    }
    if (set->filter_k < 0 || set->filter_k > 8)
        return lm_fail(err, LM_ERR_INVALID, "caustic pass: the filter's k must be 0 to 8, not %d", set->filter_k);
    if (set->filter_photons < 0)
        return lm_fail(err, LM_ERR_INVALID, "caustic pass: the filter's photons must be 0 or more, not %d",
                       set->filter_photons);
    if (set->widen_levels < 0 || set->widen_levels > LM_CAUSTIC_FILTER_LEVELS)
        return lm_fail(err, LM_ERR_INVALID, "caustic pass: the filter widens 0 to %d levels, not %d",
                       LM_CAUSTIC_FILTER_LEVELS, set->widen_levels);
    if (set->tile < 4 || set->tile > 256)
        return lm_fail(err, LM_ERR_INVALID, "caustic pass: the tile side must be 4 to 256 pixels, not %d", set->tile);
    lm_caustic_pass *cp = calloc(1, sizeof *cp);
    if (!cp)
        return lm_fail(err, LM_ERR_NOMEM, "caustic pass: no memory");
    cp->set = *set;
    lm_status st = build_programs(cp, err);
    if (st == LM_OK) {
        glGenVertexArrays(1, &cp->vao);
        glGenVertexArrays(1, &cp->empty_vao);
        glGenBuffers(1, &cp->point_vbo);
        glGenBuffers(1, &cp->rect_vbo);
        glGenFramebuffers(1, &cp->mip_fbo);
        glBindVertexArray(cp->vao);
        glBindBuffer(GL_ARRAY_BUFFER, cp->point_vbo);
        for (int a = 0; a < 4; a++) { /* position, normal, flux; the count */
            glEnableVertexAttribArray((GLuint)a);
            glVertexAttribPointer((GLuint)a, a < 3 ? 3 : 1, GL_FLOAT, GL_FALSE, POINT_FLOATS * sizeof(float),
                                  (const void *)(size_t)(3 * a * sizeof(float)));
        }
        glBindVertexArray(0);
        glBindBuffer(GL_ARRAY_BUFFER, 0);
        st = lm_gl_check("caustic pass: setup", err);
    }
    if (st != LM_OK) {
        lm_caustic_pass_free(cp);
        return st;
    }
    *out = cp;
    return LM_OK;
}

void lm_caustic_pass_free(lm_caustic_pass *cp)
{
    if (!cp)
        return;
    for (int i = 0; i < LM_CAUSTIC_SLOTS; i++)
        free_slot(&cp->slots[i]);
    GLuint progs[6] = {cp->splat_prog, cp->query_prog, cp->filter_prog, cp->composite_prog, cp->mask_prog,
                       cp->mip_prog};
    for (int i = 0; i < 6; i++)
        if (progs[i])
            glDeleteProgram(progs[i]);
    if (cp->vao) {
        glDeleteVertexArrays(1, &cp->vao);
        glDeleteVertexArrays(1, &cp->empty_vao);
        glDeleteBuffers(1, &cp->point_vbo);
        glDeleteBuffers(1, &cp->rect_vbo);
        glDeleteFramebuffers(1, &cp->mip_fbo);
    }
    free(cp->rects);
    free_photons(cp);
    free(cp);
}

static int landed(const lm_caustic_hit *h) { return h->flux[0] != 0.0f || h->flux[1] != 0.0f || h->flux[2] != 0.0f; }

static void free_photons(lm_caustic_pass *cp)
{
    free(cp->hits), free(cp->visible), free(cp->pixel), free(cp->first), free(cp->points), free(cp->sum);
    free(cp->table);
    cp->hits = NULL, cp->visible = cp->pixel = cp->first = NULL, cp->points = NULL, cp->sum = NULL;
    cp->table = NULL;
    cp->photons = cp->table_size = 0;
}

lm_status lm_caustic_pass_set_photons(lm_caustic_pass *cp, const lm_caustic_hit *hits, uint32_t count, lm_error *err)
{
    free_photons(cp);
    uint32_t n = 0, size = 1;
    for (uint32_t i = 0; i < count; i++)
        n += landed(&hits[i]);
    while (size < 2 * n)
        size <<= 1;
    size_t m = n ? n : 1;
    cp->hits = malloc(m * sizeof *cp->hits);
    cp->visible = malloc(m * sizeof *cp->visible);
    cp->pixel = malloc(m * sizeof *cp->pixel);
    cp->first = malloc(m * sizeof *cp->first);
    cp->points = malloc(m * POINT_FLOATS * sizeof *cp->points);
    cp->sum = malloc(m * 3 * sizeof *cp->sum);
    cp->table = malloc(size * sizeof *cp->table);
    if (!cp->hits || !cp->visible || !cp->pixel || !cp->first || !cp->points || !cp->sum || !cp->table) {
        free_photons(cp);
        return lm_fail(err, LM_ERR_NOMEM, "caustic pass: no memory for %u photons", n);
    }
    for (uint32_t i = 0, k = 0; i < count; i++)
        if (landed(&hits[i]))
            cp->hits[k++] = hits[i];
    cp->photons = n;
    cp->table_size = size;
    return LM_OK;
}

void lm_caustic_pass_set_widening(lm_caustic_pass *cp, int levels)
{
    cp->set.widen_levels = levels < 0 ? 0 : levels > LM_CAUSTIC_FILTER_LEVELS ? LM_CAUSTIC_FILTER_LEVELS : levels;
}

uint32_t lm_caustic_pass_photon_count(const lm_caustic_pass *cp) { return cp->photons; }

/* The view's constants the passes share: image-plane pixel area at unit distance (perspective) or the
 * pixel's world area (orthographic), its side, and whether it is orthographic. */
typedef struct {
    float view_proj[16], inv_proj[16];
    float pix_area, pix_side;
    int ortho;
    float towards_eye[3];
} view_consts;

static int view_constants(const lm_view *v, int w, int h, view_consts *c)
{
    lm_mat4_mul(c->view_proj, v->proj, v->view);
    c->ortho = v->proj[11] == 0.0f;
    /* the projection's x and y scales: a pixel spans 2 / (p0 w) by 2 / (p5 h) at unit distance (or in
     * world units, orthographic) */
    float sx = 2.0f / (v->proj[0] * (float)w), sy = 2.0f / (v->proj[5] * (float)h);
    c->pix_area = fabsf(sx * sy);
    c->pix_side = sqrtf(c->pix_area);
    c->towards_eye[0] = v->view[2], c->towards_eye[1] = v->view[6], c->towards_eye[2] = v->view[10];
    /* inverse of the projection (no general 4x4 inverse here: perspective and orthographic forms) */
    memset(c->inv_proj, 0, sizeof c->inv_proj);
    const float *p = v->proj;
    if (!(p[0] != 0.0f && p[5] != 0.0f))
        return 0;
    c->inv_proj[0] = 1.0f / p[0];
    c->inv_proj[5] = 1.0f / p[5];
    if (c->ortho) { /* x_c = p0 x + p12, y_c = p5 y + p13, z_c = p10 z + p14, w_c = 1 */
        if (p[10] == 0.0f)
            return 0;
        c->inv_proj[10] = 1.0f / p[10];
        c->inv_proj[12] = -p[12] / p[0];
        c->inv_proj[13] = -p[13] / p[5];
        c->inv_proj[14] = -p[14] / p[10];
        c->inv_proj[15] = 1.0f;
        return 1;
    }
    /* x_c = p0 x + p8 z, y_c = p5 y + p9 z, z_c = p10 z + p14, w_c = -z: z = -w_c, x = (x_c + p8 w_c) / p0,
     * y likewise, and the point's own w = (z_c + p10 w_c) / p14 */
    if (p[14] == 0.0f)
        return 0;
    c->inv_proj[12] = p[8] / p[0];
    c->inv_proj[13] = p[9] / p[5];
    c->inv_proj[14] = -1.0f;
    c->inv_proj[11] = 1.0f / p[14];
    c->inv_proj[15] = p[10] / p[14];
    return 1;
}

static void set_size(GLuint prog, int w, int h) { glUniform2f(glGetUniformLocation(prog, "size"), (float)w, (float)h); }

/* The photons inside the view's frustum (clip space, |x|, |y|, |z| <= w, w > 0) into cp->visible: the
 * vertex stage, which llvmpipe runs on one thread, then sees only those (a sixth of them for a cube map's
 * face). Returns how many. The tiles they fall on are flagged in t->lit: the only tiles whose query can
 * find a photon (the splat draws each at the centre of the pixel it projects into), so the others are not
 * queried (256 queries cost 2 ms on llvmpipe, where a caustic lights a dozen tiles). A photon within a
 * pixel of a tile's edge flags the tile across it too, so that rounding in the vertex shader cannot put
 * it where no query looks. */
static uint32_t visible_photons(lm_caustic_pass *cp, slot_targets *t, const float m[16])
{
    uint32_t n = 0;
    int T = cp->set.tile;
    memset(t->lit, 0, (size_t)(t->tiles_x * t->tiles_y));
    for (uint32_t i = 0; i < cp->photons; i++) {
        const float *p = cp->hits[i].pos;
        if (cp->clip[0] * p[0] + cp->clip[1] * p[1] + cp->clip[2] * p[2] + cp->clip[3] < 0.0f)
            continue;
        float c[4];
        for (int r = 0; r < 4; r++)
            c[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
        if (!(c[3] > 0.0f && fabsf(c[0]) <= c[3] && fabsf(c[1]) <= c[3] && fabsf(c[2]) <= c[3]))
            continue;
        float px = (0.5f * c[0] / c[3] + 0.5f) * (float)t->width, py = (0.5f * c[1] / c[3] + 0.5f) * (float)t->height;
        int ix = (int)floorf(px), iy = (int)floorf(py);
        ix = ix < 0 ? 0 : ix >= t->width ? t->width - 1 : ix;
        iy = iy < 0 ? 0 : iy >= t->height ? t->height - 1 : iy;
        cp->pixel[n] = (uint32_t)iy * (uint32_t)t->width + (uint32_t)ix;
        cp->visible[n++] = i;
        for (int dy = -1; dy <= 1; dy += 2)
            for (int dx = -1; dx <= 1; dx += 2) {
                int tx = (int)floorf((px + (float)dx) / (float)T), ty = (int)floorf((py + (float)dy) / (float)T);
                tx = tx < 0 ? 0 : tx >= t->tiles_x ? t->tiles_x - 1 : tx;
                ty = ty < 0 ? 0 : ty >= t->tiles_y ? t->tiles_y - 1 : ty;
                t->lit[ty * t->tiles_x + tx] = 1;
            }
    }
    return n;
}

/* A photon's side of its receiver: the signs of its normal's components (a triangle's two sides differ in
 * every component that is not 0). */
static unsigned side_of(const float ng[3]) { return (ng[0] > 0.0f) | (ng[1] > 0.0f) << 1 | (ng[2] > 0.0f) << 2; }

/* Whether the run's visible photons a and b fall in one point: the same pixel, receiver triangle and side. */
static int same_point(const lm_caustic_pass *cp, uint32_t a, uint32_t b)
{
    const lm_caustic_hit *x = &cp->hits[cp->visible[a]], *y = &cp->hits[cp->visible[b]];
    return cp->pixel[a] == cp->pixel[b] && x->node == y->node && x->tri == y->tri && side_of(x->ng) == side_of(y->ng);
}

static uint32_t point_hash(const lm_caustic_pass *cp, uint32_t a)
{
    const lm_caustic_hit *x = &cp->hits[cp->visible[a]];
    uint32_t h = cp->pixel[a] * 2654435761u;
    h = (h ^ (uint32_t)x->node) * 2246822519u;
    h = (h ^ x->tri) * 3266489917u;
    return (h ^ side_of(x->ng) ^ h >> 15) & (cp->table_size - 1);
}

/* The points a run draws for its n visible photons, into cp->points; returns how many. With `merge`, the
 * photons in one pixel on one receiver triangle and side are one point: their mean position (inside the
 * pixel, since a projection keeps what lies between points between their images), their summed flux, and
 * their count, which the splat adds to its photon count; the splat would draw each at that pixel's centre
 * anyway. What the points save is llvmpipe's per-point cost: a focal spot seen by an environment map face
 * puts 13,000 photons in a few pixels, whose points its rasterizer draws one after another on one thread
 * (docs/caustics.md, "Points"). Without `merge`, a point a photon. */
static uint32_t make_points(lm_caustic_pass *cp, uint32_t n)
{
    uint32_t m = 0;
    if (cp->set.merge)
        memset(cp->table, 0xff, cp->table_size * sizeof *cp->table);
    for (uint32_t i = 0; i < n; i++) {
        const lm_caustic_hit *h = &cp->hits[cp->visible[i]];
        uint32_t k = m;
        if (cp->set.merge) {
            uint32_t b = point_hash(cp, i);
            while (cp->table[b] >= 0 && !same_point(cp, cp->first[cp->table[b]], i))
                b = (b + 1) & (cp->table_size - 1);
            if (cp->table[b] < 0)
                cp->table[b] = (int32_t)m;
            k = (uint32_t)cp->table[b];
        }
        float *q = cp->points + (size_t)k * POINT_FLOATS;
        double *sum = cp->sum + 3 * (size_t)k;
        if (k == m) { /* a new point */
            cp->first[m++] = i;
            memcpy(q + 3, h->ng, 3 * sizeof *q);
            memset(q + 6, 0, 4 * sizeof *q);
            sum[0] = sum[1] = sum[2] = 0.0;
        }
        for (int c = 0; c < 3; c++)
            sum[c] += h->pos[c], q[6 + c] += h->flux[c];
        q[9] += 1.0f;
    }
    for (uint32_t k = 0; k < m; k++) {
        float *q = cp->points + (size_t)k * POINT_FLOATS;
        for (int c = 0; c < 3; c++)
            q[c] = (float)(cp->sum[3 * (size_t)k + c] / q[9]);
    }
    return m;
}

/* The receiver mask into the splat's irr alpha over the rectangles the filter reads (its rgb and the flux
 * target kept): 1 where the pixel's kd is not 0 (every pixel when kd is 0, no frame targets). */
static void receiver_mask(lm_caustic_pass *cp, const slot_targets *t, GLuint kd)
{
    GLuint p = cp->mask_prog;
    glUseProgram(p);
    set_size(p, t->width, t->height);
    GLint rect = glGetUniformLocation(p, "rect");
    glUniform1i(glGetUniformLocation(p, "have_kd"), kd != 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, kd);
    glUniform1i(glGetUniformLocation(p, "kd"), 0);
    glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_TRUE);
    glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glBindVertexArray(cp->empty_vao);
    for (int i = 0; i < t->read_count; i++) {
        const int *r = t->read_rects + 4 * i;
        glUniform4f(rect, (float)r[0], (float)r[1], (float)r[2], (float)r[3]);
        glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    }
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

/* The picture of the frame targets a slot composites into. */
static int slot_picture(int slot)
{
    return slot == LM_CAUSTIC_SLOT_PROBE    ? LM_FRAME_PROBE
           : slot == LM_CAUSTIC_SLOT_MIRROR ? LM_FRAME_MIRROR
                                            : LM_FRAME_VIEW;
}

/* kd of the frame targets the slot composites into (0: none). */
static GLuint slot_kd(const lm_direct *d, int slot)
{
    if (!d)
        return 0;
    return lm_frame_targets_kd(lm_direct_targets(d), slot_picture(slot));
}

/* Splats the n photons visible_photons listed. */
static lm_status splat(lm_caustic_pass *cp, slot_targets *t, const lm_view *view, const view_consts *vc, GLuint depth,
                       GLuint kd, uint32_t n, lm_caustic_pass_stats *st)
{
    glBindFramebuffer(GL_FRAMEBUFFER, t->splat_fbo);
    glViewport(0, 0, t->width, t->height);
    clear_box(t->splat_held, 2, 1);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    receiver_mask(cp, t, kd);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_ALWAYS, 0, 0xFF);
    glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
    GLuint p = cp->splat_prog;
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "view_proj"), 1, GL_FALSE, vc->view_proj);
    glUniformMatrix4fv(glGetUniformLocation(p, "inv_proj"), 1, GL_FALSE, vc->inv_proj);
    glUniform3fv(glGetUniformLocation(p, "eye"), 1, view->eye);
    glUniform3fv(glGetUniformLocation(p, "view_dir"), 1, vc->towards_eye);
    glUniform1i(glGetUniformLocation(p, "ortho"), vc->ortho);
    glUniform1f(glGetUniformLocation(p, "pix_area"), vc->pix_area);
    glUniform1f(glGetUniformLocation(p, "pix_side"), vc->pix_side);
    set_size(p, t->width, t->height);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, depth);
    glUniform1i(glGetUniformLocation(p, "depth"), 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, kd);
    glUniform1i(glGetUniformLocation(p, "kd"), 1);
    glUniform1i(glGetUniformLocation(p, "have_kd"), kd != 0);
    glActiveTexture(GL_TEXTURE0);
    uint32_t points = make_points(cp, n);
    glBindBuffer(GL_ARRAY_BUFFER, cp->point_vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)((size_t)(points ? points : 1) * POINT_FLOATS * sizeof(float)), cp->points,
                 GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindVertexArray(cp->vao);
    GLuint q;
    glGenQueries(1, &q);
    glBeginQuery(GL_SAMPLES_PASSED, q);
    glDrawArrays(GL_POINTS, 0, (GLsizei)points);
    glEndQuery(GL_SAMPLES_PASSED);
    GLuint64 splatted = 0;
    glGetQueryObjectui64v(q, GL_QUERY_RESULT, &splatted);
    glDeleteQueries(1, &q);
    glDisable(GL_BLEND);
    st->photons = n;
    st->points = points;
    st->splatted = splatted;
    return LM_OK;
}

/* One query per tile a photon falls on (visible_photons' flags), around a quad drawn where the stencil
 * holds a photon; the other tiles are unlit. */
static void query_tiles(lm_caustic_pass *cp, slot_targets *t, lm_caustic_pass_stats *st)
{
    GLuint p = cp->query_prog;
    glUseProgram(p);
    set_size(p, t->width, t->height);
    GLint rect = glGetUniformLocation(p, "rect");
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glStencilFunc(GL_NOTEQUAL, 0, 0xFF);
    glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    glBindVertexArray(cp->empty_vao);
    int T = cp->set.tile;
    for (int ty = 0; ty < t->tiles_y; ty++)
        for (int tx = 0; tx < t->tiles_x; tx++) {
            if (!t->lit[ty * t->tiles_x + tx]) /* no photon falls there (visible_photons): nothing to ask */
                continue;
            float x0 = (float)(tx * T), y0 = (float)(ty * T);
            float x1 = fminf(x0 + (float)T, (float)t->width), y1 = fminf(y0 + (float)T, (float)t->height);
            glUniform4f(rect, x0, y0, x1, y1);
            glBeginQuery(GL_SAMPLES_PASSED, t->queries[ty * t->tiles_x + tx]);
            glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
            glEndQuery(GL_SAMPLES_PASSED);
        }
    int lit = 0;
    for (int i = 0; i < t->tiles_x * t->tiles_y; i++) {
        GLuint64 n = 0;
        if (t->lit[i])
            glGetQueryObjectui64v(t->queries[i], GL_QUERY_RESULT, &n);
        t->lit[i] = n > 0;
        lit += t->lit[i];
    }
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDisable(GL_STENCIL_TEST);
    lit_box(t, cp->set.tile, t->splat_held); /* photons landed in lit tiles only */
    st->tiles = t->tiles_x * t->tiles_y;
    st->tiles_lit = lit;
}

/* Whether tile (tx, ty) is within d tiles of a lit one. */
static int near_lit(const slot_targets *t, int tx, int ty, int d)
{
    for (int y = ty - d; y <= ty + d; y++)
        for (int x = tx - d; x <= tx + d; x++)
            if (x >= 0 && y >= 0 && x < t->tiles_x && y < t->tiles_y && t->lit[y * t->tiles_x + x])
                return 1;
    return 0;
}

/* The coarsest mip level the filter reads (0: none, the paper's fixed filter): filter_scale's density window
 * at the widest scale, level widen_levels + ceil(log2(2k + 1)) (caustic_filter_head.glsl). */
static int top_level(const lm_caustic_pass *cp)
{
    if (cp->set.filter_photons <= 0)
        return 0;
    int lw = 0;
    while ((1 << lw) < 2 * cp->set.filter_k + 1)
        lw++;
    return cp->set.widen_levels + lw;
}

/* Whether any of tile column tx's tiles in rows ty .. ty + band - 1 is within d tiles of a lit one. */
static int needed_column(const slot_targets *t, int tx, int ty, int band, int d)
{
    for (int y = ty; y < ty + band && y < t->tiles_y; y++)
        if (near_lit(t, tx, y, d))
            return 1;
    return 0;
}

/* t->read_rects: the pixels the filter may read this run, from the tiles a photon projects into
 * (visible_photons' flags), as runs of tiles along bands of tile rows (one row, or as many as one texel
 * of the coarsest mip level read spans), each widened to whole texels of that level (so every texel of every level there is made from texels made too). The filter
 * runs on tiles within LM_CAUSTIC_FILTER_REACH_AT of a lit one (grown_tiles) and reads within that reach
 * of them, and its density window, bilinearly at the coarsest level, reads 1.5 of that level's texels
 * from the pixel; the fixed filter grows each lit tile by k and reads k further. */
static void needed_rects(const lm_caustic_pass *cp, slot_targets *t)
{
    int T = cp->set.tile, k = cp->set.filter_k, top = top_level(cp), px;
    if (cp->set.filter_photons > 0) {
        int reach = LM_CAUSTIC_FILTER_REACH_AT(k, cp->set.widen_levels), window = 3 << top >> 1;
        px = (reach + T - 1) / T * T + (reach > window ? reach : window);
    } else {
        px = 2 * k;
    }
    int d = (px + T - 1) / T, align = 1 << top, band = align > T ? align / T : 1; /* tile rows a rect spans */
    t->read_count = 0;
    for (int ty = 0; ty < t->tiles_y; ty += band)
        for (int tx = 0; tx < t->tiles_x;) {
            int end = tx;
            while (end < t->tiles_x && needed_column(t, end, ty, band, d))
                end++;
            if (end == tx) {
                tx++;
                continue;
            }
            int *r = t->read_rects + 4 * t->read_count++;
            r[0] = tx * T / align * align, r[1] = ty * T / align * align;
            r[2] = (end * T + align - 1) / align * align, r[3] = ((ty + band) * T + align - 1) / align * align;
            r[2] = r[2] < t->width ? r[2] : t->width, r[3] = r[3] < t->height ? r[3] : t->height;
            tx = end;
        }
}

/* Mip levels 1 .. top_level of the splat texture tex over t->read_rects only: glGenerateMipmap would make
 * every level over the whole target, most of the pass's fixed cost once the lit tiles are few. */
static void mip_region(lm_caustic_pass *cp, const slot_targets *t, GLuint tex)
{
    int top = top_level(cp);
    glUseProgram(cp->mip_prog);
    glUniform1i(glGetUniformLocation(cp->mip_prog, "src"), 0);
    GLint rect = glGetUniformLocation(cp->mip_prog, "rect");
    glBindFramebuffer(GL_FRAMEBUFFER, cp->mip_fbo);
    glBindVertexArray(cp->empty_vao);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, tex);
    for (int level = 1; level <= top && (t->width >> level) > 0 && (t->height >> level) > 0; level++) {
        int w = t->width >> level, h = t->height >> level;
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, level);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, level - 1);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, level - 1);
        glViewport(0, 0, w, h);
        set_size(cp->mip_prog, w, h);
        for (int i = 0; i < t->read_count; i++) {
            const int *r = t->read_rects + 4 * i;
            int x1 = (r[2] + (1 << level) - 1) >> level, y1 = (r[3] + (1 << level) - 1) >> level;
            glUniform4f(rect, (float)(r[0] >> level), (float)(r[1] >> level), (float)(x1 < w ? x1 : w),
                        (float)(y1 < h ? y1 : h));
            glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
        }
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 1000);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, 0, 0);
}

/* The filter's squares as triangles (pixel coordinates) into cp->rects, *count of them; their box in box.
 * The fixed filter: each lit tile grown by k pixels. Sized by density, the filter reaches
 * LM_CAUSTIC_FILTER_REACH(k) pixels: every tile within that of a lit one, each once (grown squares
 * would overlap many times). */
static lm_status grown_tiles(lm_caustic_pass *cp, const slot_targets *t, int *count, int box[4], uint64_t *pixels,
                             lm_error *err)
{
    int T = cp->set.tile, grow = cp->set.filter_photons > 0 ? 0 : cp->set.filter_k, n = 0;
    int reach = LM_CAUSTIC_FILTER_REACH_AT(cp->set.filter_k, cp->set.widen_levels); /* in pixels, sized by density */
    int d = cp->set.filter_photons > 0 ? (reach + T - 1) / T : 0;
    int most = d ? t->tiles_x * t->tiles_y : *count;
    float *r = realloc(cp->rects, (size_t)(most ? most : 1) * 12 * sizeof *r);
    if (!r)
        return lm_fail(err, LM_ERR_NOMEM, "caustic pass: no memory for %d tiles", most);
    cp->rects = r;
    box[0] = t->width, box[1] = t->height, box[2] = box[3] = 0;
    *pixels = 0;
    for (int ty = 0; ty < t->tiles_y; ty++)
        for (int tx = 0; tx < t->tiles_x; tx++) {
            if (d ? !near_lit(t, tx, ty, d) : !t->lit[ty * t->tiles_x + tx])
                continue;
            int x0 = tx * T - grow, y0 = ty * T - grow, x1 = tx * T + T + grow, y1 = ty * T + T + grow;
            x0 = x0 < 0 ? 0 : x0, y0 = y0 < 0 ? 0 : y0;
            x1 = x1 > t->width ? t->width : x1, y1 = y1 > t->height ? t->height : y1;
            const float q[12] = {(float)x0, (float)y0, (float)x1, (float)y0, (float)x1, (float)y1,
                                 (float)x0, (float)y0, (float)x1, (float)y1, (float)x0, (float)y1};
            memcpy(r + 12 * n++, q, sizeof q);
            box[0] = x0 < box[0] ? x0 : box[0], box[1] = y0 < box[1] ? y0 : box[1];
            box[2] = x1 > box[2] ? x1 : box[2], box[3] = y1 > box[3] ? y1 : box[3];
            *pixels += (uint64_t)(x1 - x0) * (uint64_t)(y1 - y0);
        }
    *count = n;
    return LM_OK;
}

/* The filter over count squares of cp->rects, whose box is box (what the next run clears). */
static void filter(lm_caustic_pass *cp, slot_targets *t, const view_consts *vc, GLuint depth, int count,
                   const int box[4])
{
    for (int i = 0; i < 2 && count && cp->set.filter_photons > 0; i++) /* the splat's means over 2^L pixels */
        mip_region(cp, t, t->splat_tex[i]);
    glBindFramebuffer(GL_FRAMEBUFFER, t->irr_fbo);
    glViewport(0, 0, t->width, t->height);
    clear_box(t->irr_held, 1, 0);
    memcpy(t->irr_held, box, sizeof t->irr_held);
    if (!count)
        return;
    GLuint p = cp->filter_prog;
    glUseProgram(p);
    set_size(p, t->width, t->height);
    glUniformMatrix4fv(glGetUniformLocation(p, "inv_proj"), 1, GL_FALSE, vc->inv_proj);
    glUniform1i(glGetUniformLocation(p, "ortho"), vc->ortho);
    glUniform1f(glGetUniformLocation(p, "pix_side"), vc->pix_side);
    glUniform1f(glGetUniformLocation(p, "need"), (float)cp->set.filter_photons);
    glUniform1i(glGetUniformLocation(p, "levels"), cp->set.widen_levels);
    const GLuint tex[3] = {t->splat_tex[0], t->splat_tex[1], depth};
    const char *names[3] = {"irr", "flux", "depth"};
    for (int i = 0; i < 3; i++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, tex[i]);
        glUniform1i(glGetUniformLocation(p, names[i]), i);
    }
    glBindVertexArray(cp->empty_vao);
    glBindBuffer(GL_ARRAY_BUFFER, cp->rect_vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)((size_t)count * 12 * sizeof(float)), cp->rects, GL_STREAM_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, NULL);
    glDrawArrays(GL_TRIANGLES, 0, 6 * count);
    glDisableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glActiveTexture(GL_TEXTURE0);
}

/* kd / pi x E added over the box of the grown lit tiles (outside them E is 0), into d's picture of the slot
 * (slot_picture). One quad: no geometry drawn again. */
static void composite(lm_caustic_pass *cp, const slot_targets *t, const lm_direct *d, int slot, const int box[4])
{
    const lm_frame_targets *f = lm_direct_targets(d);
    lm_frame_targets_bind_radiance(f, slot_picture(slot));
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    GLuint p = cp->composite_prog;
    glUseProgram(p);
    set_size(p, t->width, t->height);
    glUniform4f(glGetUniformLocation(p, "rect"), (float)box[0], (float)box[1], (float)box[2], (float)box[3]);
    const GLuint tex[2] = {t->irr_tex, slot_kd(d, slot)};
    const char *names[2] = {"irr", "kd"};
    for (int i = 0; i < 2; i++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, tex[i]);
        glUniform1i(glGetUniformLocation(p, names[i]), i);
    }
    glBindVertexArray(cp->empty_vao);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_BLEND);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void lm_caustic_pass_set_clip(lm_caustic_pass *cp, const float plane[4])
{
    for (int k = 0; k < 4; k++)
        cp->clip[k] = plane ? plane[k] : 0.0f;
}

lm_status lm_caustic_pass_run(lm_caustic_pass *cp, int slot, const lm_view *view, unsigned depth, int width,
                              int height, const lm_direct *d, lm_caustic_pass_stats *stats, lm_error *err)
{
    lm_caustic_pass_stats st;
    memset(&st, 0, sizeof st);
    if (slot < 0 || slot >= LM_CAUSTIC_SLOTS || width <= 0 || height <= 0)
        return lm_fail(err, LM_ERR_INVALID, "caustic pass: bad slot %d or size %dx%d", slot, width, height);
    view_consts vc;
    if (!view_constants(view, width, height, &vc))
        return lm_fail(err, LM_ERR_INVALID, "caustic pass: the view's projection cannot be inverted");
    slot_targets *t = &cp->slots[slot];
    lm_status s = make_slot(cp, t, width, height, err);
    /* no photon in the view (an environment map face that sees no focal spot): no GL work at all */
    uint32_t visible = s == LM_OK && cp->photons ? visible_photons(cp, t, vc.view_proj) : 0;
    if (visible)
        needed_rects(cp, t);
    if (s != LM_OK || !visible) {
        st.tiles = s == LM_OK ? t->tiles_x * t->tiles_y : 0;
        if (s == LM_OK && t->irr_fbo) { /* nothing lights the slot: its irradiance is 0 */
            memset(t->lit, 0, (size_t)(t->tiles_x * t->tiles_y));
            t->lit_count = 0;
            glBindFramebuffer(GL_FRAMEBUFFER, t->irr_fbo);
            clear_box(t->irr_held, 1, 0);
            memset(t->irr_held, 0, sizeof t->irr_held);
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
        }
        if (stats)
            *stats = st;
        return s;
    }
    double tw = lm_now();
    glFinish(); /* the times below are the pass's own, not the frame's work before it */
    double t0 = lm_now();
    st.t_wait = t0 - tw;
    splat(cp, t, view, &vc, depth, slot_kd(d, slot), visible, &st); /* its query's result waits for the splat */
    double t1 = lm_now();
    query_tiles(cp, t, &st);
    double t2 = lm_now();
    int box[4] = {0, 0, 0, 0}, squares = st.tiles_lit;
    s = grown_tiles(cp, t, &squares, box, &st.pixels_filtered, err);
    if (s == LM_OK) {
        filter(cp, t, &vc, depth, squares, box);
        glFinish();
    }
    double t3 = lm_now();
    t->lit_count = st.tiles_lit;
    memcpy(t->box, box, sizeof box);
    if (s == LM_OK && d && st.tiles_lit) {
        composite(cp, t, d, slot, box);
        glFinish();
    }
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    st.t_splat = t1 - t0, st.t_query = t2 - t1, st.t_filter = t3 - t2, st.t_composite = lm_now() - t3;
    if (stats)
        *stats = st;
    return s == LM_OK ? lm_gl_check("caustic pass", err) : s;
}

/* The slot asked for, the frame's when out of range. */
static const slot_targets *slot_of(const lm_caustic_pass *cp, int slot)
{
    return &cp->slots[slot >= 0 && slot < LM_CAUSTIC_SLOTS ? slot : LM_CAUSTIC_SLOT_FRAME];
}

unsigned lm_caustic_pass_irradiance(const lm_caustic_pass *cp, int slot) { return slot_of(cp, slot)->irr_tex; }

lm_status lm_caustic_pass_composite(lm_caustic_pass *cp, int slot, const lm_direct *d, lm_caustic_pass_stats *stats,
                                    lm_error *err)
{
    if (slot < 0 || slot >= LM_CAUSTIC_SLOTS || !cp->slots[slot].irr_fbo)
        return lm_fail(err, LM_ERR_INVALID, "caustic pass: slot %d has no irradiance to composite", slot);
    slot_targets *t = &cp->slots[slot];
    lm_caustic_pass_stats st;
    memset(&st, 0, sizeof st);
    double t0 = lm_now();
    if (t->lit_count && cp->photons) {
        composite(cp, t, d, slot, t->box);
        glFinish();
    }
    glBindVertexArray(0);
    st.t_composite = lm_now() - t0;
    if (stats)
        *stats = st;
    return lm_gl_check("caustic pass: composite", err);
}

const uint8_t *lm_caustic_pass_tiles(const lm_caustic_pass *cp, int slot, int *tiles_x, int *tiles_y)
{
    const slot_targets *t = slot_of(cp, slot);
    *tiles_x = t->tiles_x;
    *tiles_y = t->tiles_y;
    return t->lit;
}

static lm_status read_texture(GLuint tex, int w, int h, float *rgba, lm_error *err)
{
    if (!tex)
        return lm_fail(err, LM_ERR_INVALID, "caustic pass: nothing to read before a run");
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, rgba);
    (void)w, (void)h;
    return lm_gl_check("caustic pass: read-back", err);
}

lm_status lm_caustic_pass_read_splat(const lm_caustic_pass *cp, int slot, float *rgba, lm_error *err)
{
    const slot_targets *t = slot_of(cp, slot);
    size_t n = (size_t)t->width * (size_t)t->height;
    float *flux = malloc((n ? n : 1) * 4 * sizeof *flux);
    if (!flux)
        return lm_fail(err, LM_ERR_NOMEM, "caustic pass: no memory to read the splat");
    lm_status st = read_texture(t->splat_tex[0], t->width, t->height, rgba, err);
    if (st == LM_OK)
        st = read_texture(t->splat_tex[1], t->width, t->height, flux, err);
    for (size_t i = 0; st == LM_OK && i < n; i++) /* the photon count is the flux target's alpha */
        rgba[4 * i + 3] = flux[4 * i + 3];
    free(flux);
    return st;
}

lm_status lm_caustic_pass_read_irradiance(const lm_caustic_pass *cp, int slot, float *rgb, lm_error *err)
{
    const slot_targets *t = slot_of(cp, slot);
    size_t n = (size_t)t->width * (size_t)t->height;
    float *rgba = malloc((n ? n : 1) * 4 * sizeof *rgba);
    if (!rgba)
        return lm_fail(err, LM_ERR_NOMEM, "caustic pass: no memory to read back");
    lm_status st = read_texture(t->irr_tex, t->width, t->height, rgba, err);
    for (int y = 0; st == LM_OK && y < t->height; y++)
        for (int x = 0; x < t->width; x++) {
            const float *s = rgba + 4 * ((size_t)(t->height - 1 - y) * t->width + x);
            float *o = rgb + 3 * ((size_t)y * t->width + x);
            o[0] = s[0], o[1] = s[1], o[2] = s[2];
        }
    free(rgba);
    return st;
}
