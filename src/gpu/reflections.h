/* Reflections (the paper's section 6): a dynamic environment cube map per node that holds mirror, glossy
 * or glass triangles, rendered from the centre of the node's world bounds with the frame's own direct
 * pass (direct light, shadows, emission and the IIM's indirect term; the node itself left out), and an
 * additive pass that adds to the frame what those triangles reflect of it:
 *
 *   mirror   albedo x env(r)
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
 * Approximations: the map is seen from one point, so a reflection of something near a large reflector is
 * displaced (parallax); reflectors see each other without their reflections (one bounce); glass bends the
 * ray at its near surface only and looks it up unbent by the far one (no image through a lens), and the
 * light it focuses is the caustics' (issue 12). Cost: 6 direct passes of size^2 pixels per map, at creation of the object's first
 * update and then `faces_per_frame` faces a frame, round robin over all maps (docs/direct.md,
 * "Reflections"). Needs a current GL context; not thread-safe. */
#ifndef LM_REFLECTIONS_H
#define LM_REFLECTIONS_H

#include "../core/error.h"
#include "../scene/scene.h"
#include "../trace/lights.h"
#include "camera.h"
#include "direct.h"

typedef struct lm_reflections lm_reflections;

/* One map of size^2 texels a face for every node with mirror or glossy triangles; *out NULL (and LM_OK)
 * when the scene has none, so that a scene without them pays nothing. */
lm_status lm_reflections_create(const lm_scene *s, int size, int faces_per_frame, lm_reflections **out,
                                lm_error *err);
void lm_reflections_free(lm_reflections *r);
/* Re-renders faces of the maps with d's direct pass (after lm_direct_set_indirect for this frame): every
 * face on the first call, then faces_per_frame of them, round robin. */
lm_status lm_reflections_update(lm_reflections *r, lm_direct *d, const lm_scene *s, const lm_emitters *em,
                                lm_error *err);
/* Adds the reflections to the frame d just drew from view (lm_direct_draw; depth test against its depth). */
lm_status lm_reflections_draw(const lm_reflections *r, const lm_direct *d, const lm_view *view, lm_error *err);

#endif
