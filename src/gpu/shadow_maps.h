/* Shadow maps for the punctual lights (docs/direct.md): a cube map for a point light, a 2D perspective
 * map for a spot light (its cone = the outer angle) and an orthographic map fitted to the scene's bounds
 * for a directional light. Each texel holds a float distance metric of the nearest caster: the distance
 * to the light (point, spot) or the depth along the light's direction (directional). */
#ifndef LM_SHADOW_MAPS_H
#define LM_SHADOW_MAPS_H

#include "../core/error.h"
#include "../scene/scene.h"
#include "../trace/lights.h"
#include "gl_mesh.h"

typedef struct {
    int cube;             /* 1: cube map (point light); 0: 2D map */
    int ortho;            /* 2D map: 1 orthographic (directional), 0 perspective (spot) */
    unsigned tex;         /* GL_R32F texture (cube or 2D) */
    int size;             /* texels per side (per face for a cube) */
    float light_vp[16];   /* 2D map: world -> light clip space */
    float origin[3];      /* where the metric is measured from: the light, or the ortho box's near plane */
    float dir[3];         /* directional: unit direction the light travels */
    float texel;          /* ortho: world size of a texel; perspective/cube: size per unit distance */
} lm_shadow_map;

/* Renders the map of punctual emitter e (pos/dir current) over the caster triangles `casters`
 * (attribute 0 = world position). Leaves the framebuffer binding at 0; the viewport is changed. */
lm_status lm_shadow_map_render(lm_shadow_map *m, const lm_scene *s, const lm_emitter *e,
                               const lm_gl_mesh *casters, int size, lm_error *err);
void lm_shadow_map_free(lm_shadow_map *m);

#endif
