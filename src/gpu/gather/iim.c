/* IIM scheduling, double-buffered blending (glsl/iim_blend_cs.glsl) and invalid-texel filling (iim.h). */
#include "iim.h"

#include "../gl/gl_api.h"
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../charts/atlas_dilate.h"
#include "../gl/gl_shader.h"
#include "glsl.h"
#include "hemicube.h"

#define NEVER (INT_MIN / 2)

void lm_iim_settings_default(lm_iim_settings *s)
{
    s->texels_per_frame = LM_IIM_DEFAULT_TEXELS_PER_FRAME;
    s->blend_frames = 8;
    s->delta_threshold = 0.0;
    s->texel_change = 0.03125f;
    s->backface_limit = 0.1f;
    s->spread = 3;
    s->estimate_rays = 36; /* LM_RAY_ESTIMATE_RAYS (update/ray_estimate.h, a layer above) */
}

/* The six atlas textures in binding order (glsl/iim_blend_cs.glsl): fresh, old, new, display, delta, carry. */
#define IIM_TEXTURES 6
static void textures(lm_iim *iim, unsigned *tex[IIM_TEXTURES])
{
    unsigned *t[IIM_TEXTURES] = {&iim->fresh_tex,   &iim->old_tex,   &iim->new_tex,
                                 &iim->display_tex, &iim->delta_tex, &iim->carry_tex};
    memcpy(tex, t, sizeof t);
}

/* The turn maps (iim.h), where the atlas has texels that turn (lm_texel_turns). Half floats: a turn is a
 * relative change of a few tenths, and 3 digits are more than its estimate holds. */
static lm_status init_turn(lm_iim *iim, const lm_atlas *a, lm_error *err)
{
    uint32_t turns = 0;
    for (uint32_t i = 0; a->footprint_count && i < a->texel_count && !turns; i++)
        turns = lm_texel_turns(a, i);
    if (!turns)
        return LM_OK;
    glGenTextures(3, iim->turn_tex);
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int c = 0; c < 3; c++) {
        glBindTexture(GL_TEXTURE_2D, iim->turn_tex[c]);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA16F, a->width, a->height);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glClearTexImage(iim->turn_tex[c], 0, GL_RGBA, GL_FLOAT, zero);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    return lm_gl_check("IIM: the turn maps", err);
}

static lm_status init_gl(lm_iim *iim, const lm_atlas *a, lm_error *err)
{
    unsigned *tex[IIM_TEXTURES];
    textures(iim, tex);
    for (int i = 0; i < IIM_TEXTURES; i++)
        if (!(*tex[i] = lm_iim_texture_create(a->width, a->height)))
            return lm_fail(err, LM_ERR_BACKEND, "IIM: could not make a %dx%d RGBA32F texture", a->width, a->height);
    lm_status st = lm_gl_compute_program("iim_blend", lm_glsl_iim_blend_cs, &iim->blend_prog, err);
    if (st != LM_OK)
        return st;
    size_t n = (size_t)a->width * (size_t)a->height;
    int *surf = malloc(sizeof(int) * n);
    if (!surf)
        return lm_fail(err, LM_ERR_NOMEM, "IIM: no memory");
    for (size_t i = 0; i < n; i++)
        surf[i] = a->texel_index[i] < 0 ? -1 : a->texels[a->texel_index[i]].surface;
    GLuint bufs[8];
    glGenBuffers(8, bufs);
    iim->surface_buf = bufs[0], iim->params_buf = bufs[1], iim->start_buf = bufs[2], iim->list_buf = bufs[3];
    iim->chart_buf = bufs[4], iim->redraw_buf = bufs[5], iim->ops_buf = bufs[6], iim->flag_buf = bufs[7];
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[0]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(int) * n), surf, GL_STATIC_DRAW);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[4]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(int) * n), a->chart_owner, GL_STATIC_DRAW);
    for (int i = 5; i <= 6; i++) { /* the frame's cells to draw and flag changes: at most one a texel */
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[i]);
        glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(int32_t) * (a->texel_count ? a->texel_count : 1)),
                     NULL, GL_DYNAMIC_DRAW);
    }
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[1]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(float) * 2 * (size_t)(iim->sched.surface_count + 1)), NULL,
                 GL_DYNAMIC_DRAW);
    memset(surf, 0, sizeof(int) * n); /* no cell waits */
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[7]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(int) * n), surf, GL_DYNAMIC_DRAW);
    for (size_t i = 0; i < n; i++)
        surf[i] = NEVER; /* every cell's clock: fully blended */
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[2]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(int) * n), surf, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[3]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(int) * (a->texel_count ? a->texel_count : 1)), NULL,
                 GL_DYNAMIC_DRAW);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    free(surf);
    if (!(iim->sight_tex = lm_iim_texture_create(a->width, a->height)))
        return lm_fail(err, LM_ERR_BACKEND, "IIM: could not make a %dx%d RGBA32F texture", a->width, a->height);
    st = lm_gl_check("IIM: blend buffers", err);
    return st == LM_OK ? init_turn(iim, a, err) : st;
}

lm_status lm_iim_init(lm_iim *iim, const lm_atlas *a, const lm_iim_settings *set, int with_gl, lm_error *err)
{
    memset(iim, 0, sizeof *iim);
    iim->set = *set;
    iim->width = a->width, iim->height = a->height;
    size_t S = (size_t)(a->surface_count ? a->surface_count : 1);
    iim->blend_start = malloc(S * sizeof *iim->blend_start);
    iim->version = calloc(S, sizeof *iim->version);
    iim->texel_start = malloc(S * sizeof *iim->texel_start);
    iim->list = malloc(sizeof *iim->list * (a->texel_count ? a->texel_count : 1));
    iim->version_touch = calloc(S, 1);
    iim->active = calloc(S, 1);
    iim->sight = calloc(4 * (size_t)a->width * a->height + 4, sizeof *iim->sight);
    iim->sight_dirty[0] = 1; /* none */
    iim->spent = malloc(sizeof *iim->spent * (a->texel_count ? a->texel_count : 1));
    lm_status st = iim->blend_start && iim->version && iim->texel_start && iim->list && iim->version_touch &&
                           iim->active && iim->sight && iim->spent
                       ? lm_iim_sched_init(&iim->sched, a, set->texels_per_frame, set->delta_threshold, err)
                       : lm_fail(err, LM_ERR_NOMEM, "IIM: no memory for %d surfaces", a->surface_count);
    if (st == LM_OK)
        st = lm_iim_pending_init(&iim->pending, a->texel_count, err);
    for (size_t k = 0; st == LM_OK && k < S; k++)
        iim->blend_start[k] = iim->texel_start[k] = NEVER;
    if (st == LM_OK && with_gl)
        st = init_gl(iim, a, err);
    if (st != LM_OK)
        lm_iim_free(iim);
    return st;
}

void lm_iim_free(lm_iim *iim)
{
    unsigned *tex[IIM_TEXTURES];
    textures(iim, tex);
    for (int i = 0; i < IIM_TEXTURES; i++)
        lm_iim_texture_free(*tex[i]);
    lm_iim_texture_free(iim->sight_tex);
    if (iim->turn_tex[0])
        glDeleteTextures(3, iim->turn_tex);
    if (iim->blend_prog) {
        GLuint bufs[8] = {iim->surface_buf, iim->params_buf, iim->start_buf, iim->list_buf,
                          iim->chart_buf,   iim->redraw_buf, iim->ops_buf,   iim->flag_buf};
        glDeleteBuffers(8, bufs);
        glDeleteProgram(iim->blend_prog);
    }
    if (iim->scale_prog) {
        glDeleteBuffers(1, &iim->factor_buf);
        glDeleteProgram(iim->scale_prog);
    }
    lm_iim_sched_free(&iim->sched);
    free(iim->blend_start);
    free(iim->texel_start);
    free(iim->list);
    lm_iim_pending_free(&iim->pending);
    free(iim->version_touch);
    free(iim->active);
    free(iim->version);
    free(iim->sight);
    free(iim->spent);
    memset(iim, 0, sizeof *iim);
}

/* Whether a commit at frame `start` still blends at frame `frame` (glsl/iim_blend_cs.glsl, blend_t_at: the
 * commit's frame shows 1 / blend_frames of it, frame start + blend_frames - 1 all of it). */
static int blending_at(const lm_iim *iim, int start, double frame)
{
    return frame - start + 1 < iim->set.blend_frames;
}

void lm_iim_commit_texels(lm_iim *iim, const lm_atlas *a, const uint32_t *texels, uint32_t n)
{
    for (uint32_t j = 0; j < n && iim->list_count < a->texel_count; j++) {
        const lm_texel *t = &a->texels[texels[j]];
        iim->list[iim->list_count++] = t->y * a->width + t->x;
        iim->texel_start[t->surface] = iim->sched.frame;
        lm_iim_pending_committed(&iim->pending, texels[j]);
    }
}

void lm_iim_set_pending(lm_iim *iim, const lm_atlas *a, const uint32_t *texels, uint32_t n)
{
    if (iim->set.spread > 0)
        lm_iim_pending_add(&iim->pending, a, texels, n, iim->version_touch);
}

/* Cell (x, y)'s sight changed: in the rectangle to upload. */
static void sight_touched(lm_iim *iim, int x, int y)
{
    int *d = iim->sight_dirty;
    if (d[0] > d[2])
        d[0] = d[2] = x, d[1] = d[3] = y;
    d[0] = x < d[0] ? x : d[0], d[1] = y < d[1] ? y : d[1];
    d[2] = x > d[2] ? x : d[2], d[3] = y > d[3] ? y : d[3];
}

void lm_iim_set_sight(lm_iim *iim, const lm_atlas *a, const uint32_t *texels, const float *change, const float *light,
                      const uint8_t *rays, uint8_t many, uint32_t n)
{
    for (uint32_t j = 0; j < n; j++) {
        const lm_texel *t = &a->texels[texels[j]];
        float *cell = iim->sight + 4 * ((size_t)t->y * a->width + t->x);
        const float *c = change + 3 * (size_t)texels[j], *e = light + 3 * (size_t)texels[j];
        float moved = fabsf(c[0] - cell[0]) + fabsf(c[1] - cell[1]) + fabsf(c[2] - cell[2]);
        float how = rays && rays[texels[j]] >= many ? LM_IIM_SIGHT_ALONE : 1.0f; /* the shader's flag */
        if (cell[3] == how && moved <= LM_IIM_SIGHT_KEEP * (fabsf(e[0]) + fabsf(e[1]) + fabsf(e[2])))
            continue; /* shown already, to what the eye can tell */
        memcpy(cell, c, 3 * sizeof *cell);
        cell[3] = how;
        sight_touched(iim, (int)t->x, (int)t->y);
        for (int dy = -LM_IIM_SIGHT_SPREAD; dy <= LM_IIM_SIGHT_SPREAD; dy++) /* and the neighbours that average it */
            for (int dx = -LM_IIM_SIGHT_SPREAD; dx <= LM_IIM_SIGHT_SPREAD; dx++) {
                int x = (int)t->x + dx, y = (int)t->y + dy;
                int32_t q = x < 0 || y < 0 || x >= a->width || y >= a->height ? -1 : a->texel_index[(size_t)y * a->width + x];
                if (q >= 0)
                    lm_iim_pending_redraw(&iim->pending, (uint32_t)q);
            }
    }
}

void lm_iim_sight_gathered(lm_iim *iim, const lm_atlas *a, const uint32_t *texels, uint32_t n)
{
    for (uint32_t j = 0; j < n; j++) {
        const lm_texel *t = &a->texels[texels[j]];
        uint32_t c = t->y * a->width + t->x;
        if (iim->sight[4 * (size_t)c + 3] <= 0.5f || iim->spent_count >= a->texel_count)
            continue;
        iim->sight[4 * (size_t)c + 3] = -1.0f;
        iim->spent[iim->spent_count++] = c;
        sight_touched(iim, (int)t->x, (int)t->y);
    }
}

/* The frame's estimates of their own to the GPU, if any changed. */
static void upload_sight(lm_iim *iim)
{
    int *d = iim->sight_dirty;
    if (d[0] > d[2] || !iim->sight_tex)
        return;
    glBindTexture(GL_TEXTURE_2D, iim->sight_tex);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, iim->width);
    glTexSubImage2D(GL_TEXTURE_2D, 0, d[0], d[1], d[2] - d[0] + 1, d[3] - d[1] + 1, GL_RGBA, GL_FLOAT,
                    iim->sight + 4 * ((size_t)d[1] * iim->width + d[0]));
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glBindTexture(GL_TEXTURE_2D, 0);
    d[0] = 1, d[2] = 0;
}

/* The cells whose texel was gathered this frame hold no estimate of their own from the next on. */
static void clear_spent(lm_iim *iim)
{
    for (uint32_t j = 0; j < iim->spent_count; j++) {
        memset(iim->sight + 4 * (size_t)iim->spent[j], 0, 4 * sizeof *iim->sight);
        sight_touched(iim, (int)(iim->spent[j] % (uint32_t)iim->width), (int)(iim->spent[j] / (uint32_t)iim->width));
    }
    iim->spent_count = 0;
}

/* One list pass of iim_blend: mode `mode` over the `count` entries of buffer `buf`, bound at `binding`,
 * uploaded from data first (NULL: the buffer holds them already). */
typedef struct {
    int mode;
    unsigned buf;
    int binding;
    const int32_t *data;
    uint32_t count;
} list_pass;

/* Passes a and b (b.count may be 0) as one dispatch, their entries one after the other: two passes that
 * neither read what the other writes (glsl/iim_blend_cs.glsl), for one wait for llvmpipe's threads
 * instead of two. */
static void dispatch_lists(lm_iim *iim, const list_pass *a, const list_pass *b)
{
    const list_pass *passes[2] = {a, b};
    for (int i = 0; i < 2; i++) {
        const list_pass *l = passes[i];
        if (l->data && l->count) {
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, l->buf);
            glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(sizeof(int32_t) * l->count), l->data);
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
        }
        if (l->count)
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)l->binding, l->buf);
    }
    GLuint groups = (GLuint)(a->count + b->count + 63) / 64;
    glUniform1i(glGetUniformLocation(iim->blend_prog, "mode"), a->mode);
    glUniform1i(glGetUniformLocation(iim->blend_prog, "list_count"), (int)a->count);
    glUniform1i(glGetUniformLocation(iim->blend_prog, "mode2"), b->mode);
    glUniform1i(glGetUniformLocation(iim->blend_prog, "count2"), (int)b->count);
    glUniform1i(glGetUniformLocation(iim->blend_prog, "row"), 8 * (int)groups);
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
}

/* Runs the passes given: both at once, the one with entries alone, or none. */
static void run_lists(lm_iim *iim, list_pass a, list_pass b)
{
    if (!a.count) {
        a = b;
        b.count = 0;
    }
    if (a.count)
        dispatch_lists(iim, &a, &b);
}

lm_status lm_iim_blend(lm_iim *iim, int instant, lm_error *err)
{
    int S = iim->sched.surface_count;
    uint8_t *commit = iim->sched.commit;
    float *param = malloc(sizeof(float) * 2 * (size_t)(S + 1));
    if (!param)
        return lm_fail(err, LM_ERR_NOMEM, "IIM: no memory");
    int any_commit = iim->list_count > 0, blending = 0;
    double frame = iim->sched.frame;
    for (int s = 0; s < S; s++) {
        /* shown differently from the last frame: committed now (the surface or some of its texels), still
         * blending last frame, or with texels that began to wait (their estimate) */
        int changed = commit[s] || iim->texel_start[s] == iim->sched.frame ||
                      blending_at(iim, iim->blend_start[s], frame - 1) ||
                      blending_at(iim, iim->texel_start[s], frame - 1) || iim->version_touch[s];
        iim->version[s] += (uint32_t)changed;
        iim->version_touch[s] = changed ? 2 : 0; /* 2: counted; lm_iim_pending_frame may add 1 below */
        if (commit[s])
            iim->blend_start[s] = instant ? NEVER : iim->sched.frame;
        if (instant && iim->texel_start[s] == iim->sched.frame)
            iim->texel_start[s] = NEVER;
        int blends = blending_at(iim, iim->blend_start[s], frame) || blending_at(iim, iim->texel_start[s], frame);
        iim->active[s] = commit[s] || iim->texel_start[s] == iim->sched.frame || blends;
        param[2 * s] = commit[s] ? 1.0f : 0.0f;
        param[2 * s + 1] = instant ? 1.0f : 0.0f;
        any_commit |= commit[s];
        blending |= blends;
    }
    lm_iim_pending_frame(&iim->pending, commit, iim->active, iim->version_touch);
    for (int s = 0; s < S; s++) { /* and those with texels that stopped waiting, back to themselves */
        iim->version[s] += iim->version_touch[s] == 1;
        iim->version_touch[s] = commit[s] = 0;
    }
    const lm_iim_pending *pend = &iim->pending;
    if (!any_commit && iim->settled && !pend->op_count && !pend->redraw_count) { /* nothing shows differently */
        free(param);
        clear_spent(iim);
        lm_iim_sched_end_frame(&iim->sched);
        return LM_OK;
    }
    upload_sight(iim);
    int atlas_pass = any_commit || !iim->settled; /* else only estimates to draw */
    iim->settled = !blending;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, iim->params_buf);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(sizeof(float) * 2 * (size_t)S), param);
    free(param);
    glUseProgram(iim->blend_prog);
    glUniform2i(glGetUniformLocation(iim->blend_prog, "size"), iim->width, iim->height);
    glUniform1i(glGetUniformLocation(iim->blend_prog, "frame"), iim->sched.frame);
    glUniform1i(glGetUniformLocation(iim->blend_prog, "blend_frames"), iim->set.blend_frames);
    glUniform1f(glGetUniformLocation(iim->blend_prog, "limit"), iim->set.backface_limit);
    glUniform1i(glGetUniformLocation(iim->blend_prog, "spread"), iim->set.spread);
    glUniform1i(glGetUniformLocation(iim->blend_prog, "sight_spread"), LM_IIM_SIGHT_SPREAD);
    glUniform1i(glGetUniformLocation(iim->blend_prog, "sight_apart"), LM_IIM_SIGHT_APART);
    glUniform1i(glGetUniformLocation(iim->blend_prog, "sight_blend"), LM_IIM_SIGHT_BLEND);
    unsigned *tex[IIM_TEXTURES];
    textures(iim, tex);
    for (int i = 0; i < IIM_TEXTURES; i++)
        glBindImageTexture((GLuint)i, *tex[i], 0, GL_FALSE, 0, i ? GL_READ_WRITE : GL_READ_ONLY, GL_RGBA32F);
    glBindImageTexture(IIM_TEXTURES, iim->sight_tex, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, iim->surface_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, iim->params_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, iim->start_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, iim->chart_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, iim->flag_buf);
    /* which cells wait (mode 3, read by the atlas pass: a committed one is drawn as itself) and the cells
     * committed on their own (mode 1) */
    glUniform1i(glGetUniformLocation(iim->blend_prog, "instant"), instant);
    run_lists(iim, (list_pass){3, iim->ops_buf, 7, pend->ops, pend->op_count},
              (list_pass){1, iim->list_buf, 3, (const int32_t *)iim->list, iim->list_count});
    if (atlas_pass) {
        glUniform1i(glGetUniformLocation(iim->blend_prog, "mode"), 0);
        glDispatchCompute((GLuint)(iim->width + 7) / 8, (GLuint)(iim->height + 7) / 8, 1);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    }
    /* the cells mode 1 committed rebased (mode 4, uploaded there) and the waiting cells' estimates (2) */
    uint32_t rebased = iim->set.spread > 0 && !instant ? iim->list_count : 0;
    run_lists(iim, (list_pass){4, iim->list_buf, 3, NULL, rebased},
              (list_pass){2, iim->redraw_buf, 5, pend->redraw, pend->redraw_count});
    iim->list_count = 0;
    clear_spent(iim);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    lm_iim_sched_end_frame(&iim->sched);
    return lm_gl_check("IIM blend (iim_blend)", err);
}

lm_status lm_iim_scale(lm_iim *iim, const lm_atlas *a, const float *factor, const float *add, uint8_t *scaled,
                       lm_error *err)
{
    memset(scaled, 0, (size_t)iim->sched.surface_count);
    for (uint32_t i = 0; i < a->texel_count; i++)
        scaled[a->texels[i].surface] |= factor[3 * i] != 1.0f || factor[3 * i + 1] != 1.0f || factor[3 * i + 2] != 1.0f ||
                                        (add && (add[3 * i] != 0.0f || add[3 * i + 1] != 0.0f || add[3 * i + 2] != 0.0f));
    for (int k = 0; k < iim->sched.surface_count; k++)
        iim->version[k] += scaled[k];
    for (uint32_t i = 0; i < a->texel_count; i++) { /* the estimates of their own scale with what they add to */
        float *cell = iim->sight + 4 * ((size_t)a->texels[i].y * a->width + a->texels[i].x);
        for (int c = 0; c < 3 && cell[3] != 0.0f; c++)
            cell[c] *= factor[3 * i + c];
        if (cell[3] != 0.0f)
            sight_touched(iim, (int)a->texels[i].x, (int)a->texels[i].y);
    }
    if (!iim->blend_prog)
        return LM_OK;
    if (!iim->scale_prog) {
        lm_status st = lm_gl_compute_program("iim_scale", lm_glsl_iim_scale_cs, &iim->scale_prog, err);
        if (st != LM_OK)
            return st;
        glGenBuffers(1, &iim->factor_buf);
    }
    size_t cells = (size_t)a->width * a->height, n = cells ? cells : 1;
    float *f4 = malloc(sizeof *f4 * 8 * n); /* per cell: the factor, then the addition (rgb, one unused) */
    if (!f4)
        return lm_fail(err, LM_ERR_NOMEM, "IIM: no memory to scale %zu cells", cells);
    for (size_t c = 0; c < 8 * n; c++)
        f4[c] = c % 8 < 4 ? 1.0f : 0.0f;
    for (uint32_t i = 0; i < a->texel_count; i++) {
        float *cell = f4 + 8 * ((size_t)a->texels[i].y * a->width + a->texels[i].x);
        memcpy(cell, factor + 3 * (size_t)i, 3 * sizeof *f4);
        if (add)
            memcpy(cell + 4, add + 3 * (size_t)i, 3 * sizeof *f4);
    }
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, iim->factor_buf);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof *f4 * 8 * n), f4, GL_DYNAMIC_DRAW);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    free(f4);
    glUseProgram(iim->scale_prog);
    glUniform2i(glGetUniformLocation(iim->scale_prog, "size"), iim->width, iim->height);
    unsigned *tex[IIM_TEXTURES];
    textures(iim, tex);
    for (int i = 0; i < IIM_TEXTURES; i++)
        glBindImageTexture((GLuint)i, *tex[i], 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, iim->surface_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, iim->factor_buf);
    glDispatchCompute((GLuint)(iim->width + 7) / 8, (GLuint)(iim->height + 7) / 8, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    return lm_gl_check("IIM scale (iim_scale)", err);
}

lm_status lm_iim_clear(lm_iim *iim, const lm_atlas *a, lm_error *err)
{
    float *zero = calloc(3 * (size_t)a->texel_count + 3, sizeof *zero);
    uint8_t *scaled = malloc((size_t)iim->sched.surface_count + 1);
    lm_status st = zero && scaled ? lm_iim_scale(iim, a, zero, NULL, scaled, err)
                                  : lm_fail(err, LM_ERR_NOMEM, "IIM: no memory to clear %u texels", a->texel_count);
    free(zero);
    free(scaled);
    return st;
}

/* One pass over the window win: every invalid texel with valid same-surface 4-neighbours in it gets
 * their mean (read from the state before the pass, so the result does not depend on visiting order).
 * rgba and valid hold the window's cells. */
static uint32_t fill_pass(const lm_atlas *a, const int win[4], float *rgba, uint8_t *valid, uint8_t *next)
{
    static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    const int w = win[2], h = win[3];
    uint32_t filled = 0;
    memcpy(next, valid, (size_t)w * h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t c = (size_t)y * w + x;
            int i = a->texel_index[(size_t)(win[1] + y) * a->width + (win[0] + x)];
            if (i < 0 || valid[c])
                continue;
            float sum[3] = {0, 0, 0};
            int n = 0;
            for (int k = 0; k < 4; k++) {
                int xx = x + dx[k], yy = y + dy[k];
                if (xx < 0 || yy < 0 || xx >= w || yy >= h)
                    continue;
                size_t cc = (size_t)yy * w + xx;
                int j = a->texel_index[(size_t)(win[1] + yy) * a->width + (win[0] + xx)];
                if (j < 0 || !valid[cc] || a->texels[j].surface != a->texels[i].surface)
                    continue;
                for (int ch = 0; ch < 3; ch++)
                    sum[ch] += rgba[4 * cc + ch];
                n++;
            }
            if (!n)
                continue;
            float *o = rgba + 4 * c;
            for (int ch = 0; ch < 3; ch++)
                o[ch] = sum[ch] / (float)n;
            o[3] = 0.0f;
            next[c] = 1;
            filled++;
        }
    memcpy(valid, next, (size_t)w * h);
    return filled;
}

uint32_t lm_iim_fill_invalid_window(const lm_atlas *a, float *rgba, float limit, const int win[4])
{
    size_t n = (size_t)win[2] * win[3];
    uint8_t *valid = malloc(n + 1), *next = malloc(n + 1);
    uint32_t left = 0;
    if (valid && next) {
        for (int y = 0; y < win[3]; y++)
            for (int x = 0; x < win[2]; x++) {
                size_t c = (size_t)y * win[2] + x;
                int i = a->texel_index[(size_t)(win[1] + y) * a->width + (win[0] + x)];
                valid[c] = i < 0 || !(rgba[4 * c + 3] > limit); /* gutters: nothing to fill */
                left += !valid[c];
            }
        uint32_t f;
        while (left && (f = fill_pass(a, win, rgba, valid, next)) > 0)
            left -= f;
    }
    free(valid);
    free(next);
    lm_atlas_dilate_window(a, rgba, 4, lm_atlas_dilate_reach(a), win);
    return left;
}

uint32_t lm_iim_fill_invalid(const lm_atlas *a, float *rgba, float limit)
{
    const int whole[4] = {0, 0, a->width, a->height};
    return lm_iim_fill_invalid_window(a, rgba, limit, whole);
}
