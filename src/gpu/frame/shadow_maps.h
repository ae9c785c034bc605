/* Shadow maps for the punctual lights (docs/direct.md): a cube map for a point light, a 2D perspective
 * map for a spot light (its cone = the outer angle) and an orthographic map fitted to the scene's bounds
 * for a directional light, with more fitted to the parts of them a view sees. Each texel holds a
 * float distance metric of the nearest caster, divided by the map's range: the distance to the light
 * (point, spot) or the depth along the light's direction (directional). The maps are DEPTH_COMPONENT32F
 * textures with hardware comparison and a linear filter, so one lookup with a reference metric / range
 * returns the lit fraction of the 2 x 2 texels around it (bilinear PCF). */
#ifndef LM_SHADOW_MAPS_H
#define LM_SHADOW_MAPS_H

#include "../../core/camera.h"
#include "../../core/error.h"
#include "../../scene/scene.h"
#include "../../trace/lights.h"
#include "../gl/gl_mesh.h"

/* Everything a map is made from, apart from the casters' geometry: two maps with equal parameters
 * (memcmp) over the same casters are identical. Computed without GL by lm_shadow_params_compute. */
typedef struct {
    int cube;             /* 1: cube map (point light); 0: 2D map */
    int ortho;            /* 2D map: 1 orthographic (directional), 0 perspective (spot) */
    int size;             /* texels per side (per face for a cube) */
    float light_vp[16];   /* 2D map: world -> light clip space */
    float origin[3];      /* where the metric is measured from: the light, or the ortho box's near plane */
    float dir[3];         /* spot, directional: unit direction the light travels (0 for a cube map) */
    float texel;          /* ortho: world size of a texel; perspective/cube: size per unit distance */
    float pos[3];         /* the light's position (cube faces) */
    float znear, zfar;    /* perspective and cube projections */
    float range;          /* metric / range = the depth written */
} lm_shadow_params;

/* A map and its GL objects, kept between renders (zero-initialise; lm_shadow_map_free releases). When the
 * casters are split into static and dynamic ones, the static casters' map is kept as a layer: a render
 * that only has to redo the dynamic casters copies the layer and draws them on top. */
typedef struct {
    lm_shadow_params p;   /* what the texture was last rendered from (valid when tex != 0) */
    unsigned tex;         /* DEPTH_COMPONENT32F texture (cube or 2D), compare mode LEQUAL, linear */
    unsigned fbo;         /* its framebuffer (depth only) */
    unsigned layer_tex, layer_fbo; /* static layer: DEPTH_COMPONENT32F texture and framebuffer */
    int layer_valid;      /* the layer holds the static casters under parameters p */
    unsigned char face_dynamic[6]; /* cube: the face holds dynamic casters drawn over the layer */
} lm_shadow_map;

/* The shadow-map program and its uniform locations. */
typedef struct {
    unsigned prog;
    int u_vp, u_origin, u_dir, u_ortho, u_range;
} lm_shadow_renderer;

lm_status lm_shadow_renderer_create(lm_shadow_renderer *r, lm_error *err);
void lm_shadow_renderer_free(lm_shadow_renderer *r);

/* The parameters of punctual emitter e's map (pos/dir current, s->bounds current). */
void lm_shadow_params_compute(lm_shadow_params *p, const lm_scene *s, const lm_emitter *e, int size);
/* A directional light's map fitted to what view v sees of the scene (docs/direct.md, "The view's sun
 * maps"): the part of the scene's bounds inside v's frustum and no deeper than max_depth (<= 0: all of
 * it), as the light sees it, in a square a power of two smaller than `whole`'s (the light's whole-scene
 * map, lm_shadow_params_compute), its corner on a sixteenth of its side. Same size, origin, direction
 * and depth range as `whole`, so its metric is the same. Returns 0 (near untouched) for a map that is not
 * directional, a view that sees none of the scene, or one that sees about half of it or more (the whole
 * map is then as fine). */
int lm_shadow_params_fit_view(lm_shadow_params *near, const lm_shadow_params *whole, const lm_scene *s,
                              const lm_view *v, float max_depth);
/* Renders map m with parameters p over the caster triangles `casters` (attribute 0 = world position),
 * (re)allocating its textures when the kind or size changed. The first static_count vertices (indices
 * when the mesh is indexed) are static casters: when some follow them, the static ones are drawn into
 * the layer, re-drawn only when p changed or redo_static is set, and each render copies the layer and
 * draws the rest on top. With the dynamic casters' world bounds (dynamic_lo, dynamic_hi; NULL: unknown)
 * a cube face whose frustum they miss now and at its last render already equals its layer and is
 * skipped. Leaves the framebuffer binding at 0; the viewport is changed. */
lm_status lm_shadow_map_draw(lm_shadow_map *m, const lm_shadow_params *p, const lm_shadow_renderer *r,
                             const lm_gl_mesh *casters, int static_count, int redo_static, const float dynamic_lo[3],
                             const float dynamic_hi[3], lm_error *err);
void lm_shadow_map_free(lm_shadow_map *m);

#endif
