/* IIM scheduling, double-buffered blending and invalid-texel filling (iim.h). */
#include "iim.h"

#include "gl_api.h"
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "../charts/atlas_dilate.h"
#include "gl_shader.h"
#include "hemicube.h"

#define NEVER (INT_MIN / 2)

/* Per texel: commit its surface (old = display, new = fresh), then display = mix(old, new, t), clamped
 * to [old, new] so rounding never leaves the interval. */
static const char *BLEND_CS =
    "#version 450 core\n"
    "layout(local_size_x = 8, local_size_y = 8) in;\n"
    "layout(binding = 0, rgba32f) uniform readonly image2D fresh;\n"
    "layout(binding = 1, rgba32f) uniform image2D old_map;\n"
    "layout(binding = 2, rgba32f) uniform image2D new_map;\n"
    "layout(binding = 3, rgba32f) uniform image2D display;\n"
    "layout(std430, binding = 0) readonly buffer Surfaces { int surf[]; };\n"
    "layout(std430, binding = 1) readonly buffer Params { vec2 param[]; }; /* commit, t */\n"
    "uniform ivec2 size;\n"
    "void main() {\n"
    "    ivec2 q = ivec2(gl_GlobalInvocationID.xy);\n"
    "    if (q.x >= size.x || q.y >= size.y) return;\n"
    "    int s = surf[q.y * size.x + q.x];\n"
    "    if (s < 0) return;\n"
    "    vec4 o = imageLoad(old_map, q), n = imageLoad(new_map, q);\n"
    "    if (param[s].x > 0.5) {\n"
    "        o = imageLoad(display, q); n = imageLoad(fresh, q);\n"
    "        imageStore(old_map, q, o); imageStore(new_map, q, n);\n"
    "    }\n"
    "    imageStore(display, q, clamp(mix(o, n, param[s].y), min(o, n), max(o, n)));\n"
    "}\n";

void lm_iim_settings_default(lm_iim_settings *s)
{
    s->texels_per_frame = LM_IIM_DEFAULT_TEXELS_PER_FRAME;
    s->blend_frames = 8;
    s->delta_threshold = 0.0;
}

static lm_status group_texels(lm_iim *iim, const lm_atlas *a, lm_error *err)
{
    int S = iim->surface_count;
    iim->surf_first = calloc((size_t)S + 1, sizeof *iim->surf_first);
    iim->surf_texels = malloc(sizeof *iim->surf_texels * (a->texel_count ? a->texel_count : 1));
    if (!iim->surf_first || !iim->surf_texels)
        return lm_fail(err, LM_ERR_NOMEM, "IIM: no memory for texel lists");
    for (uint32_t i = 0; i < a->texel_count; i++)
        iim->surf_first[a->texels[i].surface + 1]++;
    for (int s = 0; s < S; s++)
        iim->surf_first[s + 1] += iim->surf_first[s];
    uint32_t *fill = iim->cursor; /* borrowed as a write position, zeroed after */
    for (uint32_t i = 0; i < a->texel_count; i++) {
        int s = a->texels[i].surface;
        iim->surf_texels[iim->surf_first[s] + fill[s]++] = i;
    }
    memset(iim->cursor, 0, sizeof *iim->cursor * (size_t)(S ? S : 1));
    return LM_OK;
}

static lm_status init_gl(lm_iim *iim, const lm_atlas *a, lm_error *err)
{
    unsigned *tex[4] = {&iim->fresh_tex, &iim->old_tex, &iim->new_tex, &iim->display_tex};
    for (int i = 0; i < 4; i++)
        if (!(*tex[i] = lm_iim_texture_create(a->width, a->height)))
            return lm_fail(err, LM_ERR_BACKEND, "IIM: could not make a %dx%d RGBA32F texture", a->width, a->height);
    lm_status st = lm_gl_compute_program("iim_blend", BLEND_CS, &iim->blend_prog, err);
    if (st != LM_OK)
        return st;
    size_t n = (size_t)a->width * (size_t)a->height;
    int *surf = malloc(sizeof(int) * n);
    if (!surf)
        return lm_fail(err, LM_ERR_NOMEM, "IIM: no memory");
    for (size_t i = 0; i < n; i++)
        surf[i] = a->texel_index[i] < 0 ? -1 : a->texels[a->texel_index[i]].surface;
    GLuint bufs[2];
    glGenBuffers(2, bufs);
    iim->surface_buf = bufs[0], iim->params_buf = bufs[1];
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[0]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(int) * n), surf, GL_STATIC_DRAW);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[1]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(sizeof(float) * 2 * (size_t)(iim->surface_count + 1)), NULL,
                 GL_DYNAMIC_DRAW);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    free(surf);
    return lm_gl_check("IIM: blend buffers", err);
}

lm_status lm_iim_init(lm_iim *iim, const lm_atlas *a, const lm_iim_settings *set, int with_gl, lm_error *err)
{
    memset(iim, 0, sizeof *iim);
    iim->set = *set;
    iim->width = a->width, iim->height = a->height;
    iim->surface_count = a->surface_count;
    size_t S = (size_t)(a->surface_count ? a->surface_count : 1);
    iim->cursor = calloc(S, sizeof *iim->cursor);
    iim->last_done = malloc(S * sizeof *iim->last_done);
    iim->blend_start = malloc(S * sizeof *iim->blend_start);
    iim->commit = calloc(S, 1);
    iim->version = calloc(S, sizeof *iim->version);
    if (!iim->cursor || !iim->last_done || !iim->blend_start || !iim->commit || !iim->version) {
        lm_iim_free(iim);
        return lm_fail(err, LM_ERR_NOMEM, "IIM: no memory for %d surfaces", a->surface_count);
    }
    for (size_t s = 0; s < S; s++)
        iim->last_done[s] = -1, iim->blend_start[s] = NEVER;
    lm_status st = group_texels(iim, a, err);
    if (st == LM_OK && with_gl)
        st = init_gl(iim, a, err);
    if (st != LM_OK)
        lm_iim_free(iim);
    return st;
}

void lm_iim_free(lm_iim *iim)
{
    unsigned tex[4] = {iim->fresh_tex, iim->old_tex, iim->new_tex, iim->display_tex};
    for (int i = 0; i < 4; i++)
        lm_iim_texture_free(tex[i]);
    if (iim->blend_prog) {
        GLuint bufs[2] = {iim->surface_buf, iim->params_buf};
        glDeleteBuffers(2, bufs);
        glDeleteProgram(iim->blend_prog);
    }
    free(iim->surf_first);
    free(iim->surf_texels);
    free(iim->cursor);
    free(iim->last_done);
    free(iim->blend_start);
    free(iim->commit);
    free(iim->version);
    memset(iim, 0, sizeof *iim);
}

/* Order: larger delta_i first, then older (never refreshed counts as oldest), then lower id. */
static int before(const lm_iim *iim, const lm_photon_store *ps, int s, int t)
{
    double ds = ps->surfaces[s].delta_i, dt = ps->surfaces[t].delta_i;
    if (ds != dt)
        return ds > dt;
    long as = iim->last_done[s] < 0 ? LONG_MAX : (long)iim->frame - iim->last_done[s];
    long at = iim->last_done[t] < 0 ? LONG_MAX : (long)iim->frame - iim->last_done[t];
    if (as != at)
        return as > at;
    return s < t;
}

static void complete_surface(lm_iim *iim, lm_photon_store *ps, int s)
{
    iim->cursor[s] = 0;
    iim->last_done[s] = iim->frame;
    iim->commit[s] = 1;
    lm_photon_store_reset_delta_i(ps, s);
}

/* Hands out texels of surface s from its cursor; completes it when its last texel is out. */
static uint32_t take_texels(lm_iim *iim, lm_photon_store *ps, int s, uint32_t *out, uint32_t room)
{
    uint32_t first = iim->surf_first[s], count = iim->surf_first[s + 1] - first, n = 0;
    while (iim->cursor[s] < count && n < room)
        out[n++] = iim->surf_texels[first + iim->cursor[s]++];
    if (iim->cursor[s] == count)
        complete_surface(iim, ps, s);
    return n;
}

uint32_t lm_iim_schedule(lm_iim *iim, lm_photon_store *ps, uint32_t *out)
{
    int *cand = malloc(sizeof(int) * (size_t)(iim->surface_count ? iim->surface_count : 1));
    if (!cand)
        return 0;
    int nc = 0;
    for (int s = 0; s < iim->surface_count; s++) {
        if (iim->cursor[s] == 0 && !(ps->surfaces[s].delta_i > iim->set.delta_threshold))
            continue;
        int k = nc++; /* insertion sort: surface counts are small */
        while (k > 0 && before(iim, ps, s, cand[k - 1]))
            cand[k] = cand[k - 1], k--;
        cand[k] = s;
    }
    uint32_t budget = iim->set.texels_per_frame > 0 ? (uint32_t)iim->set.texels_per_frame : 0, n = 0;
    for (int i = 0; i < nc && n < budget; i++)
        n += take_texels(iim, ps, cand[i], out + n, budget - n);
    free(cand);
    return n;
}

uint32_t lm_iim_schedule_all(lm_iim *iim, lm_photon_store *ps, uint32_t *out)
{
    uint32_t n = 0;
    for (int s = 0; s < iim->surface_count; s++) {
        iim->cursor[s] = 0;
        n += take_texels(iim, ps, s, out + n, UINT32_MAX);
    }
    return n;
}

float lm_iim_blend_weight(const lm_iim *iim, int surface)
{
    if (iim->set.blend_frames <= 0)
        return 1.0f;
    float t = (float)((double)iim->frame - iim->blend_start[surface]) / (float)iim->set.blend_frames;
    return t < 1.0f ? t : 1.0f;
}

lm_status lm_iim_blend(lm_iim *iim, int instant, lm_error *err)
{
    int S = iim->surface_count;
    float *param = malloc(sizeof(float) * 2 * (size_t)(S + 1));
    if (!param)
        return lm_fail(err, LM_ERR_NOMEM, "IIM: no memory");
    int any_commit = 0, blending = 0;
    for (int s = 0; s < S; s++) {
        /* shown differently from the last frame: committed now, or last frame's weight was below 1 */
        if (iim->commit[s] || (double)iim->frame - 1 - iim->blend_start[s] < iim->set.blend_frames)
            iim->version[s]++;
        if (iim->commit[s])
            iim->blend_start[s] = instant ? NEVER : iim->frame;
        param[2 * s] = iim->commit[s] ? 1.0f : 0.0f;
        param[2 * s + 1] = lm_iim_blend_weight(iim, s);
        any_commit |= iim->commit[s];
        blending |= param[2 * s + 1] < 1.0f;
        iim->commit[s] = 0;
    }
    if (!any_commit && iim->settled) { /* the last pass already wrote every final value */
        free(param);
        iim->frame++;
        return LM_OK;
    }
    iim->settled = !blending;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, iim->params_buf);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(sizeof(float) * 2 * (size_t)S), param);
    free(param);
    glUseProgram(iim->blend_prog);
    glUniform2i(glGetUniformLocation(iim->blend_prog, "size"), iim->width, iim->height);
    const unsigned tex[4] = {iim->fresh_tex, iim->old_tex, iim->new_tex, iim->display_tex};
    for (int i = 0; i < 4; i++)
        glBindImageTexture((GLuint)i, tex[i], 0, GL_FALSE, 0, i ? GL_READ_WRITE : GL_READ_ONLY, GL_RGBA32F);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, iim->surface_buf);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, iim->params_buf);
    glDispatchCompute((GLuint)(iim->width + 7) / 8, (GLuint)(iim->height + 7) / 8, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    iim->frame++;
    return lm_gl_check("IIM blend (iim_blend)", err);
}

/* One pass: every invalid texel with valid same-surface 4-neighbours gets their mean (read from the
 * state before the pass, so the result does not depend on visiting order). */
static uint32_t fill_pass(const lm_atlas *a, float *rgba, uint8_t *valid, uint8_t *next)
{
    static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    uint32_t filled = 0;
    memcpy(next, valid, a->texel_count);
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        if (valid[i])
            continue;
        float sum[3] = {0, 0, 0};
        int n = 0;
        for (int k = 0; k < 4; k++) {
            int x = t->x + dx[k], y = t->y + dy[k];
            if (x < 0 || y < 0 || x >= a->width || y >= a->height)
                continue;
            int j = a->texel_index[y * a->width + x];
            if (j < 0 || !valid[j] || a->texels[j].surface != t->surface)
                continue;
            for (int c = 0; c < 3; c++)
                sum[c] += rgba[4 * ((size_t)y * a->width + x) + c];
            n++;
        }
        if (!n)
            continue;
        float *o = rgba + 4 * ((size_t)t->y * a->width + t->x);
        for (int c = 0; c < 3; c++)
            o[c] = sum[c] / (float)n;
        o[3] = 0.0f;
        next[i] = 1;
        filled++;
    }
    memcpy(valid, next, a->texel_count);
    return filled;
}

uint32_t lm_iim_fill_invalid(const lm_atlas *a, float *rgba, float limit)
{
    uint8_t *valid = malloc(a->texel_count + 1), *next = malloc(a->texel_count + 1);
    uint32_t left = 0;
    if (valid && next) {
        for (uint32_t i = 0; i < a->texel_count; i++) {
            const lm_texel *t = &a->texels[i];
            valid[i] = !(rgba[4 * ((size_t)t->y * a->width + t->x) + 3] > limit);
            left += !valid[i];
        }
        uint32_t f;
        while (left && (f = fill_pass(a, rgba, valid, next)) > 0)
            left -= f;
    }
    free(valid);
    free(next);
    lm_atlas_dilate_gutters(a, rgba, 4);
    return left;
}
