/* Flat reflectors: nodes whose mirror and glossy triangles lie in one plane, which the frame reflects by
 * the view mirrored in that plane instead of a cube map seen from one point (gpu/frame/reflections.h;
 * docs/direct.md, "Flat reflectors"). Here, so that the frame and `lmgi info` (update/effects.c) judge a
 * node alike.
 *
 * A node is a flat reflector when it has mirror or glossy triangles, none of glass (glass shows what lies
 * behind it, which a mirrored picture does not hold), no reflection_box in its settings (that asks for a
 * box-projected cube map), and every corner of those triangles lies within LM_FLAT_TOLERANCE of the
 * bounds' diagonal from their plane. Cost: O(the node's triangles), at the node's current world matrix.
 * Reads the scene only: thread-safe while nothing edits it. */
#ifndef LM_FLAT_REFLECTORS_H
#define LM_FLAT_REFLECTORS_H

#include "scene.h"

#define LM_FLAT_TOLERANCE 1e-4f

/* The world plane (n, w) of node's mirror, glossy and glass triangles as they are now: n the
 * area-weighted mean of their normals (each turned to the sum's side, so that a two-sided surface's back
 * copies add to it), w = -n.p at one corner. Returns the largest distance of a corner from that plane and
 * writes the bounds' diagonal to *extent; -1 when those triangles have no area (or there are none). */
float lm_node_reflector_plane(const lm_scene *s, int node, float plane[4], float *extent);

/* Whether the node is a flat reflector (above). */
int lm_node_is_flat_reflector(const lm_scene *s, int node);

#endif
