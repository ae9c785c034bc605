/* The per-pixel photon gathers on the GPU (photon_gather.h): buffers, the order of the passes, limits;
 * the shaders are the compute shaders of glsl/. */
#include "photon_gather.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../core/timing.h"
#include "../../core/vecmath.h"
#include "../gl/gl_api.h"
#include "../gl/gl_shader.h"
#include "../gl/offscreen.h"
#include "glsl.h"

enum {
    P_BOUNDS, P_INSERT_TILES, P_INSERT_CELLS, P_SCAN, P_GATHER_TILES, P_GATHER_CELLS, P_GATHER_ALL, P_FINISH, P_RESOLVE,
    P_COUNT
};
enum { B_RECORDS, B_BOUNDS, B_COUNTS, B_OFFSETS, B_LIST, B_TOTALS, B_ACC, B_COUNT }; /* also the binding points */

#define INSERT_GROUP 64
#define MAX_GROUPS 65535u
/* llvmpipe ends a shader invocation's loops after 65,535 iterations in all (its loop limiter, shared by
 * every loop of the shader), which would silently drop the photons past it: a per-pixel loop over a long
 * list, or a photon's loop over the tiles of a large screen. So each pass is split into windows whose
 * loops stay under this many iterations, one dispatch each, the pixels' sums carried between them (a GPU
 * needs one window for any ordinary frame). */
#define WINDOW_ITERATIONS 30000u
#define FIXED_UNIT 1099511627776.0 /* 2^40: the brightest possible term in the fixed-point sums */

struct lm_photon_gather {
    lm_photon_gather_settings set;
    GLuint prog[P_COUNT];
    GLuint buf[B_COUNT];
    size_t cap[B_COUNT];         /* bytes allocated per buffer */
    uint32_t records, live;      /* records held on the GPU, those not empty */
    int top_exponent;            /* the largest flux exponent among them (photon_records.h's e), -1000: none */
    GLuint e_tex;
    int width, height;           /* of e_tex and the last run */
    float radius;                /* of the last run */
    int k;                       /* of the last run (1 but for the stochastic tiled gather) */
};

void lm_photon_gather_settings_default(lm_photon_gather_settings *s)
{
    s->kind = LM_PHOTON_GATHER_TILED;
    s->tile = 16;
    s->chunk = 256;
    s->stochastic = 1;
}

int lm_photon_gather_settings_check(const lm_photon_gather_settings *s, lm_error *err)
{
    if (s->kind < LM_PHOTON_GATHER_TILED || s->kind > LM_PHOTON_GATHER_BRUTEFORCE)
        return lm_fail(err, LM_ERR_INVALID, "photon gather: unknown kind %d", s->kind), 0;
    if (s->tile != 4 && s->tile != 8 && s->tile != 16 && s->tile != 32)
        return lm_fail(err, LM_ERR_INVALID, "photon gather: tile %d pixels (4, 8, 16 or 32)", s->tile), 0;
    if (s->chunk < 64 || s->chunk > 512)
        return lm_fail(err, LM_ERR_INVALID, "photon gather: chunk %d records (64 to 512: shared memory)", s->chunk), 0;
    if (s->stochastic < 1 || s->stochastic > 4)
        return lm_fail(err, LM_ERR_INVALID, "photon gather: stochastic k = %d (1 to 4)", s->stochastic), 0;
    return 1;
}

static lm_status compile(const lm_photon_gather_settings *s, const char *name, const char *body, GLuint *prog,
                         lm_error *err)
{
    size_t n = 256 + strlen(body);
    char *src = malloc(n);
    if (!src)
        return lm_fail(err, LM_ERR_NOMEM, "photon gather: no memory for a shader");
    snprintf(src, n, "#version 450 core\n#define TILE %d\n#define CHUNK %d\n#define LIMIT %uu\n%s", s->tile, s->chunk,
             LM_PHOTON_GATHER_MAX_ENTRIES, body);
    lm_status st = lm_gl_compute_program(name, src, prog, err);
    free(src);
    return st;
}

lm_status lm_photon_gather_create(const lm_photon_gather_settings *s, lm_photon_gather **out, lm_error *err)
{
    *out = NULL;
    lm_photon_gather_settings def;
    if (!s) {
        lm_photon_gather_settings_default(&def);
        s = &def;
    }
    if (!lm_photon_gather_settings_check(s, err))
        return err ? err->status : LM_ERR_INVALID;
    lm_photon_gather *g = calloc(1, sizeof *g);
    if (!g)
        return lm_fail(err, LM_ERR_NOMEM, "photon gather: no memory");
    g->set = *s;
    g->top_exponent = -1000;
    g->k = 1;
    static const struct {
        const char *name;
        const char *body;
    } progs[P_COUNT] = {
        {"photon_gather_bounds", lm_glsl_tile_bounds_cs},   {"photon_gather_insert_tiles", lm_glsl_insert_tiles_cs},
        {"photon_gather_insert_cells", lm_glsl_insert_cells_cs}, {"photon_gather_scan", lm_glsl_scan_cs},
        {"photon_gather_tiles", lm_glsl_gather_tiles_cs},   {"photon_gather_cells", lm_glsl_gather_cells_cs},
        {"photon_gather_all", lm_glsl_gather_all_cs},       {"photon_gather_finish", lm_glsl_finish_cs},
        {"photon_gather_resolve", lm_glsl_resolve_cs},
    };
    lm_status st = LM_OK;
    for (int i = 0; st == LM_OK && i < P_COUNT; i++)
        st = compile(s, progs[i].name, progs[i].body, &g->prog[i], err);
    glGenBuffers(B_COUNT, g->buf);
    glGenTextures(1, &g->e_tex);
    if (st == LM_OK)
        st = lm_gl_check("photon gather: create", err);
    if (st != LM_OK) {
        lm_photon_gather_free(g);
        return st;
    }
    *out = g;
    return LM_OK;
}

void lm_photon_gather_free(lm_photon_gather *g)
{
    if (!g)
        return;
    for (int i = 0; i < P_COUNT; i++)
        if (g->prog[i])
            glDeleteProgram(g->prog[i]);
    glDeleteBuffers(B_COUNT, g->buf);
    glDeleteTextures(1, &g->e_tex);
    free(g);
}

/* Buffer b holds at least `bytes` (contents kept only when it did already). */
static void ensure(lm_photon_gather *g, int b, size_t bytes)
{
    if (bytes < 16)
        bytes = 16;
    if (g->cap[b] >= bytes)
        return;
    size_t grown = g->cap[b] + g->cap[b] / 2;
    g->cap[b] = bytes > grown ? bytes : grown;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->buf[b]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)g->cap[b], NULL, GL_DYNAMIC_DRAW);
}

static void zero(lm_photon_gather *g, int b)
{
    const uint32_t z = 0;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->buf[b]);
    glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &z);
}

lm_status lm_photon_gather_set_records(lm_photon_gather *g, const lm_photon_records *r, lm_photon_gather_stats *st,
                                       lm_error *err)
{
    double t0 = lm_now();
    const size_t bytes = sizeof(lm_photon_record);
    uint32_t pages = 0;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->buf[B_RECORDS]);
    if (r->count != g->records || g->cap[B_RECORDS] < (size_t)r->count * bytes) {
        ensure(g, B_RECORDS, (size_t)r->count * bytes);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->buf[B_RECORDS]);
        if (r->count)
            glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)((size_t)r->count * bytes), r->rec);
        pages = r->pages;
    } else {
        for (uint32_t p = 0; p < r->pages; p++) {
            if (!r->dirty[p])
                continue;
            size_t first = (size_t)p * LM_RECORD_PAGE, n = r->count - first < LM_RECORD_PAGE ? r->count - first
                                                                                              : LM_RECORD_PAGE;
            glBufferSubData(GL_SHADER_STORAGE_BUFFER, (GLintptr)(first * bytes), (GLsizeiptr)(n * bytes), r->rec + first);
            pages++;
        }
    }
    g->records = r->count;
    g->live = r->live;
    g->top_exponent = r->top_exponent;
    if (st) {
        st->records = g->records, st->records_live = g->live;
        st->pages_uploaded = pages;
        st->t_upload = lm_now() - t0;
    }
    return lm_gl_check("photon gather: records upload", err);
}

/* The uniforms every gather program shares (glsl/photon_common.glsl). */
static void common_uniforms(const lm_photon_gather *g, GLuint p)
{
    float radius = g->radius;
    /* the largest term is the brightest channel (under 2^top) times kappa (at most c = 1/5) */
    double top = ldexp(1.0, g->top_exponent) * 0.2;
    glUseProgram(p);
    glUniform1f(glGetUniformLocation(p, "radius"), radius);
    glUniform1f(glGetUniformLocation(p, "radius2"), radius * radius);
    glUniform1f(glGetUniformLocation(p, "to_fixed"), g->top_exponent > -1000 ? (float)(FIXED_UNIT / top) : 1.0f);
    glUniform1i(glGetUniformLocation(p, "kd_tex"), 0);
    glUniform1i(glGetUniformLocation(p, "g_tex"), 1);
}

static void bind_buffers(const lm_photon_gather *g)
{
    for (int b = 0; b < B_COUNT; b++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)b, g->buf[b]);
}

static void bind_gbuffer(unsigned kd_tex, unsigned g_tex)
{
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, kd_tex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, g_tex);
    glActiveTexture(GL_TEXTURE0);
}

/* One insert program over every record (fill 0: counts, 1: the lists), in dispatches of at most 65,535
 * groups, and for the tiles in windows of `rows` tile rows (tile_rows of them; 0: the cells, no rows). */
static void insert_pass(lm_photon_gather *g, GLuint p, int fill, int rows, int tile_rows)
{
    glUseProgram(p);
    glUniform1i(glGetUniformLocation(p, "fill"), fill);
    glUniform1ui(glGetUniformLocation(p, "n_records"), g->records);
    glUniform1i(glGetUniformLocation(p, "rows"), rows);
    for (int row0 = 0; row0 < (tile_rows ? tile_rows : 1); row0 += rows ? rows : 1) {
        glUniform1i(glGetUniformLocation(p, "row0"), row0);
        for (uint32_t base = 0; base < g->records; base += MAX_GROUPS * INSERT_GROUP) {
            uint32_t n = g->records - base < MAX_GROUPS * INSERT_GROUP ? g->records - base : MAX_GROUPS * INSERT_GROUP;
            glUniform1ui(glGetUniformLocation(p, "base"), base);
            glDispatchCompute((n + INSERT_GROUP - 1) / INSERT_GROUP, 1, 1);
        }
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    }
}

/* Count, check the total against the limit, prefix-sum, fill: the lists of `segments` segments (for the
 * tiles: tiles_x x tile_rows tiles, inserted in row windows; tile_rows 0: the cells). *longest: the most
 * entries of one segment. */
static lm_status build_lists(lm_photon_gather *g, GLuint insert, uint32_t segments, int tiles_x, int tile_rows,
                             uint32_t *longest, lm_photon_gather_stats *st, lm_error *err)
{
    int rows = tile_rows ? (int)(WINDOW_ITERATIONS / (uint32_t)tiles_x) : 0;
    rows = tile_rows && rows < 1 ? 1 : rows;
    ensure(g, B_COUNTS, 4 * (size_t)segments);
    ensure(g, B_OFFSETS, 4 * ((size_t)segments + 1));
    ensure(g, B_TOTALS, 12);
    zero(g, B_COUNTS);
    zero(g, B_TOTALS);
    bind_buffers(g);
    insert_pass(g, insert, 0, rows, tile_rows);
    uint32_t totals[3];
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->buf[B_TOTALS]);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof totals, totals);
    if (totals[1])
        return lm_fail(err, LM_ERR_UNSUPPORTED,
                       "photon gather: the lists would hold more than %u entries (%u photons of radius %g over a "
                       "%d x %d frame); use a smaller frame, fewer photons or a smaller radius",
                       LM_PHOTON_GATHER_MAX_ENTRIES, g->live, (double)g->radius, g->width, g->height);
    glUseProgram(g->prog[P_SCAN]);
    glUniform1ui(glGetUniformLocation(g->prog[P_SCAN], "n"), segments);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    ensure(g, B_LIST, 4 * (size_t)totals[0]);
    zero(g, B_COUNTS);
    bind_buffers(g);
    insert_pass(g, insert, 1, rows, tile_rows);
    *longest = totals[2];
    if (st)
        st->entries = totals[0];
    return LM_OK;
}

static lm_status ensure_target(lm_photon_gather *g, int w, int h, lm_error *err)
{
    if (g->width == w && g->height == h)
        return LM_OK;
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    if (w < 1 || h < 1 || w > max_size || h > max_size)
        return lm_fail(err, LM_ERR_UNSUPPORTED, "photon gather: a %d x %d frame (1 to %d pixels a side here)", w, h, max_size);
    glDeleteTextures(1, &g->e_tex);
    glGenTextures(1, &g->e_tex);
    glBindTexture(GL_TEXTURE_2D, g->e_tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, w, h);
    g->width = w, g->height = h;
    return lm_gl_check("photon gather: target", err);
}

static lm_status run_tiled(lm_photon_gather *g, const lm_view *view, unsigned frame, double *t_mid,
                           lm_photon_gather_stats *st, lm_error *err)
{
    const int T = g->set.tile, k = g->set.stochastic;
    const int tx = (g->width + T - 1) / T, ty = (g->height + T - 1) / T;
    const uint32_t segments = (uint32_t)tx * (uint32_t)ty * (uint32_t)(k * k);
    float vp[16];
    lm_mat4_mul(vp, view->proj, view->view);
    const float vrow2[4] = {view->view[2], view->view[6], view->view[10], view->view[14]};
    ensure(g, B_BOUNDS, 8 * (size_t)tx * (size_t)ty);
    GLuint p = g->prog[P_BOUNDS];
    common_uniforms(g, p);
    glUniform4fv(glGetUniformLocation(p, "vrow2"), 1, vrow2);
    glUniform2i(glGetUniformLocation(p, "size"), g->width, g->height);
    glUniform1i(glGetUniformLocation(p, "tiles_x"), tx);
    glDispatchCompute((GLuint)tx, (GLuint)ty, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    p = g->prog[P_INSERT_TILES];
    common_uniforms(g, p);
    glUniformMatrix4fv(glGetUniformLocation(p, "vp"), 1, GL_FALSE, vp);
    glUniform4fv(glGetUniformLocation(p, "vrow2"), 1, vrow2);
    glUniform2i(glGetUniformLocation(p, "size"), g->width, g->height);
    glUniform1i(glGetUniformLocation(p, "tiles_x"), tx);
    glUniform1i(glGetUniformLocation(p, "tiles_y"), ty);
    glUniform1i(glGetUniformLocation(p, "classes"), k * k);
    uint32_t longest = 0;
    lm_status s = build_lists(g, p, segments, tx, ty, &longest, st, err);
    if (s != LM_OK)
        return s;
    if (st) {
        st->tiles = tx * ty;
        st->tiles_lit = 0;
        float *b = malloc(8 * (size_t)tx * (size_t)ty);
        if (b) {
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->buf[B_BOUNDS]);
            glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(8 * (size_t)tx * (size_t)ty), b);
            for (int i = 0; i < tx * ty; i++)
                st->tiles_lit += b[2 * i] <= b[2 * i + 1];
            free(b);
        }
    }
    *t_mid = lm_now();
    /* a round: its loads (CHUNK over the tile's pixels), the chunk's part read, the loop itself */
    const uint32_t part = (uint32_t)(g->set.chunk / (k * k)), rounds = (longest + part - 1) / part;
    const uint32_t per_round = 1 + part + (uint32_t)(g->set.chunk + T * T - 1) / (uint32_t)(T * T);
    const uint32_t window = WINDOW_ITERATIONS / per_round > 0 ? WINDOW_ITERATIONS / per_round : 1;
    p = g->prog[P_GATHER_TILES];
    common_uniforms(g, p);
    glUniform2i(glGetUniformLocation(p, "size"), g->width, g->height);
    glUniform1i(glGetUniformLocation(p, "tiles_x"), tx);
    glUniform1i(glGetUniformLocation(p, "k"), k);
    glUniform1i(glGetUniformLocation(p, "frame"), (int)(frame % (unsigned)(k * k)));
    glUniform1ui(glGetUniformLocation(p, "round_count"), window);
    for (uint32_t r = 0; r < rounds; r += window) {
        glUniform1ui(glGetUniformLocation(p, "round0"), r);
        glDispatchCompute((GLuint)tx, (GLuint)ty, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    return LM_OK;
}

static lm_status run_cells(lm_photon_gather *g, double *t_mid, lm_photon_gather_stats *st, lm_error *err)
{
    uint32_t buckets = 1024;
    while (buckets < 2 * g->live && buckets < (1u << 26))
        buckets *= 2;
    GLuint p = g->prog[P_INSERT_CELLS];
    common_uniforms(g, p);
    glUniform1f(glGetUniformLocation(p, "cell"), 2.0f * g->radius);
    glUniform1ui(glGetUniformLocation(p, "buckets"), buckets);
    uint32_t longest = 0;
    lm_status s = build_lists(g, p, buckets, 0, 0, &longest, st, err);
    if (s != LM_OK)
        return s;
    *t_mid = lm_now();
    const uint32_t window = WINDOW_ITERATIONS / 8 - 64; /* each of up to 8 buckets, and their loops */
    p = g->prog[P_GATHER_CELLS];
    common_uniforms(g, p);
    glUniform1f(glGetUniformLocation(p, "cell"), 2.0f * g->radius);
    glUniform1ui(glGetUniformLocation(p, "buckets"), buckets);
    glUniform2i(glGetUniformLocation(p, "size"), g->width, g->height);
    glUniform1ui(glGetUniformLocation(p, "entry_count"), window);
    for (uint32_t e = 0; e < longest; e += window) {
        glUniform1ui(glGetUniformLocation(p, "entry0"), e);
        glDispatchCompute((GLuint)(g->width + 7) / 8, (GLuint)(g->height + 7) / 8, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    return LM_OK;
}

static void run_all(lm_photon_gather *g, double *t_mid)
{
    GLuint p = g->prog[P_GATHER_ALL];
    common_uniforms(g, p);
    glUniform2i(glGetUniformLocation(p, "size"), g->width, g->height);
    *t_mid = lm_now();
    for (uint32_t first = 0; first < g->records; first += WINDOW_ITERATIONS) {
        glUniform1ui(glGetUniformLocation(p, "first"), first);
        glUniform1ui(glGetUniformLocation(p, "count"),
                     g->records - first < WINDOW_ITERATIONS ? g->records - first : WINDOW_ITERATIONS);
        glDispatchCompute((GLuint)(g->width + 7) / 8, (GLuint)(g->height + 7) / 8, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
}

lm_status lm_photon_gather_run(lm_photon_gather *g, const lm_view *view, int w, int h, unsigned kd_tex,
                               unsigned g_tex, float radius, unsigned frame, lm_photon_gather_stats *st, lm_error *err)
{
    if (!(radius > 0.0f) || !isfinite(radius))
        return lm_fail(err, LM_ERR_INVALID, "photon gather: radius %g (must be positive)", (double)radius);
    double t0 = lm_now();
    if (st) { /* timed apart: the frame's earlier GL work (its direct light) still running */
        glFinish();
        double t = lm_now();
        st->t_wait = t - t0;
        t0 = t;
    }
    lm_status s = ensure_target(g, w, h, err);
    if (s != LM_OK)
        return s;
    g->radius = radius;
    g->k = g->set.kind == LM_PHOTON_GATHER_TILED ? g->set.stochastic : 1;
    ensure(g, B_RECORDS, sizeof(lm_photon_record));
    ensure(g, B_ACC, 24 * (size_t)w * (size_t)h);
    zero(g, B_ACC);
    if (st) {
        st->entries = 0;
        st->tiles = st->tiles_lit = 0;
    }
    bind_buffers(g);
    bind_gbuffer(kd_tex, g_tex);
    double t_mid = t0;
    if (g->set.kind == LM_PHOTON_GATHER_TILED)
        s = run_tiled(g, view, frame, &t_mid, st, err);
    else if (g->set.kind == LM_PHOTON_GATHER_HASHGRID)
        s = run_cells(g, &t_mid, st, err);
    else
        run_all(g, &t_mid);
    if (s == LM_OK) {
        GLuint p = g->prog[P_FINISH];
        common_uniforms(g, p);
        glUniform1f(glGetUniformLocation(p, "share"), (float)(g->k * g->k)); /* a pixel read 1/k^2 of them */
        glUniform2i(glGetUniformLocation(p, "size"), w, h);
        glBindImageTexture(0, g->e_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glDispatchCompute((GLuint)(w + 7) / 8, (GLuint)(h + 7) / 8, 1);
    }
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    if (st) { /* the work is timed to its end (the insert's to its count's read-back) */
        glFinish();
        st->t_insert = t_mid - t0;
        st->t_gather = lm_now() - t_mid;
    }
    glUseProgram(0);
    if (s == LM_OK)
        s = lm_gl_check("photon gather: run", err);
    return s;
}

lm_status lm_photon_gather_composite(lm_photon_gather *g, unsigned radiance_tex, unsigned kd_tex, unsigned g_tex,
                                     lm_error *err)
{
    if (!g->width)
        return lm_fail(err, LM_ERR_INVALID, "photon gather: composite before any run");
    GLuint p = g->prog[P_RESOLVE];
    bind_gbuffer(kd_tex, g_tex);
    common_uniforms(g, p);
    glUniform2i(glGetUniformLocation(p, "size"), g->width, g->height);
    glUniform1i(glGetUniformLocation(p, "k"), g->k);
    glBindImageTexture(0, g->e_tex, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
    glBindImageTexture(1, radiance_tex, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glDispatchCompute((GLuint)(g->width + 7) / 8, (GLuint)(g->height + 7) / 8, 1);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    glUseProgram(0);
    return lm_gl_check("photon gather: composite", err);
}

lm_status lm_photon_gather_read(lm_photon_gather *g, float *rgb, lm_error *err)
{
    int w = g->width, h = g->height;
    float *rgba = malloc(4 * (size_t)(w ? w : 1) * (size_t)(h ? h : 1) * sizeof *rgba);
    if (!rgba)
        return lm_fail(err, LM_ERR_NOMEM, "photon gather: no memory to read %d x %d", w, h);
    glBindTexture(GL_TEXTURE_2D, g->e_tex);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, rgba);
    lm_rgba_to_rgb_top_down(rgba, w, h, rgb);
    free(rgba);
    return lm_gl_check("photon gather: read", err);
}

void lm_photon_gather_size(const lm_photon_gather *g, int *w, int *h)
{
    *w = g->width;
    *h = g->height;
}
