/* Direct light per pixel (direct.h): every punctual light's shadow map (cached), then a first pass that
 * lays down depth and writes the emitted radiance, the indirect term and the first punctual light, then
 * one additive pass (depth test LEQUAL, no depth writes) per further light, into an RGBA32F target. A
 * scene without punctual lights gets an emission-only first pass. */
#include "direct.h"

#include "../gl/gl_api.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../core/log.h"
#include "../../core/vecmath.h"
#include "../../scene/sky.h"
#include "direct_mesh.h"
#include "../gl/gl_shader.h"
#include "../gl/offscreen.h"
#include "glsl.h"
#include "shadow_maps.h"
#include "sky_pass.h"

void lm_direct_settings_default(lm_direct_settings *s)
{
    s->map_size = 1024;
    s->cube_size = 512;
    s->pcf_radius = 0;
    s->normal_offset = 1.0f;
    s->slope_bias = 1.0f;
    s->max_slope = 10.0f;
    s->const_bias = 0.5f;
    s->shadows = 1;
    s->maps_per_update = 4;
    s->probe_lod = LM_DIRECT_PROBE_LOD;
}

typedef struct {
    GLint lpos, ldir, radiant, origin, cos_outer, spot_width, texel, map_size, light_vp;
    GLint view_proj, eye, view_dir, ortho_view, normal_offset, slope_bias, max_slope, const_bias, range, light_range;
    GLint map2d, mapcube, base_tex, lit, use_lit, turn, use_turn;
    GLint map_near[LM_VIEW_CASCADES], near_vp, near_texel, has_near;
} uniforms;

_Static_assert(LM_VIEW_CASCADES == 2, "glsl/direct_fs.glsl samples two view cascades, map_near0 and map_near1");

/* One punctual light's map and the caster geometry versions it was rendered over; for a directional
 * light also the maps fitted to the frame's view, the nearest quarter of its depth and all of it (a
 * cascade's tex 0: none). */
typedef struct {
    lm_shadow_map map;
    unsigned long static_version, dynamic_version;
    unsigned long stale_since; /* the update it went stale at, 0 while current */
    lm_shadow_map near[LM_VIEW_CASCADES];
    unsigned long near_static[LM_VIEW_CASCADES], near_dynamic[LM_VIEW_CASCADES];
} cached_map;

struct lm_direct {
    lm_direct_settings set;
    GLuint prog[3], first[3], emission; /* per light kind (point, spot, directional): additive light program,
                                         * first-pass program; the emission-only program */
    int glossy;                         /* the light programs have the glossy lobe (the scene has a glossy
                                         * material: scene_glossy) */
    uint32_t programs_version;          /* the scene's pass_version the light programs were last made or
                                         * found right for (a failed remake keeps the old: tried again) */
    GLint e_view_proj, e_lit, e_use_lit, e_turn, e_use_turn;
    uniforms u[3], uf[3];
    lm_direct_mesh mesh;
    lm_sky_pass sky;        /* a gradient or image sky behind everything */
    lm_shadow_renderer shadow;
    lm_frame_targets targets; /* the view's picture and the environment map faces' (lm_direct_draw_probe) */
    int cur;                /* the picture of the draw in progress: LM_FRAME_VIEW, _PROBE or _MIRROR */
    int drop[2];            /* vertices the draw in progress leaves out (lm_direct_draw_probe's node) */
    float clip[4];          /* the draw in progress keeps dot(clip, (p, 1)) >= 0 (a mirror's side); 0: all */
    cached_map *maps;       /* per emitter index */
    int map_count;
    unsigned long static_version;  /* bumped whenever a static shadow-casting node moves (an edit) */
    unsigned long dynamic_version; /* bumped whenever a dynamic shadow-casting node moves */
    long maps_rendered;
    long near_rendered;     /* view-fitted sun maps rendered (refresh_near_maps), apart from maps_rendered */
    int maps_left;          /* shadow maps this update may still re-render (-1: every stale one) */
    unsigned long updates;  /* lm_direct_begin_update calls, the clock of stale_since */
    int cube_now, map_now;  /* the map sides the live lights get now (fit_live_sizes) */
    int has_lightmap;       /* the mesh carries lightmap uvs (an atlas at lm_direct_create) */
    const lm_atlas *atlas;  /* that atlas (borrowed), for a rebuild of the mesh */
    unsigned indirect_tex;  /* the indirect term the first pass adds (0: none) */
    unsigned turn_tex[3];   /* the footprint texels' turns (lm_direct_set_indirect; 0: none) */
    unsigned coverage_tex;  /* else the photon gathers' kernel coverage it writes to kd's alpha (0: none) */
    int gbuffer;            /* the view's first pass writes the G-buffer (lm_direct_write_gbuffer) */
};

static void find_uniforms(GLuint p, uniforms *u)
{
#define LOC(name) u->name = glGetUniformLocation(p, #name)
    LOC(lpos); LOC(ldir); LOC(radiant); LOC(origin); LOC(cos_outer);
    LOC(spot_width); LOC(texel); LOC(map_size); LOC(light_vp); LOC(view_proj); LOC(eye); LOC(view_dir);
    LOC(ortho_view); LOC(normal_offset); LOC(slope_bias); LOC(max_slope); LOC(const_bias); LOC(range); LOC(light_range);
    LOC(map2d); LOC(mapcube); LOC(base_tex); LOC(lit); LOC(use_lit); LOC(turn); LOC(use_turn);
    LOC(near_vp); LOC(near_texel); LOC(has_near);
    u->map_near[0] = glGetUniformLocation(p, "map_near0");
    u->map_near[1] = glGetUniformLocation(p, "map_near1");
#undef LOC
}

/* A light's maps and the view's cascades given back (a zeroed map has none). */
static void free_cached_map(cached_map *c)
{
    lm_shadow_map_free(&c->map);
    for (int k = 0; k < LM_VIEW_CASCADES; k++)
        lm_shadow_map_free(&c->near[k]);
}

static int kind_of(const lm_emitter *e) { return e->kind == LM_EMIT_POINT ? 0 : e->kind == LM_EMIT_SPOT ? 1 : 2; }

/* A point, spot or directional light that still exists: a removed one lights nothing and keeps no map
 * (an added light's map, a cube of 6 x 512^2 floats and its layer, was kept after its removal). */
static int live_punctual(const lm_scene *s, const lm_emitter *e)
{
    return e->punctual && !lm_emitter_removed(s, e);
}

static void set_light_uniforms(const uniforms *u, const lm_scene *s, const lm_emitter *e, const cached_map *c)
{
    const lm_shadow_map *m = &c->map;
    int kind = kind_of(e);
    float cos_outer = -2.0f, width = 1.0f;
    if (kind == 1) { /* the same falloff as lm_spot_attenuation */
        const lm_light *l = &s->lights[e->light];
        cos_outer = cosf(l->outer_cone);
        width = fmaxf(1e-3f, cosf(l->inner_cone) - cos_outer);
    }
    glUniform3fv(u->lpos, 1, e->pos);
    float ldir[3]; /* as the map's dir, which a cube map leaves 0 */
    lm_v3_store(ldir, lm_normalize(lm_v3_load(e->dir)));
    glUniform3fv(u->ldir, 1, ldir);
    glUniform3fv(u->radiant, 1, e->radiant);
    glUniform3fv(u->origin, 1, m->p.origin);
    glUniform1f(u->cos_outer, cos_outer);
    glUniform1f(u->spot_width, width);
    glUniform1f(u->texel, m->p.texel);
    glUniform1f(u->map_size, (float)m->p.size);
    glUniform1f(u->range, m->p.range);
    glUniform1f(u->light_range, kind == 2 ? 0.0f : s->lights[e->light].range); /* lm_light_range_window's */
    glUniformMatrix4fv(u->light_vp, 1, GL_FALSE, m->p.light_vp);
    glActiveTexture(m->p.cube ? GL_TEXTURE1 : GL_TEXTURE0);
    glBindTexture(m->p.cube ? GL_TEXTURE_CUBE_MAP : GL_TEXTURE_2D, m->tex);
    int has[LM_VIEW_CASCADES];
    float vps[16 * LM_VIEW_CASCADES], texels[LM_VIEW_CASCADES];
    for (int k = 0; k < LM_VIEW_CASCADES; k++) {
        has[k] = c->near[k].tex != 0;
        memcpy(vps + 16 * k, c->near[k].p.light_vp, sizeof c->near[k].p.light_vp);
        texels[k] = c->near[k].p.texel;
        glActiveTexture(GL_TEXTURE5 + (GLenum)k);
        glBindTexture(GL_TEXTURE_2D, c->near[k].tex);
    }
    glUniform1iv(u->has_near, LM_VIEW_CASCADES, has);
    glUniformMatrix4fv(u->near_vp, LM_VIEW_CASCADES, GL_FALSE, vps);
    glUniform1fv(u->near_texel, LM_VIEW_CASCADES, texels);
    glActiveTexture(GL_TEXTURE0);
}

static void set_view_uniforms(const lm_direct *d, const uniforms *u, const lm_view *view)
{
    const lm_direct_settings *set = &d->set;
    float vp[16];
    lm_mat4_mul(vp, view->proj, view->view);
    glUniformMatrix4fv(u->view_proj, 1, GL_FALSE, vp);
    /* orthographic views (no perspective divide) look along one direction: towards the eye is the
     * view matrix's third row */
    const float towards_eye[3] = {view->view[2], view->view[6], view->view[10]};
    glUniform3fv(u->eye, 1, view->eye);
    glUniform3fv(u->view_dir, 1, towards_eye);
    glUniform1i(u->ortho_view, view->proj[11] == 0.0f && view->proj[15] != 0.0f);
    glUniform1f(u->normal_offset, set->normal_offset);
    glUniform1f(u->slope_bias, set->slope_bias);
    glUniform1f(u->max_slope, set->max_slope);
    glUniform1f(u->const_bias, set->const_bias);
    glUniform1i(u->map2d, 0);
    glUniform1i(u->mapcube, 1);
    glUniform1i(u->base_tex, 2);
    for (int k = 0; k < LM_VIEW_CASCADES; k++)
        glUniform1i(u->map_near[k], 5 + k);
}

/* The vertex ranges of glsl/vertex_ranges.glsl for prog: keep (0, 0: all), drop. */
static void set_ranges(GLuint prog, const int keep[2], const int drop[2])
{
    glUniform2i(glGetUniformLocation(prog, "keep"), keep[0], keep[1]);
    glUniform2i(glGetUniformLocation(prog, "drop"), drop[0], drop[1]);
}

static const int ALL[2] = {0, 0};

/* What the picture being drawn leaves out: a node's vertices (an environment face's own node) and what
 * lies behind the clip plane (a mirror's far side; GL_CLIP_DISTANCE0 is on only while one is drawn). */
static void set_left_out(const lm_direct *d, GLuint prog)
{
    set_ranges(prog, ALL, d->drop);
    glUniform4fv(glGetUniformLocation(prog, "clip_plane"), 1, d->clip);
}

/* The scene's triangles for the picture being drawn: an environment face's simplified (probe_lod). */
static void draw_scene(const lm_direct *d, GLuint prog)
{
    (d->cur == LM_FRAME_PROBE ? lm_direct_mesh_draw_lod : lm_direct_mesh_draw)(&d->mesh, prog);
}

static float lod_error(const lm_direct *d, const lm_scene *s) { return d->set.probe_lod * lm_scene_size(s); }

/* The indirect term's texture on unit 3 and the turn maps on units 8-10 for a first-pass program (lit,
 * use_lit, turn, use_turn: its uniforms). */
static void bind_indirect(const lm_direct *d, GLint lit, GLint use_lit, GLint turn, GLint use_turn)
{
    unsigned tex = !d->has_lightmap ? 0 : d->indirect_tex ? d->indirect_tex : d->coverage_tex;
    glUniform1i(use_lit, !tex ? 0 : d->indirect_tex ? 1 : 2);
    glUniform1i(lit, 3);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, tex);
    int turns = tex && d->indirect_tex && d->turn_tex[0];
    glUniform1i(use_turn, turns);
    static const GLint units[3] = {8, 9, 10};
    glUniform1iv(turn, 3, units);
    for (int c = 0; c < 3; c++) {
        glActiveTexture(GL_TEXTURE8 + (GLenum)c);
        glBindTexture(GL_TEXTURE_2D, turns ? d->turn_tex[c] : 0);
    }
    glActiveTexture(GL_TEXTURE0);
}

/* The first pass: clears, writes depth, the emitted radiance and the indirect term at each visible
 * surface's lightmap uv, and punctual emitter `light` (-1: none, an emission-only pass), into the
 * framebuffer's first `buffers` draw buffers (radiance, kd and, with 3, the G-buffer). */
static void first_pass(lm_direct *d, const lm_scene *s, const lm_emitters *em, int light, const lm_view *view,
                       int w, int h, int buffers)
{
    glViewport(0, 0, w, h);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_DEPTH_BUFFER_BIT);
    float sky[4] = {0.0f, 0.0f, 0.0f, 1.0f}; /* the background, in frames and reflections */
    lm_sky_mean(s, sky);
    glClearBufferfv(GL_COLOR, 0, sky);
    static const float nothing[4] = {0.0f, 0.0f, 0.0f, 1.0f}; /* kd and the G-buffer where nothing is seen */
    for (int b = 1; b < buffers; b++)
        glClearBufferfv(GL_COLOR, b, nothing);
    lm_sky_pass_draw(&d->sky, s, view->view, view->proj); /* by direction, where it varies */
    if (light < 0) {
        float vp[16];
        lm_mat4_mul(vp, view->proj, view->view);
        glUseProgram(d->emission);
        set_left_out(d, d->emission);
        glUniformMatrix4fv(d->e_view_proj, 1, GL_FALSE, vp);
        const float towards_eye[3] = {view->view[2], view->view[6], view->view[10]}; /* as set_view_uniforms */
        glUniform3fv(glGetUniformLocation(d->emission, "eye"), 1, view->eye);
        glUniform3fv(glGetUniformLocation(d->emission, "view_dir"), 1, towards_eye);
        glUniform1i(glGetUniformLocation(d->emission, "ortho_view"), view->proj[11] == 0.0f && view->proj[15] != 0.0f);
        glUniform1i(glGetUniformLocation(d->emission, "base_tex"), 2);
        bind_indirect(d, d->e_lit, d->e_use_lit, d->e_turn, d->e_use_turn);
        draw_scene(d, d->emission);
        return;
    }
    const lm_emitter *e = &em->e[light];
    const uniforms *u = &d->uf[kind_of(e)];
    GLuint prog = d->first[kind_of(e)];
    glUseProgram(prog);
    set_left_out(d, prog);
    set_view_uniforms(d, u, view);
    set_light_uniforms(u, s, e, &d->maps[light]);
    bind_indirect(d, u->lit, u->use_lit, u->turn, u->use_turn);
    draw_scene(d, prog);
}

/* Emitter i's map parameters now; returns 1 when its map is stale (made from other parameters or
 * before a caster moved, or never made). */
static int map_stale(const lm_direct *d, const lm_scene *s, const lm_emitter *e, int i, lm_shadow_params *p)
{
    const cached_map *c = &d->maps[i];
    lm_shadow_params_compute(p, s, e, e->kind == LM_EMIT_POINT ? d->cube_now : d->map_now);
    return !c->map.tex || memcmp(p, &c->map.p, sizeof *p) || c->static_version != d->static_version ||
           c->dynamic_version != d->dynamic_version;
}

static lm_status redraw_map(lm_direct *d, int i, const lm_shadow_params *p, lm_error *err)
{
    cached_map *c = &d->maps[i];
    lm_status st = lm_shadow_map_draw(&c->map, p, &d->shadow, &d->mesh.casters, d->mesh.static_caster_indices,
                                      c->static_version != d->static_version, d->mesh.dynamic_lo, d->mesh.dynamic_hi,
                                      err);
    c->static_version = d->static_version;
    c->dynamic_version = d->dynamic_version;
    c->stale_since = 0;
    d->maps_rendered++;
    d->maps_left -= d->maps_left > 0;
    return st;
}

/* How much a stale map's shadow matters: the light's irradiance at what moved (the dynamic casters' box,
 * or the scene's centre when a static caster moved or nothing dynamic casts), doubled for every update it
 * has waited, so that every stale map is redrawn in the end: a light 1,000 times dimmer there than the
 * others waits about 10 updates while things keep moving (growing linearly, a far light waited over 200). */
static double map_priority(const lm_direct *d, const lm_scene *s, const lm_emitter *e, int i)
{
    const float *r = e->radiant;
    double watts = 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2], d2 = 1.0;
    if (e->kind != LM_EMIT_DIRECTIONAL) {
        const float *lo = d->mesh.dynamic_lo, *hi = d->mesh.dynamic_hi;
        int box = lo[0] <= hi[0] && d->maps[i].static_version == d->static_version;
        d2 = 0.0;
        for (int a = 0; a < 3; a++) {
            double c = box ? 0.5 * (lo[a] + hi[a]) : 0.5 * (s->bounds_min[a] + s->bounds_max[a]);
            double half = box ? 0.5 * (hi[a] - lo[a]) : 0.0, dist = fabs(e->pos[a] - c) - half;
            d2 += dist > 0.0 ? dist * dist : 0.0;
        }
        double size = lm_scene_size(s);
        d2 = d2 > 1e-4 * size * size ? d2 : 1e-4 * size * size;
    }
    unsigned long age = d->updates - d->maps[i].stale_since;
    return ldexp(watts / d2, age < 900 ? (int)age : 900);
}

typedef struct {
    double key;
    int i;
    lm_shadow_params p;
} stale_map;

static int by_priority(const void *a, const void *b)
{
    const stale_map *x = a, *y = b;
    return x->key > y->key ? -1 : x->key < y->key ? 1 : x->i - y->i;
}

/* The stale shadow maps redrawn, within the update's budget (lm_direct_begin_update): a map never made is
 * always drawn (a light without one would light through walls); the others by priority, the rest keep
 * their last map (the shadow of what moved lags a few updates behind for the least of them). */
static lm_status refresh_maps(lm_direct *d, const lm_scene *s, const lm_emitters *em, lm_error *err)
{
    stale_map *list = NULL;
    int n = 0;
    lm_status st = LM_OK;
    for (int i = 0; st == LM_OK && i < em->count; i++) {
        cached_map *c = &d->maps[i];
        lm_shadow_params p;
        if (!live_punctual(s, &em->e[i])) {
            free_cached_map(c);
            c->stale_since = 0;
        } else if (!map_stale(d, s, &em->e[i], i, &p)) {
            c->stale_since = 0;
        } else if (!c->map.tex || d->maps_left < 0) {
            st = redraw_map(d, i, &p, err);
        } else {
            if (!list && !(list = malloc(sizeof *list * (size_t)em->count)))
                return lm_fail(err, LM_ERR_NOMEM, "direct_light: no memory for %d stale shadow maps", em->count);
            c->stale_since = c->stale_since ? c->stale_since : d->updates;
            list[n++] = (stale_map){map_priority(d, s, &em->e[i], i), i, p};
        }
    }
    if (n > 1)
        qsort(list, (size_t)n, sizeof *list, by_priority);
    for (int k = 0; st == LM_OK && k < n && d->maps_left > 0; k++)
        st = redraw_map(d, list[k].i, &list[k].p, err);
    free(list);
    return st;
}

/* The directional lights' maps fitted to the frame's view (lm_shadow_params_fit_view): the nearest
 * quarter of its depth into the scene and all of it, each made or dropped as the view asks (the near one
 * also when it would be no finer than the other), redrawn when its fit or a caster changed. A camera
 * moving inside one snap cell redraws nothing; a moving one redraws up to two maps a sun per update,
 * outside the update's map count (it is the frame's own view, not a light that may wait). */
static lm_status refresh_near_maps(lm_direct *d, const lm_scene *s, const lm_emitters *em, const lm_view *view,
                                   lm_error *err)
{
    lm_status st = LM_OK;
    float reach = lm_view_box_reach(view, s->bounds_min, s->bounds_max);
    for (int i = 0; st == LM_OK && i < em->count; i++) {
        cached_map *c = &d->maps[i];
        lm_shadow_params p[LM_VIEW_CASCADES];
        int fit[LM_VIEW_CASCADES];
        for (int k = 0; k < LM_VIEW_CASCADES; k++) {
            float depth = k + 1 < LM_VIEW_CASCADES ? ldexpf(reach, -2 * (LM_VIEW_CASCADES - 1 - k)) : 0.0f;
            fit[k] = c->map.tex && c->map.p.ortho && lm_shadow_params_fit_view(&p[k], &c->map.p, s, view, depth);
        }
        for (int k = 0; k + 1 < LM_VIEW_CASCADES; k++)
            fit[k] = fit[k] && !(fit[k + 1] && p[k].texel >= p[k + 1].texel);
        for (int k = 0; st == LM_OK && k < LM_VIEW_CASCADES; k++) {
            lm_shadow_map *m = &c->near[k];
            if (!fit[k]) {
                lm_shadow_map_free(m);
                continue;
            }
            if (m->tex && !memcmp(&p[k], &m->p, sizeof p[k]) && c->near_static[k] == d->static_version &&
                c->near_dynamic[k] == d->dynamic_version)
                continue;
            st = lm_shadow_map_draw(m, &p[k], &d->shadow, &d->mesh.casters, d->mesh.static_caster_indices,
                                    c->near_static[k] != d->static_version, d->mesh.dynamic_lo, d->mesh.dynamic_hi,
                                    err);
            c->near_static[k] = d->static_version;
            c->near_dynamic[k] = d->dynamic_version;
            d->near_rendered++;
        }
    }
    return st;
}

/* A further light: an additive pass over the laid-down depth (its shadow map is ready). */
static lm_status light_pass(lm_direct *d, const lm_scene *s, const lm_emitter *e, int i, const lm_view *view,
                            int w, int h, lm_error *err)
{
    glBindFramebuffer(GL_FRAMEBUFFER, lm_frame_targets_fbo(&d->targets, d->cur));
    glViewport(0, 0, w, h);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    GLuint prog = d->prog[kind_of(e)];
    glUseProgram(prog);
    set_left_out(d, prog);
    set_view_uniforms(d, &d->u[kind_of(e)], view);
    set_light_uniforms(&d->u[kind_of(e)], s, e, &d->maps[i]);
    draw_scene(d, prog);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    return lm_gl_check("direct_light: light pass", err);
}

/* The light program for one kind (0 point, 1 spot, 2 directional), PCF radius, pass (first or additive)
 * and whether any material is glossy. Compiling them as constants takes the branches on them out of
 * every pixel: about 20% of the light pass on llvmpipe for the kind; without a glossy material the
 * lobe's pow, which llvmpipe computes for every pixel of a draw with a glossy one in it, goes too. */
static lm_status light_program(int kind, int pcf, int first, int glossy, GLuint *prog, lm_error *err)
{
    size_t n = strlen(lm_glsl_direct_fs) + 128;
    char *fs = malloc(n);
    if (!fs)
        return lm_fail(err, LM_ERR_NOMEM, "direct_light: no memory for shader source");
    snprintf(fs, n, "#version 450 core\n#define KIND %d\n#define PCF %d\n#define FIRST %d\n#define GLOSSY %d\n%s", kind,
             pcf, first, glossy, lm_glsl_direct_fs);
    static const char *names[2][3] = {
        {"direct_light (point)", "direct_light (spot)", "direct_light (directional)"},
        {"direct_light (point, first pass)", "direct_light (spot, first pass)", "direct_light (directional, first pass)"}};
    lm_status st = lm_gl_program(names[first][kind], lm_glsl_direct_vs, fs, prog, err);
    free(fs);
    return st;
}

static void free_light_programs(lm_direct *d)
{
    for (int k = 0; k < 3; k++) {
        if (d->prog[k])
            glDeleteProgram(d->prog[k]);
        if (d->first[k])
            glDeleteProgram(d->first[k]);
        d->prog[k] = d->first[k] = 0;
    }
}

/* Every light program, made again (with or without the glossy lobe). */
static lm_status light_programs(lm_direct *d, int glossy, lm_error *err)
{
    free_light_programs(d);
    lm_status st = LM_OK;
    for (int k = 0; st == LM_OK && k < 3; k++) {
        if ((st = light_program(k, d->set.pcf_radius, 0, glossy, &d->prog[k], err)) == LM_OK)
            find_uniforms(d->prog[k], &d->u[k]);
        if (st == LM_OK && (st = light_program(k, d->set.pcf_radius, 1, glossy, &d->first[k], err)) == LM_OK)
            find_uniforms(d->first[k], &d->uf[k]);
    }
    d->glossy = st == LM_OK ? glossy : -1; /* -1: half made, made again at the next draw */
    return st;
}

/* Whether a material of the scene is glossy (its class can change only with lm_scene.pass_version). */
static int scene_glossy(const lm_scene *s)
{
    for (int m = 0; m < s->material_count; m++)
        if (s->materials[m].cls == LM_MAT_GLOSSY)
            return 1;
    return 0;
}

static int valid_settings(const lm_direct_settings *set)
{
    return set->map_size > 0 && set->cube_size > 0 && set->pcf_radius >= 0 && set->probe_lod >= 0.0f;
}

/* The 2D maps (whole-scene and the view's) a spot (0) or directional (1) light holds. */
static int maps_2d(int directional) { return directional ? 1 + LM_VIEW_CASCADES : 1; }

/* Shadow-map bytes for `points` point lights and `others` 2D maps at the given sides: a cube (6 faces) per
 * point light, a 2D map per spot light and 1 + LM_VIEW_CASCADES per directional one (the whole scene's and
 * the view's), each with its static layer (shadow_maps.h), 4 bytes a texel. */
static double shadow_bytes(int points, int others, int cube_size, int map_size)
{
    return 2.0 * 4.0 * (6.0 * cube_size * cube_size * points + (double)map_size * map_size * others);
}

/* The sides that fit LM_DIRECT_SHADOW_BUDGET: halved together down to LM_DIRECT_SHADOW_MIN_SIZE. */
static void fit_sizes(int points, int others, int *cube, int *map)
{
    while (shadow_bytes(points, others, *cube, *map) > LM_DIRECT_SHADOW_BUDGET &&
           (*cube > LM_DIRECT_SHADOW_MIN_SIZE || *map > LM_DIRECT_SHADOW_MIN_SIZE)) {
        *cube = *cube / 2 > LM_DIRECT_SHADOW_MIN_SIZE ? *cube / 2 : LM_DIRECT_SHADOW_MIN_SIZE;
        *map = *map / 2 > LM_DIRECT_SHADOW_MIN_SIZE ? *map / 2 : LM_DIRECT_SHADOW_MIN_SIZE;
    }
}

/* The shadow maps share LM_DIRECT_SHADOW_BUDGET: with many lights each map is made smaller (halved down to
 * LM_DIRECT_SHADOW_MIN_SIZE, said once) instead of asking for 12 MB a point light (1,000 point lights took
 * 13.5 GB and ended in "OpenGL error 0x0505"); a scene whose lights do not fit even then is refused. */
static lm_status fit_shadow_budget(const lm_scene *s, lm_direct *d, lm_error *err)
{
    int points = 0, others = 0;
    for (int l = 0; l < s->light_count; l++)
        if (!s->lights[l].removed)
            *(s->lights[l].type == LM_LIGHT_POINT ? &points : &others) +=
                maps_2d(s->lights[l].type == LM_LIGHT_DIRECTIONAL);
    int cube = d->set.cube_size, map = d->set.map_size;
    fit_sizes(points, others, &cube, &map);
    double mb = 1024.0 * 1024.0, need = shadow_bytes(points, others, cube, map);
    if (need > LM_DIRECT_SHADOW_BUDGET)
        return lm_fail(err, LM_ERR_NOMEM, "%s: %d lights need %.0f MB of shadow maps even at %d texels a side, more "
                       "than the %.0f MB they may take", s->path, s->light_count, need / mb, LM_DIRECT_SHADOW_MIN_SIZE,
                       LM_DIRECT_SHADOW_BUDGET / mb);
    if (cube != d->set.cube_size || map != d->set.map_size)
        lm_warn("%s: %d lights: shadow maps of %d (cube faces) and %d texels a side instead of %d and %d, so that "
                "they fit in %.0f MB; their shadows are softer", s->path, s->light_count, cube, map, d->set.cube_size,
                d->set.map_size, LM_DIRECT_SHADOW_BUDGET / mb);
    d->cube_now = cube, d->map_now = map;
    return LM_OK;
}

/* The same budget as lights are added and removed: the sides follow the live lights' count (a map made at
 * other sides is stale, redrawn like a moved light's), so 95 lights added hold 256 MB of maps, not 1.2 GB.
 * Beyond what fits at the smallest side (1,365 point lights) the maps stay at that side. They grow back only
 * once they would fill at most 3/4 of the budget, so that a light count going back and forth across the
 * line does not redraw every map each time. */
static void fit_live_sizes(lm_direct *d, const lm_scene *s, const lm_emitters *em)
{
    int points = 0, others = 0;
    for (int i = 0; i < em->count; i++)
        if (live_punctual(s, &em->e[i]))
            *(em->e[i].kind == LM_EMIT_POINT ? &points : &others) += maps_2d(em->e[i].kind == LM_EMIT_DIRECTIONAL);
    int cube = d->set.cube_size, map = d->set.map_size;
    fit_sizes(points, others, &cube, &map);
    int grows = cube > d->cube_now || map > d->map_now;
    if (grows && shadow_bytes(points, others, cube, map) > 0.75 * LM_DIRECT_SHADOW_BUDGET)
        return;
    if (cube != d->cube_now || map != d->map_now)
        lm_info("%s: %d lights: shadow maps of %d (cube faces) and %d texels a side now, within %.0f MB", s->path,
                points + others, cube, map, LM_DIRECT_SHADOW_BUDGET / (1024.0 * 1024.0));
    d->cube_now = cube, d->map_now = map;
}

lm_status lm_direct_create(const lm_scene *s, const lm_atlas *a, const lm_direct_settings *settings, lm_direct **out,
                           lm_error *err)
{
    *out = NULL;
    lm_direct *d = calloc(1, sizeof *d);
    if (!d)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the direct light", s->path);
    if (settings)
        d->set = *settings;
    else
        lm_direct_settings_default(&d->set);
    if (!valid_settings(&d->set)) {
        lm_direct_settings bad = d->set;
        free(d);
        return lm_fail(err, LM_ERR_INVALID, "direct_light: bad settings (map %d, cube %d, pcf %d, probe lod %g)",
                       bad.map_size, bad.cube_size, bad.pcf_radius, (double)bad.probe_lod);
    }
    d->maps_left = -1;
    lm_status st = fit_shadow_budget(s, d, err);
    if (st == LM_OK)
        st = light_programs(d, scene_glossy(s), err);
    d->programs_version = s->pass_version;
    if (st == LM_OK)
        st = lm_gl_program("direct_emission", lm_glsl_direct_vs, lm_glsl_emission_fs, &d->emission, err);
    if (st == LM_OK)
        st = lm_sky_pass_init(&d->sky, err);
    if (st == LM_OK) {
        d->e_view_proj = glGetUniformLocation(d->emission, "view_proj");
        d->e_lit = glGetUniformLocation(d->emission, "lit");
        d->e_use_lit = glGetUniformLocation(d->emission, "use_lit");
        d->e_turn = glGetUniformLocation(d->emission, "turn");
        d->e_use_turn = glGetUniformLocation(d->emission, "use_turn");
        st = lm_shadow_renderer_create(&d->shadow, err);
    }
    if (st == LM_OK)
        st = lm_direct_mesh_build(&d->mesh, s, a, d->set.shadows, lod_error(d, s), err);
    d->has_lightmap = a != NULL;
    d->gbuffer = 1;
    d->atlas = a;
    if (st == LM_OK)
        st = lm_gl_check("direct_light: setup", err);
    if (st != LM_OK) {
        lm_direct_free(d);
        return st;
    }
    *out = d;
    return LM_OK;
}

void lm_direct_free(lm_direct *d)
{
    if (!d)
        return;
    for (int i = 0; i < d->map_count; i++)
        free_cached_map(&d->maps[i]);
    free(d->maps);
    lm_frame_targets_free(&d->targets);
    if (d->coverage_tex)
        glDeleteTextures(1, &d->coverage_tex);
    if (d->mesh.first)
        lm_direct_mesh_free(&d->mesh);
    lm_shadow_renderer_free(&d->shadow);
    free_light_programs(d);
    if (d->emission)
        glDeleteProgram(d->emission);
    lm_sky_pass_free(&d->sky);
    free(d);
}

/* One cached map per emitter index (the emitter list is fixed, but grow if it is not). */
static lm_status ensure_maps(lm_direct *d, int count, lm_error *err)
{
    if (count <= d->map_count)
        return LM_OK;
    cached_map *m = realloc(d->maps, sizeof *m * (size_t)count);
    if (!m)
        return lm_fail(err, LM_ERR_NOMEM, "direct_light: no memory for %d shadow maps", count);
    memset(m + d->map_count, 0, sizeof *m * (size_t)(count - d->map_count));
    d->maps = m;
    d->map_count = count;
    return LM_OK;
}

/* The scene from view into picture `which` of the frame's targets (width x height), leaving out the
 * vertices in d->drop. */
static lm_status draw_into(lm_direct *d, int which, const lm_scene *s, const lm_emitters *em,
                           const lm_view *view, int width, int height, lm_error *err)
{
    if (width <= 0 || height <= 0)
        return lm_fail(err, LM_ERR_INVALID, "direct_light: bad size %dx%d", width, height);
    lm_status st = ensure_maps(d, em->count, err);
    if (st == LM_OK && d->mesh.pass_version != s->pass_version) {
        /* nodes switched between static and dynamic, or shadows on or off: the casters chosen and split
         * again, every shadow redrawn */
        lm_direct_mesh fresh;
        if ((st = lm_direct_mesh_build(&fresh, s, d->atlas, d->set.shadows, lod_error(d, s), err)) == LM_OK) {
            lm_direct_mesh_free(&d->mesh);
            d->mesh = fresh;
            d->static_version++, d->dynamic_version++;
        }
    }
    if (st == LM_OK && d->programs_version != s->pass_version) { /* a class edit: the glossy lobe may come or go */
        int glossy = scene_glossy(s);
        if (glossy != d->glossy)
            st = light_programs(d, glossy, err);
        d->programs_version = st == LM_OK ? s->pass_version : d->programs_version;
    }
    if (st != LM_OK)
        return st;
    int moved = lm_direct_mesh_update(&d->mesh, s);
    d->static_version += (moved & LM_MESH_STATIC_CASTERS_MOVED) != 0;
    d->dynamic_version += (moved & LM_MESH_DYNAMIC_CASTERS_MOVED) != 0;
    st = lm_frame_targets_ensure(&d->targets, which, width, height, err);
    if (st != LM_OK)
        return st;
    d->cur = which;
    fit_live_sizes(d, s, em);
    if ((st = refresh_maps(d, s, em, err)) != LM_OK)
        return st;
    if (which == LM_FRAME_VIEW && (st = refresh_near_maps(d, s, em, view, err)) != LM_OK)
        return st;
    int first = -1;
    for (int i = 0; first < 0 && i < em->count; i++)
        first = live_punctual(s, &em->e[i]) ? i : -1;
    glBindFramebuffer(GL_FRAMEBUFFER, lm_frame_targets_fbo(&d->targets, which));
    if (which == LM_FRAME_MIRROR) { /* the scene reflected: its triangles' winding turns over */
        glEnable(GL_CLIP_DISTANCE0);
        glFrontFace(GL_CW);
    }
    static const GLenum all[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    /* only the view's G-buffer is read (by the photon gathers), and only when they run: another float
     * attachment written and cleared costs about a tenth of the pass on llvmpipe */
    int buffers = which == LM_FRAME_VIEW && d->gbuffer ? 3 : 2;
    glDrawBuffers(buffers, all);
    first_pass(d, s, em, first, view, width, height, buffers);
    glDrawBuffers(1, all); /* the additive passes after it add radiance only */
    for (int i = first + 1; first >= 0 && st == LM_OK && i < em->count; i++)
        if (live_punctual(s, &em->e[i]))
            st = light_pass(d, s, &em->e[i], i, view, width, height, err);
    glDisable(GL_CLIP_DISTANCE0);
    glFrontFace(GL_CCW);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return st;
}

/* What the next draws leave out (set_left_out): node `skip`'s vertices (-1: none) and what lies behind
 * `clip` (NULL: nothing). */
static void leave_out(lm_direct *d, int skip, const float clip[4])
{
    int ok = skip >= 0 && skip < d->mesh.node_count;
    d->drop[0] = ok ? d->mesh.node_first[skip] : 0;
    d->drop[1] = ok ? d->mesh.node_first[skip] + d->mesh.node_verts[skip] : 0;
    for (int k = 0; k < 4; k++)
        d->clip[k] = clip ? clip[k] : 0.0f;
}

lm_status lm_direct_draw(lm_direct *d, const lm_scene *s, const lm_emitters *em, const lm_view *view, int width,
                         int height, lm_error *err)
{
    leave_out(d, -1, NULL);
    return draw_into(d, LM_FRAME_VIEW, s, em, view, width, height, err);
}

lm_status lm_direct_draw_probe(lm_direct *d, const lm_scene *s, const lm_emitters *em, const lm_view *view, int size,
                               int skip, lm_error *err)
{
    leave_out(d, skip, NULL);
    lm_status st = draw_into(d, LM_FRAME_PROBE, s, em, view, size, size, err);
    leave_out(d, -1, NULL);
    return st;
}

lm_status lm_direct_draw_mirror(lm_direct *d, const lm_scene *s, const lm_emitters *em, const lm_view *mirrored,
                                int width, int height, int skip, const float plane[4], lm_error *err)
{
    leave_out(d, skip, plane);
    lm_status st = draw_into(d, LM_FRAME_MIRROR, s, em, mirrored, width, height, err);
    leave_out(d, -1, NULL);
    return st;
}

const lm_frame_targets *lm_direct_targets(const lm_direct *d) { return &d->targets; }
uint32_t lm_direct_probe_triangles(const lm_direct *d) { return d->mesh.lod_tris; }

void lm_direct_draw_node(const lm_direct *d, unsigned prog, int node)
{
    if (node < 0 || node >= d->mesh.node_count || !d->mesh.node_verts[node])
        return;
    int keep[2] = {d->mesh.node_first[node], d->mesh.node_first[node] + d->mesh.node_verts[node]};
    set_ranges(prog, keep, ALL);
    lm_direct_mesh_draw(&d->mesh, prog);
    set_ranges(prog, ALL, ALL);
}

unsigned lm_direct_depth_texture(const lm_direct *d, int probe) { return lm_frame_targets_depth(&d->targets, probe); }
unsigned lm_direct_kd_texture(const lm_direct *d, int probe) { return lm_frame_targets_kd(&d->targets, probe); }
unsigned lm_direct_gbuffer_texture(const lm_direct *d) { return lm_frame_targets_gbuffer(&d->targets); }
unsigned lm_direct_radiance_texture(const lm_direct *d) { return lm_frame_targets_radiance(&d->targets, LM_FRAME_VIEW); }

void lm_direct_set_indirect(lm_direct *d, unsigned lit_tex, const unsigned turn_tex[3])
{
    d->indirect_tex = lit_tex;
    for (int c = 0; c < 3; c++)
        d->turn_tex[c] = turn_tex ? turn_tex[c] : 0;
}
void lm_direct_write_gbuffer(lm_direct *d, int on) { d->gbuffer = on != 0; }
lm_status lm_direct_set_coverage(lm_direct *d, const float *coverage, lm_error *err)
{
    if (!coverage || !d->has_lightmap) {
        if (d->coverage_tex)
            glDeleteTextures(1, &d->coverage_tex);
        d->coverage_tex = 0;
        return LM_OK;
    }
    const lm_atlas *a = d->atlas;
    float *rgba = calloc(4 * (size_t)a->width * (size_t)a->height, sizeof *rgba);
    if (!rgba)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for a %d x %d coverage atlas", a->width, a->height);
    for (uint32_t i = 0; i < a->texel_count; i++) {
        float *p = rgba + 4 * ((size_t)a->texels[i].y * (size_t)a->width + (size_t)a->texels[i].x);
        p[0] = coverage[i] > 0.0f ? 1.0f / coverage[i] : 1.0f;
        p[3] = 1.0f;
    }
    if (!d->coverage_tex) {
        glGenTextures(1, &d->coverage_tex);
        glBindTexture(GL_TEXTURE_2D, d->coverage_tex);
        lm_texture_linear_clamped();
    }
    glBindTexture(GL_TEXTURE_2D, d->coverage_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, a->width, a->height, 0, GL_RGBA, GL_FLOAT, rgba);
    glBindTexture(GL_TEXTURE_2D, 0);
    free(rgba);
    return LM_OK;
}

void lm_direct_begin_update(lm_direct *d, int maps)
{
    d->updates++;
    d->maps_left = maps < 0 ? -1 : maps;
}

void lm_direct_end_update(lm_direct *d) { d->maps_left = -1; }

int lm_direct_stale_maps(const lm_direct *d)
{
    int n = 0;
    for (int i = 0; i < d->map_count; i++)
        n += d->maps[i].stale_since != 0;
    return n;
}

int lm_direct_map_stale(const lm_direct *d, int i) { return i >= 0 && i < d->map_count && d->maps[i].stale_since; }

void lm_direct_map_sides(const lm_direct *d, int *cube, int *map)
{
    *cube = d->cube_now;
    *map = d->map_now;
}

long lm_direct_shadow_maps_rendered(const lm_direct *d) { return d->maps_rendered; }
long lm_direct_view_maps_rendered(const lm_direct *d) { return d->near_rendered; }
int lm_direct_view_map_texel(const lm_direct *d, int i, int cascade, float *texel)
{
    if (i < 0 || i >= d->map_count || cascade < 0 || cascade >= LM_VIEW_CASCADES || !d->maps[i].near[cascade].tex)
        return 0;
    *texel = d->maps[i].near[cascade].p.texel;
    return 1;
}

int lm_direct_shadow_maps_held(const lm_direct *d)
{
    int n = 0;
    for (int i = 0; i < d->map_count; i++)
        n += d->maps[i].map.tex != 0;
    return n;
}

lm_status lm_direct_read(lm_direct *d, float *rgb, lm_error *err)
{
    return lm_frame_targets_read(&d->targets, rgb, err);
}

lm_status lm_direct_render(lm_direct *d, const lm_scene *s, const lm_emitters *em, const lm_view *view, int width,
                           int height, float *rgb, lm_error *err)
{
    lm_status st = lm_direct_draw(d, s, em, view, width, height, err);
    return st == LM_OK ? lm_direct_read(d, rgb, err) : st;
}

lm_status lm_render_direct(const lm_scene *s, const lm_emitters *em, const lm_view *view, int width,
                           int height, const lm_direct_settings *settings, float *rgb, lm_error *err)
{
    if (width <= 0 || height <= 0)
        return lm_fail(err, LM_ERR_INVALID, "direct_light: bad size %dx%d or settings", width, height);
    lm_direct *d = NULL;
    lm_status st = lm_direct_create(s, NULL, settings, &d, err);
    if (st == LM_OK)
        st = lm_direct_render(d, s, em, view, width, height, rgb, err);
    lm_direct_free(d);
    return st;
}
