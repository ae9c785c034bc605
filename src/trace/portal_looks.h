/* Inside the portal finder (portal_finder.h): rays from the surfaces towards a light, and the rectangles
 * they find, shared by portal_finder.c, portal_openings.c and portal_bounces.c.
 *
 * A look is a ray from a point of the surfaces drawn by area (lm_look_draw) towards a light; each found
 * rectangle is worth the light its looks saw through it, in the same unit for openings and bounces (the
 * irradiance at the look's point, per unit of the light's, summed over the looks): so the portals made of
 * both are picked in proportion to the light they bring. Reads only: thread-safe. */
#ifndef LM_PORTAL_LOOKS_H
#define LM_PORTAL_LOOKS_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../core/vecmath.h"
#include "lights.h"
#include "rt_scene.h"

/* Points of the surfaces drawn by area: every surface triangle with its share of the area. */
typedef struct {
    uint32_t *tri;
    double *cdf;
    uint32_t count;
    double area;   /* the surfaces' area in all */
    float offset;  /* rays leave this far off the surface (1e-5 x the scene's size) */
} lm_look_draw;

lm_status lm_look_draw_init(lm_look_draw *d, const lm_scene *s, const lm_surfaces *su, lm_error *err);
void lm_look_draw_free(lm_look_draw *d);
/* The point x of look `index` (u: its 3 first numbers), its triangle's unit front normal, and the origin
 * of rays off it. */
void lm_look_point(const lm_look_draw *d, const lm_scene *s, const float u[3], lm_vec3 *x, lm_vec3 *front,
                   lm_vec3 *org);
/* The `n` numbers of look `index` of stretch `stretch` (QMC: Halton dims 0 .. n - 1). */
void lm_look_numbers(uint32_t stretch, uint32_t index, int n, float *u);
/* The unit direction from a point towards emitter e's light: against a sun's travel; for the sky, drawn
 * cosine-distributed about `front` from (u0, u1). */
lm_vec3 lm_look_direction(const lm_emitter *e, lm_vec3 front, float u0, float u1);

/* A rectangle found in a plane: axes t, b (t x b = n), normal n facing where the light comes from, at
 * `level` along n; [lo, hi] along t and b; what it is worth; whether it is an opening (a way in) or a
 * place outside (set by lm_portals_find, where both are known). */
typedef struct {
    lm_vec3 t, b, n;
    double level, lo[2], hi[2];
    double worth;
    int opening;
} lm_found_rect;

lm_vec3 lm_found_rect_point(const lm_found_rect *r, double x, double y);

/* A point a look found (a crossing of an opening, a place outside): where, facing where the light comes
 * from, its worth, and the keys it is gathered by: its plane (the normal in hundredths, the offset in steps
 * of lm_found_point_plane's) and, for a place, its cell's size and place in the plane (0 for a crossing). */
typedef struct {
    float pos[3], normal[3];
    double worth;
    int64_t key[7];
} lm_found_point;

/* The step in which found planes' offsets are told apart: the level's size over 4096. */
double lm_found_plane_step(const lm_scene *s);
/* Sets p's plane keys (key[0 .. 3]) from its normal and position, the offset in steps of `step`. */
void lm_found_point_plane(lm_found_point *p, double step);
/* qsort's order of found points by their keys: those of one plane (and cell) together. */
int lm_found_point_order(const void *a, const void *b);
/* Whether the ray org + s w, 0 < s < far, crosses r from its back to its front (going out, towards the
 * light). */
int lm_found_rect_crossed_out(const lm_found_rect *r, lm_vec3 org, lm_vec3 w, float far);
/* The same from its front to its back (coming in). */
int lm_found_rect_crossed_in(const lm_found_rect *r, lm_vec3 org, lm_vec3 w, float far);

/* portal_openings.c: the openings (windows) through which the light gets in, found from LM_FIND_LOOKS
 * looks, each worth the light its looks saw (a sun's cosine at the surface, the sky's luminance; the
 * finder turns it into flux with the looks' share of the area); at most `cap` of them into out. Returns
 * how many, or UINT32_MAX when memory ran out. */
uint32_t lm_find_openings(const lm_scene *s, const lm_rt *rt, const lm_look_draw *d, const lm_emitter *e,
                          lm_found_rect *out, uint32_t cap, lm_error *err);
/* portal_bounces.c: the places outside (a lawn under the windows) whose light, reflected, gets in through
 * the openings found, from LM_FIND_LOOKS rays out of them, each worth the flux it lets in; at most `cap`
 * into out. The sky's own flux in by each opening (its rays that leave the scene) into sky_in[n_openings]
 * (0 for a sun). Returns how many, or UINT32_MAX when memory ran out. */
uint32_t lm_find_bounces(const lm_scene *s, const lm_rt *rt, const lm_look_draw *d, const lm_emitter *e,
                         const lm_found_rect *openings, uint32_t n_openings, lm_found_rect *out, uint32_t cap,
                         double *sky_in, lm_error *err);

#endif
