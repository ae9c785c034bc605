/* Reflections (the paper's section 6): a dynamic environment cube map per node that holds mirror, glossy
 * or glass triangles, rendered from the centre of the node's world bounds with the frame's own passes
 * (direct light, shadows, emission, the IIM's indirect term, and the caustics when a caustic pass is
 * given; the node itself left out), and an additive pass that adds to the frame what those triangles
 * reflect of it:
 *
 *   mirror   F x env(r), F = albedo + (1 - albedo)(1 - cos)^5 (a metal's Fresnel, Schlick's)
 *   glossy   ks (n + 2) / (n + 1) max(n.r, 0) x env(r, blurred to the lobe)
 *   glass    F env(r) + (1 - F) albedo env(t), F Schlick's Fresnel, t refracted at the near surface
 *
 * r the eye ray reflected about the shading normal, ks and n the Phong lobe of bsdf.c (the normalized
 * lobe integrated against an environment that is constant across it). The glossy lobe is the cube map's
 * mip level whose texel matches the lobe's angular width 1 / sqrt(n) (box-filtered mips: a blur of that
 * width, not the lobe's exact shape). What the diffuse lobe takes from the lightmap (kd / pi x E) and
 * the punctual lights' highlights are the direct pass's; the environment holds no punctual light, so
 * nothing is counted twice (docs/materials.md, "What each class gets from where").
 *
 * Box projection: a node whose extras give "reflection_box" (world space) looks its map up where the
 * reflected ray leaves that box, seen from the map's centre (a parallax-corrected cube map): right for a
 * room's walls seen in a mirror anywhere inside it, where the plain lookup is right only at the centre.
 *
 * Flat reflectors (lm_reflections_draw_planes): a node whose mirror and glossy triangles lie in one plane
 * (no glass, no reflection_box) gets no cube map but the frame's view mirrored in that plane, looked up
 * at the pixel itself, blurred for a glossy lobe by how far behind the plane the reflected surface lies.
 *
 * Approximations (docs/caustics.md measures them): the map is seen from one point, so a reflection of
 * something near a large curved reflector is displaced (parallax; a box proxy the cure where the
 * surroundings are a box); reflectors see each other without their reflections (one
 * bounce); glass bends the ray at its near surface only and looks it up unbent by the far one (no image
 * through a lens), and the light it focuses is the caustics'.
 *
 * Updates: a face is dirty when something it sees changed since it was rendered: a node whose world bounds
 * meet its frustum moved (where it was or where it is), a surface there had its displayed lightmap
 * change, or the lighting changed (the caller's hash: lights, materials, caustic photons; every face). A
 * reflector that moved has all its faces dirty. Each update renders every face at the first call, then up
 * to `faces_per_frame` dirty faces, longest dirty first; a still scene renders none. Cost: a direct pass of
 * size^2 pixels per face (and the caustic pass over it); a flat reflector's picture a direct pass of the
 * frame's size whenever the view or what it shows changed. Needs a current GL context; not thread-safe. */
#ifndef LM_REFLECTIONS_H
#define LM_REFLECTIONS_H

#include "../../core/error.h"
#include "../../scene/scene.h"
#include "../../trace/lights.h"
#include "../../charts/charts.h"
#include "../../core/camera.h"
#include "caustic_pass.h"
#include "direct.h"

typedef struct lm_reflections lm_reflections;

/* One map of size^2 texels a face for every node with mirror, glossy or glass triangles whose reflections
 * are on; *out NULL (and LM_OK) when the scene has none, so that a scene without them pays nothing. */
lm_status lm_reflections_create(const lm_scene *s, int size, int faces_per_frame, lm_reflections **out,
                                lm_error *err);
void lm_reflections_free(lm_reflections *r);
/* What the maps' faces may see change (the update's dirty tracking). */
typedef struct {
    const lm_surfaces *surfaces;      /* with surface_version: per surface, how many times its displayed
                                       * lightmap changed (lm_iim.version); NULL: no lightmaps */
    const uint32_t *surface_version;
    uint64_t lighting;                /* the caller's hash of everything else that lights what they see */
    lm_caustic_pass *caustics;        /* NULL: none; else each face rendered gets its caustics */
} lm_reflection_inputs;
/* Renders the dirty faces (see the file comment) with d's direct pass (after lm_direct_set_indirect for
 * this frame); *faces gets how many. */
lm_status lm_reflections_update(lm_reflections *r, lm_direct *d, const lm_scene *s, const lm_emitters *em,
                                const lm_reflection_inputs *in, int *faces, lm_error *err);
/* The faces the next updates render at most, in place of faces_per_frame (a time budget's count,
 * update/budget_plan.h); 0: faces_per_frame again. NULL: nothing. */
void lm_reflections_limit_faces(lm_reflections *r, int most);
/* Faces of all the maps (6 a map; 0 for NULL and for a flat reflector, which has none). */
int lm_reflections_face_count(const lm_reflections *r);
/* Faces still dirty after the last update (0 for NULL). */
int lm_reflections_dirty_faces(const lm_reflections *r);
/* Flat reflectors (every mirror and glossy triangle of the node within 1e-4 of its size of one plane, no
 * glass): instead of a cube map, the frame's view mirrored in the plane (lm_direct_draw_mirror: what lies
 * on the eye's side of it, the node itself left out), width x height as the frame, drawn again when the
 * view or anything in the key of lm_reflection_inputs changed; *drawn gets how many were. Call before
 * lm_reflections_draw for the same view. */
lm_status lm_reflections_draw_planes(lm_reflections *r, lm_direct *d, const lm_scene *s, const lm_emitters *em,
                                     const lm_reflection_inputs *in, const lm_view *view, int width, int height,
                                     int *drawn, lm_error *err);
/* Adds the reflections to the frame d just drew from view (lm_direct_draw; depth test against its depth). */
lm_status lm_reflections_draw(const lm_reflections *r, const lm_direct *d, const lm_scene *s, const lm_view *view,
                              lm_error *err);

#endif
