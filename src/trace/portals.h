/* Portals: openings (windows) that a sun's or the sky's photons are aimed through (docs/levels.md,
 * "Portals").
 *
 * Without them a sunlit interior gets the photons that happen to pass its windows: a sun's leave from a
 * rectangle across the whole level and the sky's from the disk of its bounding sphere (one in 2,000 of
 * the sun's entered the test room's window). With them, a photon is drawn with probability
 * LM_PORTAL_SHARE through a portal, else as before, and either way its flux is divided by the density of
 * that mixture at its line (one-sample multiple importance sampling, the balance heuristic): the estimate
 * is the one without portals, half its photons where the light gets in.
 *
 * A set holds triangles in world space whose front (counter-clockwise) faces where the light comes from,
 * each with a weight: a portal tagged in the file (extras.lmgi.portal) is worth its area, one found
 * (portal_finder.h: an opening, or a place outside whose reflected light gets in) the light it lets in.
 *
 *   sun (direction of travel d): triangle k is picked with probability P_k, proportional to its weight
 *        times its cosine to the light for a tagged one (its area across the light) and to its weight for a
 *        found one, 0 where its front does not face the light; a point on it is uniform. The line's
 *        density, per unit of area across the light: sum over the triangles it enters by their fronts of
 *        P_k / (A_k |cos_k|).
 *   sky: triangle k is picked with probability proportional to its weight, a point on it uniform, the
 *        direction w towards the sky cosine-distributed about its front normal n_k: the photon travels the
 *        other way, in through the triangle. Per unit of line measure (area across x solid angle) that
 *        is P_k / (pi A_k) for each triangle the line enters by its front.
 * Either density counts every triangle a line crosses, whatever stands in front of it: a line drawn
 * through a portal that meets a wall first is still a line of the mixture, and lands on the wall.
 *
 * Cost: a line-triangle test against every triangle of the set per photon of a guided light (at most
 * LM_MAX_PORTAL_TRIS tagged and 2 LM_FOUND_PORTALS found). Reads only: thread-safe once aimed. */
#ifndef LM_PORTALS_H
#define LM_PORTALS_H

#include <stdint.h>

#include "../core/error.h"
#include "../scene/scene.h"

#define LM_PORTAL_SHARE 0.5f /* of a guided light's photons drawn through its portals */

typedef struct {
    uint32_t count;            /* triangles */
    float *tris;               /* 9 floats each: world corners, the front facing where light comes from */
    double *weight;            /* what each is worth (above) */
    unsigned char *tagged;     /* 1: tagged in the file (its weight its area), 0: found */
    unsigned char *opening;    /* 1: a way in (tagged, or an opening found), 0: a place outside */
    uint32_t found;            /* how many were found */
    /* Made by lm_portals_aim for one light: */
    double *area;              /* A_k */
    double *density;           /* P_k / (A_k |cos_k|) (sun) or P_k / (pi A_k) (sky); 0: never picked */
    double *cdf;               /* cumulative P_k */
    float *normal;             /* 3 per triangle: unit front normal */
    int usable;                /* some triangle can be picked for this light */
} lm_portals;

/* A set of n triangles (9 floats each) with their weights, whether each is tagged and whether it is a way
 * in, copied: NULL weight, each its area; NULL tagged, none is; NULL opening, each is one. NULL on running
 * out of memory (err says so). */
lm_portals *lm_portals_make(const float *tris, const double *weight, const unsigned char *tagged,
                            const unsigned char *opening, uint32_t n, lm_error *err);
/* The file's portals: n triangles, each tagged and worth its area. */
lm_portals *lm_portals_tagged(const float *tris, uint32_t n, lm_error *err);
void lm_portals_free(lm_portals *p);
/* Sets the probabilities and densities for a sun travelling along unit d, or for the sky (d NULL). */
void lm_portals_aim(lm_portals *p, const float d[3]);

/* Sun: a point x on a portal from two uniform numbers (u0 picks the triangle and, rescaled, with u1 the
 * point). 0 when the set is not usable. */
int lm_portals_sun_point(const lm_portals *p, float u0, float u1, float x[3]);
/* Sky: a point x on a portal (u_pick picks the triangle and, rescaled, with u_tri the point) and the unit
 * direction w towards the sky from it, cosine-distributed about the portal's front (u0, u1). 0 when the set
 * is not usable. */
int lm_portals_sky_line(const lm_portals *p, float u_pick, float u_tri, float u0, float u1, float x[3], float w[3]);
/* The portals' density at the line o + t d, t > 0 (the sum above, for the light p was aimed for). */
double lm_portals_density(const lm_portals *p, const float o[3], const float d[3]);

/* Bounces outside aimed in through the openings (docs/levels.md, "Bounces aimed in"). A photon's diffuse
 * bounce at x, outside in front of the openings, is drawn with probability LM_PORTAL_BOUNCE_SHARE (a
 * quarter) towards a point uniform on an opening (opening i picked in proportion to the cosine-weighted
 * solid angle it fills at x, judged from its centre), else from the BSDF, and weighed by the mixture's
 * density at the direction drawn (one-sample multiple importance sampling, as for emission): the estimate
 * stays the one without, but the light of a sunlit lawn gets in as many light photons instead of a rare
 * heavy one. Places outside are
 * not aimed at, and a point behind every opening (inside) bounces as before.
 *   lm_portals_bounce_reach: the sum of what the openings fill at x (unit normal n, the side the bounce
 *     leaves by); 0: none in sight, the bounce is the BSDF's alone;
 *   lm_portals_bounce_dir: a unit direction w from x towards an opening from two uniform numbers (u0 picks
 *     the opening and, rescaled, with u1 the point); 0 when there is none;
 *   lm_portals_bounce_density: that draw's density per unit solid angle at unit w (total: the reach).
 * Cost: a pass over the set's triangles per call. Reads only: thread-safe. */
#define LM_PORTAL_BOUNCE_SHARE 0.25f
double lm_portals_bounce_reach(const lm_portals *p, const float x[3], const float n[3]);
int lm_portals_bounce_dir(const lm_portals *p, const float x[3], const float n[3], double total, float u0, float u1,
                          float w[3]);
double lm_portals_bounce_density(const lm_portals *p, const float x[3], const float n[3], double total,
                                 const float w[3]);

#endif
