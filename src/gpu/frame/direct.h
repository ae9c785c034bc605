/* Direct light per pixel (docs/direct.md): the scene seen from an lm_view, each pixel holding the
 * radiance (linear RGB) leaving the visible surface towards the eye from the direct light of every point,
 * spot and directional light, shadowed by shadow maps with PCF, plus the emitted radiance of emissive
 * materials. Light from emissive meshes onto other surfaces is not here (it reaches the image through the
 * IIMs); mirror and glass are black (their reflections are a later item). */
#ifndef LM_DIRECT_H
#define LM_DIRECT_H

#include "../../charts/charts.h"
#include "../../core/error.h"
#include "../../scene/scene.h"
#include "../../trace/lights.h"
#include "../../core/camera.h"
#include "frame_targets.h"

typedef struct {
    int map_size;         /* 2D shadow maps (spot, directional), texels per side. Default 1024 */
    int cube_size;        /* point-light cube map, texels per face side. Default 512 */
    int pcf_radius;       /* PCF: (2r)^2 bilinear compare taps 1 texel apart (r = 0: one, over the 2 x 2 texels
                           * around the receiver). Default 0: one tap (r = 1, 4 taps over 3 x 3 texels, costs
                           * four times the shadow lookups: docs/direct.md) */
    float normal_offset;  /* receiver moved along its normal by this many texels. Default 1 */
    float slope_bias;     /* depth bias per texel and unit slope tan(theta), times (pcf_radius + 1). Default 1 */
    float max_slope;      /* tan(theta) is clamped here (theta near 90 degrees). Default 10 */
    float const_bias;     /* constant depth bias in texels. Default 0.5 */
    int shadows;          /* 0: no node casts shadows (the run's switch; a node's own is lm_node_settings).
                           * Default 1 */
    int maps_per_update;  /* stale shadow maps re-rendered per update (lm_direct_begin_update's count for the
                           * frame loop; < 0: all). Default 4 */
    float probe_lod;      /* environment map faces (lm_direct_draw_probe) draw the scene simplified to this
                           * error, a fraction of the scene's size (direct_mesh.h; 0: every triangle).
                           * Default LM_DIRECT_PROBE_LOD */
} lm_direct_settings;

void lm_direct_settings_default(lm_direct_settings *s);

/* The environment faces' level of detail: 1/512 of the scene's size, 7 mm in the 3.5 m Cornell box, a
 * tenth of a face's pixel there at its default 128 texels (docs/direct.md, "Reflections"). Larsen &
 * Christensen section 9: LOD works with their methods. */
#define LM_DIRECT_PROBE_LOD (1.0f / 512.0f)

/* What all shadow maps together may take, and the smallest side they are shrunk to to fit (direct.c,
 * fit_shadow_budget): 256 MB holds 10 point lights at the default 512 a face, 1,365 at 64. */
#define LM_DIRECT_SHADOW_BUDGET (256.0 * 1024.0 * 1024.0)
#define LM_DIRECT_SHADOW_MIN_SIZE 64

/* A persistent direct-light renderer (docs/direct.md, "What is cached"): the program, the scene's vertex
 * buffers and textures, the float target and one shadow map per punctual light, kept between renders.
 * Each render re-uploads only the nodes whose world matrix changed and re-renders a light's shadow map
 * only when its parameters (position, direction, cone, size, the scene bounds it is fitted to) or a
 * shadow-casting node changed since that map was made. Everything else about the scene (materials,
 * textures, the node set, which nodes cast shadows) is fixed at creation. Needs a current GL context. */
typedef struct lm_direct lm_direct;

/* settings NULL = defaults; they are fixed for the object's life. a (may be NULL): the lightmap atlas
 * whose uvs the vertices carry, so that the first pass can add the frame's indirect light
 * (lm_direct_set_indirect). */
lm_status lm_direct_create(const lm_scene *s, const lm_atlas *a, const lm_direct_settings *settings, lm_direct **out,
                           lm_error *err);
void lm_direct_free(lm_direct *d);
/* The shadow maps' work per update: between lm_direct_begin_update and lm_direct_end_update the draws
 * re-render at most `maps` stale shadow maps together (a light's map never made is drawn whatever the
 * count), the rest keep their last map until a later update: those of the brightest lights nearest to
 * what moved first, each map's priority growing with the updates it has waited (direct.c, refresh_maps).
 * maps < 0, and outside an update: every stale map. So a scene with 56 lights whose cube moves spreads
 * the 56 maps it needs over 14 updates at 4 instead of one update of 268 ms on llvmpipe. */
void lm_direct_begin_update(lm_direct *d, int maps);
void lm_direct_end_update(lm_direct *d);
/* Stale shadow maps left for a later update by the last draw (0 when all are current), and whether
 * emitter i's is one of them. */
int lm_direct_stale_maps(const lm_direct *d);
int lm_direct_map_stale(const lm_direct *d, int i);
/* The sides the live lights' maps get now: a point light's cube face and a spot or directional map. */
void lm_direct_map_sides(const lm_direct *d, int *cube, int *map);
/* Renders into the view's picture of the frame's targets (lm_direct_targets, frame_targets.h), width x
 * height, no read-back, where the later passes add to it before lm_direct_read. em and s->bounds current
 * as for lm_render_direct. */
lm_status lm_direct_draw(lm_direct *d, const lm_scene *s, const lm_emitters *em, const lm_view *view, int width,
                         int height, lm_error *err);
/* lm_direct_draw, then the image read back as RGB floats (row 0 at the top). */
lm_status lm_direct_render(lm_direct *d, const lm_scene *s, const lm_emitters *em, const lm_view *view, int width,
                           int height, float *rgb, lm_error *err);
/* The scene from view into the probe's picture of the frame's targets (LM_FRAME_PROBE), size x size, node
 * `skip`'s vertices left out (-1: none): one face of skip's environment map (reflections.h). The first
 * pass's indirect term and the shadow maps are the frame's. */
lm_status lm_direct_draw_probe(lm_direct *d, const lm_scene *s, const lm_emitters *em, const lm_view *view, int size,
                               int skip, lm_error *err);
/* The scene seen in a flat reflector into the mirror's picture of the frame's targets (LM_FRAME_MIRROR),
 * width x height, every triangle: `mirrored` is the frame's view reflected about the reflector's plane
 * (view matrix times the reflection, eye reflected), plane = (n, w) the world plane whose side
 * dot(n, p) + w >= 0 is kept (the side the eye is on; what lies behind the reflector is not in it), node
 * `skip`'s vertices left out. The reflection turns the triangles' winding over; the draw takes that into
 * account, so that a surface's front is its front. reflections.h looks the picture up. */
lm_status lm_direct_draw_mirror(lm_direct *d, const lm_scene *s, const lm_emitters *em, const lm_view *mirrored,
                                int width, int height, int skip, const float plane[4], lm_error *err);
/* The triangles an environment face draws (settings.probe_lod), the skipped node's included. */
uint32_t lm_direct_probe_triangles(const lm_direct *d);
/* Draws only node's triangles with prog, a program on glsl/direct_vs.glsl (its uniforms set by the caller;
 * has_tex and the base colour texture on unit 2 set here per texture group). */
void lm_direct_draw_node(const lm_direct *d, unsigned prog, int node);
/* The frame's targets the draws fill (frame_targets.h): what the later passes bind, read and add to. */
const lm_frame_targets *lm_direct_targets(const lm_direct *d);
/* Shorthands of frame_targets.h on lm_direct_targets(d), for the frame loop, the tests and tools: the
 * view's radiance read back (RGB floats, row 0 at the top), and the depth and kd textures of the view
 * (probe 0) or the probe (1), the view's G-buffer and radiance. */
lm_status lm_direct_read(lm_direct *d, float *rgb, lm_error *err);
unsigned lm_direct_depth_texture(const lm_direct *d, int probe);
unsigned lm_direct_kd_texture(const lm_direct *d, int probe);
unsigned lm_direct_gbuffer_texture(const lm_direct *d);
unsigned lm_direct_radiance_texture(const lm_direct *d);
/* The indirect term the first pass adds at each visible surface's lightmap uv: the premultiplied atlas
 * of lm_composite_indirect (rgb / a = albedo / pi * E_IIM; a = 0: none). 0 = none. Needs an atlas at
 * lm_direct_create; surfaces without a chart (mirror, glass) and the background get none. turn_tex (NULL
 * or zeros: none): the IIM's turn maps (gpu/gather/iim.h), by which a footprint texel's value turns with
 * the pixel's shading normal (glsl/indirect.glsl; docs/charts.md, "Turning with the normal"). */
void lm_direct_set_indirect(lm_direct *d, unsigned lit_tex, const unsigned turn_tex[3]);
/* Whether the view's draws write its G-buffer (lm_direct_gbuffer_texture): on from lm_direct_create; off
 * leaves it as the last draw that wrote it, for a frame without per-pixel photon gathers. */
void lm_direct_write_gbuffer(lm_direct *d, int on);
/* For the per-pixel photon gathers, with no indirect term set: coverage (one float per atlas texel, NULL:
 * none) is the part of the gathers' kernel on each texel's surface, c (photonmap/aim.h
 * lm_aim_kernel_coverage). The first pass then writes 1 / c, taken over the valid texels of the pixel's
 * bilinear footprint, into the kd texture's alpha (1 where no texel is, or without coverage). Copied to
 * a texture the object owns. Needs an atlas at lm_direct_create (else ignored). Errors: out of memory. */
lm_status lm_direct_set_coverage(lm_direct *d, const float *coverage, lm_error *err);
/* Shadow maps rendered since creation (each cube map counts once), for tests and statistics. */
long lm_direct_shadow_maps_rendered(const lm_direct *d);
/* The directional lights' maps fitted to the frame's view (docs/direct.md, "The view's sun maps"): the
 * nearest quarter of the view's depth into the scene (cascade 0) and all of it (cascade 1). */
#define LM_VIEW_CASCADES 2
/* Those maps rendered since creation, counted apart from lm_direct_shadow_maps_rendered; and whether
 * emitter i has cascade c now, with its texel's world size. */
long lm_direct_view_maps_rendered(const lm_direct *d);
int lm_direct_view_map_texel(const lm_direct *d, int i, int cascade, float *texel);
/* How many shadow maps it holds now (a removed light's is given back at the next draw). */
int lm_direct_shadow_maps_held(const lm_direct *d);

/* One-shot: creates an lm_direct, renders, reads back and frees it.
 * Renders width x height RGB floats into rgb (3 per pixel, row 0 at the top). em must be current
 * (lm_emitters_update) and s->bounds current (lm_scene_update_bounds) for the directional fit.
 * Needs a current GL context. settings NULL = defaults. */
lm_status lm_render_direct(const lm_scene *s, const lm_emitters *em, const lm_view *view, int width,
                           int height, const lm_direct_settings *settings, float *rgb, lm_error *err);

#endif
