/* Portals found without a tag: the openings (windows) through which a sun's or the sky's light gets in to
 * an interior (docs/levels.md, "Portals"; issue 30).
 *
 * A sunlit interior is lit through its windows, which its photons find by chance: one in 2,000 of a sun's
 * through a 1 m window of a room on a 60 m lawn, and the sky's fewer still. The finder looks for the
 * windows backwards, from the surfaces:
 *   - from LM_FIND_LOOKS points of the surfaces, drawn by area, a ray towards the light (a sun: against its
 *     direction, from the surfaces that face it; the sky: cosine-distributed about each surface's front);
 *   - a ray that leaves the scene has reached the light; it came from inside when the rays round it (8 in a
 *     ring at 15, 30, then 60 degrees) mostly hit something: the wall round the opening it leaves by. Where
 *     it crosses that wall's plane is a point of the opening, the wall's normal (turned out, towards the
 *     light) its facing. A ray from the open (a lawn, a roof) finds no ring of hits and counts for nothing;
 *   - the crossings are gathered by wall plane, and each plane's rectangle round its crossings (widened
 *     by 2% a side) is a portal worth its crossings (a sun's cosine at the surface, the sky's luminance
 *     from there), the LM_FOUND_PORTALS worth most.
 * The room's windows become the sun's and the sky's portals, as if tagged. What is found changes only where
 * the photons go: every photon is weighed by the mixture's density (portals.h), so the estimate stays the
 * one without portals. A level without an interior that sees the light finds none, and its photons are
 * unchanged.
 *
 * Cost: LM_FIND_LOOKS rays, and up to 24 more for each that leaves the scene. Deterministic (QMC numbers,
 * the scene as it is): every process of a shared trace finds the same portals. Reads only: thread-safe. */
#ifndef LM_PORTAL_FINDER_H
#define LM_PORTAL_FINDER_H

#include "../charts/charts.h"
#include "lights.h"
#include "rt_scene.h"

#define LM_FIND_LOOKS 65536   /* rays from the surfaces towards the light */
#define LM_FOUND_PORTALS 32   /* at most this many found portals (two triangles each) a light */

/* Whether emitter e is one whose photons portals guide (a directional light or the sky). */
int lm_portals_guide(const lm_emitter *e);
/* The portals found for emitter e (a directional light or the sky, placed: lm_emitters_update), or *out
 * NULL when none is found. Fails only when memory runs out. */
lm_status lm_portals_find(const lm_scene *s, const lm_surfaces *su, const lm_rt *rt, const lm_emitter *e,
                          lm_portals **out, lm_error *err);
/* 1 when a and b are the same portals (both NULL included): no re-trace is needed. */
int lm_portals_same(const lm_portals *a, const lm_portals *b);

#endif
