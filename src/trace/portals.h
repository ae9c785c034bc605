/* Portals: openings (windows) that a directional light's photons are aimed through (docs/levels.md,
 * "Portals"; lm_scene.portal_tris, tagged extras.lmgi.portal, their fronts facing the outside).
 *
 * Without them a sunlit interior gets the photons that happen to pass its windows: the sun's leave from a
 * rectangle across the whole level (one in 2,000 entered the test room's window). With them, a photon of
 * the sun is drawn with probability LM_PORTAL_SHARE through a portal (a point on it by its area across
 * the sun, moved back onto the rectangle's plane), else from the rectangle as before, and either way its
 * flux is divided by the density of that mixture at its line (one-sample multiple importance sampling,
 * the balance heuristic): the estimate is the one without portals, half its photons where the light gets
 * in. (The sky's photons are not aimed yet: docs/levels.md.)
 *
 * Cost: a line-triangle test against every portal triangle per photon of a directional light (at most
 * LM_MAX_PORTAL_TRIS). Thread-safe: reads the scene only. */
#ifndef LM_PORTALS_H
#define LM_PORTALS_H

#include "../scene/scene.h"

#define LM_PORTAL_SHARE 0.5f /* of a directional light's photons drawn through the portals */

/* How many portal triangles the line o + t d, t > 0, crosses from their front to their back (inwards). */
int lm_portal_crossings(const lm_scene *s, const float o[3], const float d[3]);
/* The sum over the portal triangles a light travelling along unit d enters by (fronts towards it) of
 * their area across d. */
double lm_portal_area(const lm_scene *s, const float d[3]);
/* A point p of a portal triangle that d enters by, drawn by the area lm_portal_area counts (total, as it
 * gave it for d): u0 picks the triangle and, rescaled, with u1 the point. 0 when there is none. */
int lm_portal_point(const lm_scene *s, const float d[3], double total, float u0, float u1, float p[3]);

#endif
