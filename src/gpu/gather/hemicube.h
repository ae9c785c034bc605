/* Final gathering with a single-plane hemicube (Larsen & Christensen section 4; DESIGN.md step 4).
 *
 * From a texel's centre, the scene is rendered through one enlarged hemicube front plane: the square
 * [-a, a]^2 at distance 1 along the texel's normal, R x R pixels. A pixel at plane position (x, y)
 * carries the cosine-weighted solid angle it subtends, whose density is 1 / (pi (x^2 + y^2 + 1)^2) per
 * unit plane area (DESIGN.md's weight dA / (pi (x^2 + y^2 + 1)^2) is its midpoint rule). lmgi uses the
 * exact integral of that density over each pixel (closed form, lm_hemicube_pixel_weight), so the
 * weights sum to F(a) = 4/pi * a/sqrt(1+a^2) * atan(a/sqrt(1+a^2)) exactly; the midpoint rule is off by
 * 1.4e-4 at R = 32, a = 1. The part of the hemisphere outside the plane (1 - F(a): 17% at a = 2) is not
 * seen and is assumed to look like the rest:
 *
 *     E = pi * sum(w L) / F(a)                (a uniform sky of radiance L gives exactly pi L)
 *
 * What the plane shows (DESIGN.md "What an IIM holds"): each surface at its AIM radiance (the AIM
 * atlas, dilated into the gutters, sampled bilinearly with the lightmap UVs) plus its material's
 * emitted radiance (an AIM holds only reflected light); mirror and glass triangles, which have no AIM,
 * as black (they still occlude); the back of a single-sided surface as black; nothing hit as the sky
 * radiance; the back of the texel's own surface is skipped (only a simplified copy of it can rise above
 * the texel). Back faces (face normal . view direction > 0, single-sided materials only) are counted by
 * weight: a texel whose back-face fraction is above backface_limit sees the inside of geometry and is
 * invalid (the caller fills it from valid neighbours).
 *
 * GPU work: a batch of up to tiles^2 texels is rendered into one RGBA32F target, one R x R tile per
 * texel (how the tiles are reached: lm_gather_scheme; rgb = radiance, a = 1 on back faces), with reversed
 * float depth (no far plane), `samples` AIM lookups per pixel on the surface's plane and
 * `coverage_samples` MSAA samples resolved before the sum (docs/gather.md: they remove banding and
 * plaid). A compute shader then sums each tile with the weights in float, in a fixed order
 * (deterministic), and writes (E, back-face fraction) with imageStore straight into the texel of an
 * atlas-sized RGBA32F IIM texture. Nothing is read back in the gather; lm_iim_texture_read is for tests
 * and output.
 * With proxy_error > 0 the plane shows the gather proxy (charts/proxy.h) instead of every triangle. */
#ifndef LM_HEMICUBE_H
#define LM_HEMICUBE_H

#include <stdint.h>

#include "../../charts/charts.h"
#include "../../charts/proxy.h"
#include "../../core/error.h"
#include "../../scene/scene.h"
#include "../../trace/direct_irradiance.h"
#include "../../trace/emitter_light.h"
#include "../../trace/rt_scene.h"

/* How a pass puts many texels' planes into one render target (docs/gather.md, "Throughput"). */
typedef enum {
    LM_GATHER_VIEWPORTS = 0, /* one draw per texel into its own viewport tile */
    LM_GATHER_INSTANCED = 1, /* one instanced draw per pass, each instance cut to its tile by clip distances */
    LM_GATHER_LAYERED = 2,   /* one instanced draw per pass into a layered target (needs
                                GL_ARB_shader_viewport_layer_array) */
    LM_GATHER_RAYS = 3       /* no hemicube: ray_samples cosine-weighted strata of the whole hemisphere traced
                                with Embree on every core, the AIM averaged over each stratum's footprint
                                where it meets what it hits (photonmap/hemicube_rim.h with enlargement 0). Its cost
                                grows with the log of the level's triangles, the raster's with the proxy's:
                                the choice where the GL rasterizes in software (docs/gather.md, "Rays") */
} lm_gather_scheme;

/* "viewports", "instanced", "layered" */
const char *lm_gather_scheme_name(lm_gather_scheme s);

typedef struct {
    int resolution;        /* R, pixels per side of the plane (default 32) */
    float enlargement;     /* a, half-side of the plane at distance 1 (default 2: F = 0.831) */
    float sky[3];          /* radiance where nothing is hit (default 0) */
    float backface_limit;  /* back-face weight fraction above which a texel is invalid (default 0.1) */
    float offset;          /* texel centre lifted along its normal by this x scene size (default 1e-4), at most
                            * LM_GATHER_TEXEL_LIFT x the atlas's texel size (lm_gather_lift) */
    int tiles;             /* tiles per side of the render target: tiles^2 texels per pass (default 16) */
    float proxy_error;     /* gather proxy's error bound x scene size (default 0.005; 0: the full scene) */
    lm_gather_scheme scheme; /* default LM_GATHER_VIEWPORTS, the fastest measured (docs/gather.md) */
    int samples;           /* AIM lookups per pixel, 1 or 4 (default 4: no banding from edge-on bright spots) */
    int coverage_samples;  /* coverage samples per pixel (MSAA, 1 to 16; default 4): a small emitter covering a
                              few pixels adds a fraction per pixel instead of all or nothing (no plaid).
                              lm_gather_coverage_for picks it per scene */
    int rim_samples;       /* K, rays per texel into the rim the plane misses, each averaging the AIM over its
                              footprint (photonmap/hemicube_rim.h; default 64: fewer mottle surfaces that see a bright
                              spot near their horizon), with a tracer (lm_gather_set_tracer); 0 or no
                              tracer: the paper's division by F(a) */
    int ray_samples;       /* LM_GATHER_RAYS: strata per texel, rounded down to a square (default 400) */
    int direct_at_hits;    /* LM_GATHER_RAYS with a direct light (lm_gather_set_direct_at_hits): 1 (default) the
                              direct light the AIM computes (punctual lights, emissive triangles) computed
                              where each stratum's ray hits; 0: read from the AIM texel it hits, as the
                              hemicube does */
    float direct_near;     /* with direct_at_hits, emissive triangles in the direct light and the whole AIM
                              given (lm_gather_set_aim_whole): only hits within this many of their own
                              surface's texel widths take the direct light at the hit, further ones read it
                              in the whole AIM (default 16; docs/gather.md, "Near and far hits"); <= 0, or
                              punctual lights alone: every hit */
    float adapt;           /* LM_GATHER_RAYS: a texel whose strata estimate the relative standard error of their
                              mean above this in some channel gets 4 x as many strata more (lm_rim.adapt;
                              docs/gather.md, "Adaptive strata"); 0 (default): the strata alone */
    uint32_t seed;         /* mixed into every texel's sample patterns (the strata's turn and elevations, the
                              emitters' and the rim's samples, a light edit's factors' rays), which are
                              seeded by the texel's index: 0 (default) the index alone; another seed, other
                              patterns, so that a sweep of seeds (`lmgi check --seed`) shows the gather's
                              noise too (lm_gather_texel_seed) */
    int cpu_threads;       /* threads for a pass's CPU share (closed-form emitters, rim rays): 0 (default)
                              one on a software GL, whose rasterizer takes the cores, else every OpenMP
                              thread; n > 0: n. The IIM is the same bit for bit either way */
} lm_hemicube_settings;

void lm_hemicube_settings_default(lm_hemicube_settings *s);
/* The seed of texel t's sample patterns: its index, moved by the settings' seed times 2^32 / the golden
 * ratio (mod 2^32; 0: the index alone), so that seeds 0 and 1 share no texel's pattern on an atlas of under
 * 1.6 billion texels. Every ray a texel casts for the gather or for a light edit's factors (light_scale.h)
 * draws from it. */
static inline uint32_t lm_gather_texel_seed(const lm_hemicube_settings *s, uint32_t t)
{
    return t + s->seed * 0x9e3779b9u;
}

/* The coverage samples a scene calls for: 4 when a triangle is emissive and its light is drawn into the
 * hemicubes (small emitters alias), else 1: with the emitters' light in closed form (closed_form_emitters,
 * lm_gather_set_emitter_light) or none, the AIM's sub-samples handle the rest and coverage samples would
 * only cost time. */
int lm_gather_coverage_for(const lm_scene *s, int closed_form_emitters);

/* F(a): the fraction of the cosine-weighted hemisphere the plane covers (closed form). */
double lm_hemicube_coverage(double a);
/* Exact weight of pixel (i, j) (i along x, 0 at x = -a) of an R x R plane of half-side a. */
double lm_hemicube_pixel_weight(int R, double a, int i, int j);
/* DESIGN.md's midpoint weight dA / (pi (x^2 + y^2 + 1)^2) at the pixel's centre. */
double lm_hemicube_pixel_weight_midpoint(int R, double a, int i, int j);
/* Sum of the exact (midpoint = 0) or midpoint (midpoint = 1) weights over all R^2 pixels. */
double lm_hemicube_weight_sum(int R, double a, int midpoint);
/* Form factor from a differential area at the origin facing +z to the rectangle [x0,x1] x [y0,y1] in the
 * parallel plane at distance d (closed form; a coaxial square of half-side p: F = coverage(p / d)). */
double lm_form_factor_rect(double x0, double x1, double y0, double y1, double d);

typedef struct lm_gather lm_gather;

typedef struct {
    uint32_t texels;       /* texels gathered */
    int passes;            /* render + reduce passes */
    double seconds;        /* wall time including glFinish */
} lm_gather_stats;

/* Compiles the programs and makes the tiled target. Needs a current GL 4.5 context. */
lm_status lm_gather_create(const lm_hemicube_settings *set, lm_gather **out, lm_error *err);
void lm_gather_free(lm_gather *g);
/* Uploads every triangle in world space under the current node matrices, with lightmap UVs, emitted
 * radiance and face normals. Call again after nodes move. With proxy_error > 0 the triangles are those
 * of the gather proxy (proxy.h), built on the first call for (s, a) and kept for later calls. A call that
 * finds (s, a), the node matrices, the materials' emission and sides and the emitter light as the last
 * upload had them uploads nothing (it hashes them: O(nodes + materials)). */
lm_status lm_gather_set_scene(lm_gather *g, const lm_scene *s, const lm_atlas *a, lm_error *err);
/* How many times lm_gather_set_scene made and uploaded the mesh. */
uint64_t lm_gather_scene_uploads(const lm_gather *g);
/* With an emitter light (NULL: none, the default), emissive triangles are drawn without their emission
 * (they still occlude) and each texel gets their irradiance in closed form with sampled visibility
 * instead (trace/emitter_light.h: no plaid from small emitters, no coverage samples needed). Takes
 * effect at the next lm_gather_set_scene; el is borrowed. */
void lm_gather_set_emitter_light(lm_gather *g, const lm_emitter_light *el);
/* With a BVH (NULL: none, the default): the rim of the hemisphere outside the plane is traced
 * (photonmap/hemicube_rim.h, when rim_samples > 0) instead of extrapolated by 1 / F(a), and a covered texel
 * (lm_texel_covered) is invalid (alpha 1), like a texel that sees back faces. rt is borrowed and must
 * describe the scene the gather draws (the same node matrices). */
void lm_gather_set_tracer(lm_gather *g, const lm_rt *rt);
/* With a direct light that computes something (punctual lights or emissive triangles; NULL or neither:
 * off, the default), the rays scheme (LM_GATHER_RAYS, with a tracer) computes that part at each ray's hit
 * (photonmap/hemicube_rim.h), and the AIM it is given must then hold everything else:
 * lm_aim_rest_dilated_rgba, not the whole AIM. The hemicube schemes ignore it. d is copied (its emitters,
 * emissive triangles and tracer are borrowed; the triangles take as many shadow rays at a hit as at an AIM
 * texel's part); its cover distance is not used. */
void lm_gather_set_direct_at_hits(lm_gather *g, const lm_direct_light *d);
/* Whether the gather computes the direct light at its hits (the rays scheme with one set): the AIM to give
 * it is then the rest. */
int lm_gather_direct_at_hits(const lm_gather *g);
/* The emissive triangles' light in closed form that the gather adds to texel `texel`'s irradiance
 * (lm_gather_set_emitter_light; 0 without one): the same point, normal and seed as its gather takes, so the
 * same bits (for a texel gathered over its footprint, the mean over the same points, to float rounding).
 * The IIM less it is what the texel gathered from the AIM. Thread-safe. */
void lm_gather_emitted_at(const lm_gather *g, const lm_scene *s, const lm_atlas *a, uint32_t texel, float e[3]);
/* With the direct light at the hits: the whole AIM as well (lm_aim_dilated_rgba, atlas-sized RGBA, copied),
 * which hits further than settings.direct_near texel widths read instead of the rest and the direct light at
 * the hit; NULL (as after creation) forgets it, and every hit takes its direct light. */
lm_status lm_gather_set_aim_whole(lm_gather *g, const lm_atlas *a, const float *dilated_rgba, lm_error *err);
/* Whether texel `texel` is covered as the gather with a tracer decides it: straight out from its centre
 * along the shading normal there (lm_texel_centre_normal, lifted by lm_gather_lift), other geometry within a texel's width, or the back of a triangle (the texel
 * lies inside a closed mesh) (docs/gather.md, "Covered texels"). */
int lm_texel_covered(const lm_rt *rt, const lm_scene *s, const lm_atlas *a, const lm_hemicube_settings *set,
                     uint32_t texel);
/* How far a texel's eye is lifted off it: set->offset x the scene size, at most LM_GATHER_TEXEL_LIFT x a's
 * texel size. The hemicube's near plane is half of it. */
#define LM_GATHER_TEXEL_LIFT 0.01f
float lm_gather_lift(const lm_hemicube_settings *set, const lm_scene *s, const lm_atlas *a);
/* Where texel `texel` gathers from: its centre lifted along the shading normal by lm_gather_lift (eye), the unit shading normal n the plane faces, and the geometric normal ng turned to n's side
 * (directions below its plane are blocked by the texel's own surface), under the current node matrices. */
void lm_gather_texel_frame(const lm_hemicube_settings *set, const lm_scene *s, const lm_atlas *a, uint32_t texel,
                           float eye[3], float n[3], float ng[3]);
/* The proxy the gather draws; NULL when proxy_error is 0 or before lm_gather_set_scene. */
const lm_proxy *lm_gather_proxy(const lm_gather *g);
/* Uploads the AIM (atlas-sized RGB radiance, width*height*3 floats), dilated into the gutters. */
lm_status lm_gather_set_aim(lm_gather *g, const lm_atlas *a, const float *aim_rgb, lm_error *err);
/* The same for an AIM already dilated as RGBA (lm_aim_dilated_rgba): uploaded as it is. */
lm_status lm_gather_set_aim_dilated(lm_gather *g, const lm_atlas *a, const float *dilated_rgba, lm_error *err);
/* Where each turning texel's turn goes (charts.h, lm_texel_turns and lm_footprint_turn; docs/charts.md,
 * "Turning with the normal"): three atlas-sized textures, channel c's r_c and r_c . nbar as RGBA, written
 * by every later lm_gather_texels for the turning texels it gathers (one gathered at one point gets 0; the
 * other texels' are never written). NULL or zeros: nowhere (the default). The hemicube schemes read each
 * turning texel back once a round to get its points' light apart (a few hundred reads on a level). */
void lm_gather_set_turn(lm_gather *g, const unsigned tex[3]);
/* Gathers texels (indices into a->texels) into iim_tex (an RGBA32F texture of the atlas's size, from
 * lm_iim_texture_create): rgb = indirect irradiance E, a = back-face fraction. stats may be NULL. */
lm_status lm_gather_texels(lm_gather *g, const lm_scene *s, const lm_atlas *a, const uint32_t *texels,
                           uint32_t count, unsigned iim_tex, lm_gather_stats *stats, lm_error *err);

/* An atlas-sized RGBA32F texture, cleared to 0. Returns 0 on failure. */
unsigned lm_iim_texture_create(int width, int height);
void lm_iim_texture_free(unsigned tex);
/* Reads the whole texture back: width*height*4 floats, row y at offset 4 * (y * width + x). */
lm_status lm_iim_texture_read(unsigned tex, int width, int height, float *rgba, lm_error *err);
/* Reads the window win = {x, y, w, h} alone (inside the texture): w*h*4 floats, row 0 at win's y. */
lm_status lm_iim_texture_read_window(unsigned tex, const int win[4], float *rgba, lm_error *err);
/* The radiance a hemicube sees where nothing is hit (settings.sky): the scene's sky, set before each
 * gather by the frame loop, so that a sky edit reaches the next gather. */
void lm_gather_set_sky(lm_gather *g, const float sky[3]);
/* Replaces the whole texture's contents with rgba (as lm_iim_texture_read gives it): a resumed bake's
 * checkpoint (update/bake_checkpoint.h). */
lm_status lm_iim_texture_write(unsigned tex, int width, int height, const float *rgba, lm_error *err);

#endif
