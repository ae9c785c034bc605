/* Light emitters: every point, spot and directional light, and the emissive triangles of each node
 * (one emitter per node with an emissive material), with the flux each emits.
 *
 * Units (docs/materials.md): glTF intensities are used as linear RGB radiometric quantities.
 * Point: intensity I -> flux 4 pi I. Spot: I -> I times the solid angle of its cone (with the glTF
 * smooth falloff between inner and outer angles integrated). Directional: illuminance E -> flux E times
 * the area of the rectangle across the light that covers the scene's bounds as the light sees them.
 * Emissive: radiance L = emissive x strength, flux pi L A per emitting side (double-sided materials emit
 * on both sides). Sky (lm_scene.sky*, radiance L(d) by direction, scene/sky.h): photons leave the disk
 * that covers the scene's bounds across a direction drawn uniformly on the sphere, each with the radiance
 * from where it comes, flux 4 pi mean(L) x pi R^2 in all; it has no next-event estimation (the reference
 * meets it where rays leave the scene) and no caustic photons. It is the last emitter of a list built with
 * it; node and light are -1. A directional light's and the sky's photons may be aimed in part through
 * portals (portals.h: the file's, or those found, portal_finder.h), each weighed so the estimate stays. */
#ifndef LM_LIGHTS_H
#define LM_LIGHTS_H

#include <stdint.h>

#include "../core/error.h"
#include "../scene/scene.h"
#include "portals.h"
#include "sun_guide.h"

typedef enum { LM_EMIT_POINT = 0, LM_EMIT_SPOT, LM_EMIT_DIRECTIONAL, LM_EMIT_AREA, LM_EMIT_SKY } lm_emitter_kind;

typedef struct {
    lm_emitter_kind kind;
    int light;            /* scene light index, -1 for AREA */
    int node;             /* node that places it */
    float power[3];       /* emitted flux, RGB */
    float luminance;      /* luminance of power: photon counts are split in proportion to it */
    /* AREA: the node's emissive triangles and the CDF for choosing one by flux */
    uint32_t tri_count;
    uint32_t *tris;
    float *cdf;
    float area;           /* world area of those triangles */
    int punctual;         /* point, spot, directional: their direct light is computed per pixel */
    /* Placement, kept current by lm_emitters_update (added for NEE): */
    float pos[3];         /* point/spot: world position (node world translation) */
    float dir[3];         /* point/spot/directional: unit direction the light shines (node world -Z) */
    float radiant[3];     /* point/spot: intensity x colour; directional: illuminance x colour */
    float rect[3][3];     /* directional: the rectangle its photons leave from, across its direction and
                           * upstream of the scene: a corner and its two edges (lights.c, "fitted") */
    lm_portals *portals;  /* directional and sky: where a share of its photons is aimed (portals.h): the
                           * file's portals, or those found from its photons (portal_finder.h); NULL: none.
                           * Owned; aimed at each placement */
    lm_sun_guide *guide;  /* directional, without usable portals: where its photons leave the rectangle
                           * (sun_guide.h); NULL: uniformly. Owned */
} lm_emitter;

typedef struct {
    int count;
    lm_emitter *e;
    float total_luminance;
    float disk_center[3], disk_radius; /* directional lights emit from this disk (scene bounds) */
} lm_emitters;

lm_status lm_emitters_build(const lm_scene *s, lm_emitters *out, lm_error *err);
void lm_emitters_free(lm_emitters *em);
/* Appends the emitter of scene light `light`, added by an edit after em was built, and places every
 * emitter (lm_emitters_update). */
lm_status lm_emitters_add_light(lm_emitters *em, const lm_scene *s, int light, lm_error *err);
/* Appends the sky emitter, for a scene given a sky (lm_scene.has_sky) after em was built; and the index of
 * em's sky emitter, -1 without one. */
lm_status lm_emitters_add_sky(lm_emitters *em, const lm_scene *s, lm_error *err);
int lm_emitters_sky(const lm_emitters *em);
/* Point, spot and directional emitters in em (the lights it knows). */
int lm_emitters_light_count(const lm_emitters *em);
/* 1 when e is the emitter of a light removed for good (lmgi_remove_light): it lights nothing again, and what
 * it holds (shadow map, photon paths, caustic slots) may be given back. */
int lm_emitter_removed(const lm_scene *s, const lm_emitter *e);
/* Re-reads emitter placement and flux after node moves or light edits (world matrices, bounds). */
void lm_emitters_update(lm_emitters *em, const lm_scene *s);
/* Emitter e's photons aimed through portals p from now on (taking p, aimed for it at once and at every
 * lm_emitters_update), in place of what it had; NULL: none. */
void lm_emitter_set_portals(lm_emitters *em, int e, lm_portals *p);
/* Emitter e's (a sun's) photons drawn from guide g from now on (taking g), in place of what it had; NULL:
 * uniformly. */
void lm_emitter_set_guide(lm_emitters *em, int e, lm_sun_guide *g);

/* A photon leaving emitter e: origin, unit direction, and its flux for a total of `count` photons
 * from this emitter (flux = power / count, times any falloff weight). u: 4 uniform numbers in [0,1)
 * (u[0], u[1] choose the direction, so QMC strata of those two give photons of similar direction). */
typedef struct {
    float org[3], dir[3];
    float flux[3];
} lm_emission;
void lm_emitter_emit(const lm_emitters *em, const lm_scene *s, int e, const float u[4], uint32_t count,
                     lm_emission *out);
/* An area emitter's triangle placed in world space (current node matrices), with what emission
 * derives from that placement. A caller that emits many photons while nothing moves (one photon
 * batch) places each triangle once instead of once per photon. */
typedef struct {
    float p[3][3];        /* world corners */
    float n[3];           /* unit geometric normal, front side */
    float t[3], b[3];     /* tangents: (t, b, n) orthonormal, the frame emitted directions are drawn in */
    float flux[3];        /* the triangle's flux (all emitting sides) */
    float lift;           /* origin offset along the normal: 1e-5 x scene size */
    int double_sided;
} lm_emit_tri;
/* Places emitter e's tri_count triangles into out[0 .. tri_count) (nothing for punctual lights). */
void lm_emitter_place(const lm_emitters *em, const lm_scene *s, int e, lm_emit_tri *out);
/* lm_emitter_emit from triangles that lm_emitter_place placed (tris may be NULL for punctual
 * emitters): bit for bit the same emission while the scene has not changed since. */
void lm_emitter_emit_placed(const lm_emitters *em, const lm_scene *s, int e, const lm_emit_tri *tris,
                            const float u[4], uint32_t count, lm_emission *out);

/* A point on area emitter e as emission picks one (u[0]: the triangle by flux, its leftover the side of a
 * double-sided one; u[1] with that leftover: uniform on the triangle), for an emitter that then picks
 * its own direction (the caustic photons, trace/caustics.h): pos lifted off the surface as an emitted
 * photon's origin, n the unit normal of the emitting side, and weight = Le / pdf (pdf per unit area over
 * all sides of all the emitter's triangles), so that a photon leaving along w with density p_w (solid
 * angle) carries weight x cos(n, w) / p_w. Returns 0 for a punctual or flux-less emitter. tris: as
 * lm_emitter_place made them, or NULL. */
int lm_emitter_area_point(const lm_emitters *em, const lm_scene *s, int e, const lm_emit_tri *tris, const float u[2],
                          float pos[3], float n[3], float weight[3]);

/* Next-event estimation from point p: a sample on emitter e. dir is unit from p towards the light,
 * dist its distance (INFINITY for directional), radiance_weight the incident radiance times the
 * inverse pdf (so that E += radiance_weight * cos for one sample). Returns 0 if p gets nothing. */
typedef struct {
    float dir[3];
    float dist;
    float weight[3];
    float pdf;            /* solid-angle density of dir (AREA; 0 for the delta lights), for MIS */
} lm_light_sample;
int lm_emitter_sample_toward(const lm_emitters *em, const lm_scene *s, int e, const float p[3],
                             const float u[3], lm_light_sample *out);

/* Additions (lights.c documents the details):
 * lm_spot_attenuation: glTF KHR_lights_punctual's smooth cone falloff at cos_angle (cosine between the
 * spot's axis and the direction to the lit point): t = clamp((cos_angle - cos outer) / max(1e-3,
 * cos inner - cos outer), 0, 1), attenuation t^2, as the extension's reference implementation.
 * lm_spot_solid_angle: the integral of that attenuation over the sphere (exact), so flux = I x it.
 * lm_emitter_pdf: the solid-angle density with which lm_emitter_sample_toward(e, p) picks the point x
 * on scene triangle tri (0 if tri is not one of e's triangles or p sees its non-emitting side).
 * lm_emitted_radiance: radiance a surface of material m (geometric normal ng) emits along wo (unit,
 * leaving the surface): the material's emissive for an emitter on an emitting side, else 0; returns
 * whether it is non-zero. Emissive textures are not used (the emissive factor is). */
float lm_spot_attenuation(const lm_light *l, float cos_angle);
/* KHR_lights_punctual `range` (lights.c): the factor on a point or spot light's inverse square at
 * distance dist, clamp(1 - (dist / range)^4, 0, 1); 1 without a range and for directional lights.
 * lm_emitter_range_window: the same for emitter e (1 for area emitters). Photons carry it from their
 * first hit on (photon_trace.c, caustics.c), so photon maps, the gather and the reference agree. */
float lm_light_range_window(const lm_light *l, float dist);
float lm_emitter_range_window(const lm_scene *s, const lm_emitter *e, float dist);
float lm_spot_solid_angle(const lm_light *l);
float lm_emitter_pdf(const lm_emitters *em, const lm_scene *s, int e, uint32_t tri, const float p[3],
                     const float x[3]);
int lm_emitted_radiance(const lm_material *m, const float ng[3], const float wo[3], float out[3]);

#endif
