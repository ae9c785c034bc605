/* The AIM estimate's visibility test (docs/aim.md, "Occluders"): which photon hits near a texel would have
 * reached the texel itself.
 *
 * A hit at p whose photon left the vertex q (lm_hit.travelled) says "light from q reaches this surface".
 * Summed over a disc, every hit assumes that the texel at x sees what p saw, which blurs a contact shadow
 * into light: the floor beside a box gets the hits of the floor a few centimetres out, whose photons came
 * past the box's side. Weighing each hit by V(x, q) alone is biased the other way: the hits of points closer
 * to the box than x are missing the light that only x sees, and the estimate becomes the mean of min(what p
 * sees, what x sees). So each hit is weighed by V(x, q) / P(q), with P(q) the share of the disc, as the
 * estimate's kernel weighs it, that sees q: the photons from q land only where q is seen, so over the disc
 * they sum to P(q) times what an unoccluded disc would get, and 1 / P gives back the light from q that x
 * sees. Σ w Φ V / P / A_w is then the irradiance at x where the incident light is the same across the disc
 * but for visibility. P is measured at LM_AIM_SIGHT_POINTS fixed points of the disc (turned per texel) that
 * lie on a surface facing the same way and are not covered (a point past a wall's edge is not on the disc's
 * surface; one under a box standing on the floor gets no photon whatever it would see: both are left out,
 * and where nothing occludes the estimate is the paper's).
 *
 * Cost: per texel 2 LM_AIM_SIGHT_POINTS rays to place the points; per hit summed one segment from x, and
 * where x sees q one more per point, traced as one packet from q (remembered while q repeats: a point
 * light's first hits share it).
 * Points are lifted `lift` off the surface towards q's side; a segment stops 2 lift short of q (its own
 * surface). A texel with geometry closer than `cover` straight out on q's side (under a box standing on
 * the floor) is hidden, not dark: its hits on that side weigh 1. Thread-safe (reads rt only).
 * Deterministic: the points depend on the texel's index only. */
#ifndef LM_AIM_SIGHT_H
#define LM_AIM_SIGHT_H

#include <stdint.h>

#include "../trace/rt_scene.h"

#define LM_AIM_SIGHT_POINTS 8

typedef struct {
    const lm_rt *rt; /* NULL: no test, every weight 1 */
    float lift, cover;
    int kernel;      /* the estimate's kernel, which spreads the points: 1 Epanechnikov, 0 box */
} lm_aim_sight;

/* The texel: world point x, unit front normal n, the estimate's radius r (world units), its atlas index
 * (turns the points). */
typedef struct {
    float x[3], n[3], r;
    uint32_t index;
} lm_aim_sight_texel;

/* ends: 6 floats per hit, its world position and that of the vertex its photon left (NaN: not known, the
 * hit weighs 1). For the k hits idx[0..k) of the texel, writes weight[i] = V(x, q) / P(q) (0 where x does
 * not see q; at most LM_AIM_SIGHT_POINTS, where no point sees q but the hit's own did). */
void lm_aim_sight_weigh(const lm_aim_sight *s, const lm_aim_sight_texel *t, const float *ends, const uint32_t *idx,
                        uint32_t k, float *weight);

#endif
