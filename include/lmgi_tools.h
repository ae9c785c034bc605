/* lmgi tools — the lab beside the runtime: the reference solver every error figure is measured
 * against, a frame checked against it, pictures (tone mapping, image files), output directories and the
 * density `lmgi run` loads a scene at. The `lmgi` command is built on lmgi.h and this header alone; an
 * application that only keeps lightmaps up to date needs lmgi.h only. Same conventions as lmgi.h (errors,
 * NULL, coordinates), same library (liblmgi), same lmgi_ prefix. */
#ifndef LMGI_TOOLS_H
#define LMGI_TOOLS_H

#include "lmgi.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The atlas texel count `lmgi run` loads a scene at when given no texel size: what an updater gathering
 * texels_per_frame texels an update (0: 20) regathers in full in 90 updates (3 s at 30 fps); pass it as
 * lmgi_options.target_texels. Lightmaps much denser than their texel budget cannot follow what moves. */
LMGI_API int lmgi_atlas_texels_for(int texels_per_frame);

/* ------------------------------------------------------------------------------------------------------
 * Reference: the converged answer every error figure is measured against (docs/reference.md): Monte
 * Carlo path tracing, per lightmap texel and per pixel, each entry sampled until its relative standard
 * error reaches the target, and light tracing for the caustics. Deterministic for a scene, desc and
 * camera; results are cached on disk under a key of all of them, so asking again costs a file read.
 * Cost: seconds (small atlases, a 96 x 96 picture) to minutes; the caustic part adds caustic_photons
 * photons per (light, mirror or glass node) pair. Progress lines go to stderr at verbosity 2.
 * Thread-safety: one call at a time per scene (other scenes' calls may run beside it); it uses every
 * core.
 *
 * The light is split by the path it came along (docs/reference.md, "Which part carries which light"),
 * so that every pass is checked against its own part. Mirror and glass are specular; the receiver is
 * the texel, or the first surface an eye ray meets when that is not mirror or glass:
 *   direct       point, spot and directional lights straight at the receiver;
 *   caustic      light from any emitter that reached the receiver off mirrors and glass only (light
 *                tracing: the paths a path tracer cannot find from point lights);
 *   lost         light seen by the receiver in mirrors and glass that last came off an ordinary
 *                surface: the runtime's gather sees mirrors black, so no pass carries it;
 *   iim          (texels) the rest: emissive surfaces seen directly and everything whose first bounce
 *                from the receiver is off an ordinary surface;
 *   pixels add   emission (the surface's own), indirect (the iim-like rest, shaded) and reflections
 *                (everything seen where the eye ray first meets mirror or glass).
 * full is the sum of the parts: direct + iim + caustic + lost for texels, emission + direct + indirect +
 * caustic + lost + reflections for pixels (to float rounding). */
typedef struct {
    float target_error;     /* relative standard error per entry to stop at (0: 0.02) */
    int samples;            /* paths per entry per pass (0: 64; entries take at least two passes) */
    uint32_t seed;          /* (0: 1) */
    const char *cache_dir;  /* NULL: $LMGI_CACHE, else build/reference-cache */
    int no_cache;           /* 1: neither read nor write the cache */
    int caustic_photons;    /* light-traced photons per (emitter, mirror or glass node) pair, 1..16777216
                             * (0: 1048576) */
} lmgi_reference_desc;

/* A reference solution as images, width x height x 3 linear floats, top row first for pixels, row 0 at
 * v = 0 for texels (the lightmaps' layout; 0 outside texels). Texels hold irradiance, pixels radiance. */
typedef struct {
    int width, height;
    float *full;            /* texels: irradiance E from all light; pixels: radiance reaching the eye */
    float *iim;             /* texels: the iim part (what the IIM holds); pixels: NULL */
    float *radiance;        /* texels: albedo / pi x E (what the AIM approximates); pixels: NULL */
    float *direct;          /* point, spot and directional lights straight at the receiver (pixels: as it
                             * reflects them towards the eye) */
    float *caustic;         /* light off mirrors and glass only, straight from an emitter */
    float *lost;            /* light seen in mirrors and glass that last came off an ordinary surface */
    float *emission;        /* pixels: the surface's own emission; texels: NULL */
    float *indirect;        /* pixels: the iim-like rest as the surface reflects it; texels: NULL */
    float *reflections;     /* pixels: everything seen where the eye ray first meets mirror or glass; texels: NULL */
    float target_error;     /* the relative standard error it sampled to (the desc's, or the default) */
    uint32_t entries, converged; /* texels or pixels, and how many reached the target (the rest hit the cap) */
    uint64_t samples;       /* paths traced over all entries */
    uint64_t paths_cut;     /* paths still going after 65536 bounces, their light past that missing: 0 but
                             * where light never dies out (a closed room of albedo 1); a warning says so */
    double mean_rel_se, max_rel_se; /* achieved relative standard error per entry (of the path-traced parts) */
    double seconds;         /* computing time (the first computation's when it came from the cache) */
    uint64_t caustic_photons; /* photons the caustic part traced (0: the scene has no mirror, glass or light) */
    double caustic_seconds; /* its share of seconds */
    int from_cache;
} lmgi_reference;

/* Every texel of the scene's atlas. NULL scene or out: LMGI_ERR_INVALID; NULL desc: the defaults; a
 * target_error, samples or caustic_photons out of range: LMGI_ERR_INVALID naming it. out is zeroed on
 * failure. */
LMGI_API lmgi_status lmgi_reference_texels(const lmgi_scene *scene, const lmgi_reference_desc *desc,
                                           lmgi_reference *out, lmgi_error *err);
/* The picture a perspective camera sees (lmgi_scene_camera, or the application's). An orthographic or
 * non-invertible camera, sides outside 1..16384: LMGI_ERR_INVALID. */
LMGI_API lmgi_status lmgi_reference_pixels(const lmgi_scene *scene, const lmgi_reference_desc *desc,
                                           const lmgi_camera *cam, int width, int height, lmgi_reference *out,
                                           lmgi_error *err);
LMGI_API void lmgi_reference_free(lmgi_reference *r); /* NULL: nothing; the struct is zeroed */

/* Check: an updater's composited frame against the reference's pixels of the same camera, the way a user
 * meets the lighting (docs/reference.md, "Frame against reference"). Compared are the pixels whose
 * centre and four neighbours see one surface (edges alias, which is not lighting); mirror and glass
 * pixels and the background are left out, and the frame's totals leave out emissive surfaces too (each
 * still has its row). */
typedef struct {
    int node, material;     /* the surface's node and material ids */
    uint32_t pixels;        /* compared pixels (0: not seen) */
    double frame_mean[3], reference_mean[3]; /* mean radiance over them per channel */
    double ratio[3];        /* frame / reference per channel (1 when both are 0, INFINITY when only the frame is not) */
} lmgi_check_surface;
typedef struct {
    int width, height;
    float *frame, *reference; /* width x height x 3 linear floats, top row first */
    unsigned char *compared; /* per pixel: 1 where it counts */
    int surface_count;      /* lmgi_surface_count */
    lmgi_check_surface *surfaces;
    uint32_t pixels;        /* compared pixels of non-emissive surfaces */
    double frame_mean[3], reference_mean[3], ratio[3]; /* over those pixels */
    double rel_rmse;        /* relative RMSE of the frame over those pixels */
    /* The caustic part (light off mirrors and glass straight from a light, L S+ D; docs/caustics.md): what
     * the frame's caustic pass added (kd / pi x its E) and the reference's, width x height x 3 like frame
     * (0 everywhere in a scene without caustics); their means and ratio per channel and the relative RMSE
     * over the same pixels (ratio 1 and RMSE 0 where both are 0). */
    float *caustic_frame, *caustic_reference;
    double caustic_frame_mean[3], caustic_reference_mean[3], caustic_ratio[3];
    double caustic_rel_rmse;
    float reference_target_error; /* the reference's target relative standard error */
    double reference_rel_se, reference_seconds; /* the reference's own noise and cost */
} lmgi_check_result;
/* Creates an updater on ctx for scene with desc (frame_width x frame_height: the picture, 0 x 0 is
 * 128 x 128; camera: the view), runs `frames` updates (at least 1, 30 per second of animation), compares
 * the last frame with lmgi_reference_pixels at the same camera and frees the updater. NULL ctx, scene or
 * out, a scene that has an updater, frames < 1: LMGI_ERR_INVALID; else the updater's and reference's
 * errors. out is zeroed on failure. */
LMGI_API lmgi_status lmgi_check(lmgi_context *ctx, lmgi_scene *scene, const lmgi_updater_desc *desc,
                                const lmgi_reference_desc *ref, int frames, lmgi_check_result *out,
                                lmgi_error *err);
/* The same for an updater as it is now, between its updates: its picture from cam at width x height, drawn
 * as lmgi_render draws it, against lmgi_reference_pixels of the scene as it is now (its edits included:
 * the reference cache keys on nodes, lights and materials). What an editor's user sees while the
 * lightmaps catch up with an edit (docs/tradeoff.md, "The frame's lag"). NULL u, cam or out, sides outside
 * 1..16384: LMGI_ERR_INVALID; else the render's and reference's errors. out is zeroed on failure. */
LMGI_API lmgi_status lmgi_check_updater(lmgi_updater *u, const lmgi_camera *cam, int width, int height,
                                        const lmgi_reference_desc *ref, lmgi_check_result *out, lmgi_error *err);
LMGI_API void lmgi_check_free(lmgi_check_result *c); /* NULL: nothing; the struct is zeroed */

/* ------------------------------------------------------------------------------------------------------
 * Pictures. EXR keeps the linear numbers; PNG is for people: exposure, a tone map, then sRGB.
 *   LMGI_TONEMAP_NEUTRAL (the default): Khronos PBR Neutral. Colours below 0.76 pass unchanged, brighter
 *     ones are compressed smoothly towards white and desaturated with it, so a bright lit floor keeps its
 *     shading. Automatic exposure meters like a camera: the median lit luminance goes to 0.18.
 *   LMGI_TONEMAP_CLAMP: min(1, k c), the linear look; automatic exposure puts the 99th percentile lit
 *     luminance at 0.9, so large bright areas clip to flat white. */
typedef enum { LMGI_TONEMAP_NEUTRAL = 0, LMGI_TONEMAP_CLAMP } lmgi_tonemap;

/* The exposure `op` picks for `pixels` RGB values (3 floats each); 1 when none is lit or rgb is NULL. */
LMGI_API float lmgi_auto_exposure(lmgi_tonemap op, const float *rgb, size_t pixels);
/* The picture as its PNG would show it, for a window (lmgi view): rgba8[4 i ..] = sRGB of tone map `op` at
 * `exposure` (0: automatic, as lmgi_auto_exposure) of the i-th of `pixels` RGB values, alpha 255. Returns
 * the exposure used; NULL rgb or rgba8, or an unknown op: nothing written, 0. */
LMGI_API float lmgi_tonemap_rgba8(lmgi_tonemap op, float exposure, const float *rgb, size_t pixels,
                                  unsigned char *rgba8);
/* How lmgi_write_image writes; zero-initialised (or NULL) means the defaults. */
typedef struct {
    lmgi_tonemap tonemap;  /* PNG: the tone map (default neutral) */
    float exposure;        /* PNG: the exposure (0: automatic) */
    int half;              /* EXR: 16-bit half floats (half the size, 11 bits, values up to 65504); 0: 32-bit */
} lmgi_image_desc;
/* Writes width x height pixels of `channels` floats (1, 3 or 4; rows top first) to path: ".exr" linear
 * as given, ".png" RGB tone-mapped, alpha dropped. The file appears whole or not at all (written to
 * PATH.partial, then renamed). NULL path or pixels, sizes outside 1..65536, other channel counts, a bad
 * desc, another extension, or a pixel that is NaN or infinite: LMGI_ERR_INVALID (nothing written); a failed
 * write: LMGI_ERR_IO naming the file. Half floats: values beyond 65504 are written as 65504, with a
 * warning that counts them. */
LMGI_API lmgi_status lmgi_write_image(const char *path, int width, int height, int channels, const float *pixels,
                                      const lmgi_image_desc *desc, lmgi_error *err);

/* Writes size bytes to path whole or not at all: through PATH.partial, created exclusively (a file or a
 * link already there is refused, never written through), every write and the close checked, then renamed
 * over path. NULL path or data with size > 0: LMGI_ERR_INVALID; a failed write: LMGI_ERR_IO naming it. */
LMGI_API lmgi_status lmgi_write_file(const char *path, const void *data, size_t size, lmgi_error *err);

/* Output directories (README, "Output directories"; src/core/output_dir.h has the layout): one command's
 * result, written beside the previous one and swapped in only when the command succeeds, so a failed,
 * cancelled or killed command leaves the last good result; lmgi removes or replaces only files it wrote
 * itself, known from a manifest it keeps in the directory (DIR/.lmgi), never by their names.
 *
 * lmgi_output_open makes `dir` (and its parents) if needed and locks it for this command: a second
 * lmgi_output_open of it, from this or another process, is refused (LMGI_ERR_IO naming the holder's
 * process) until the first commits or aborts; a killed process's lock is released by the system. It
 * refuses a directory without lmgi's manifest that holds files unless force is non-zero (the mistake of
 * writing into a home folder). Whatever is in `dir` that lmgi did not place there (not in the manifest,
 * another file put under a listed name, or lmgi's file written over) is never removed or replaced, with or
 * without force. `command` (a-z and -: "bake", "run", ...)
 * names whose result this is: the commit replaces that command's earlier files in `dir` and leaves
 * other commands'. `inputs` (NULL-terminated paths, or NULL) are the files the command reads: none of them
 * is ever replaced or removed (refused at open when the earlier result is one of them, and at commit).
 * lmgi_output_file gives the path to write the new result's file `name` to (a plain file name); it is
 * refused early when `dir` holds a file of that name lmgi did not write, or an input.
 * lmgi_output_work_file gives a path in `dir` itself for a file that must survive a failure (a bake's
 * checkpoint), listed in the manifest at once; the next successful commit of the command removes it.
 * lmgi_output_commit moves the new files in, removes the command's earlier files the new result lacks
 * (a 20-frame run after a 60-frame one leaves 20 frames) and frees the output, whatever it returns;
 * lmgi_output_abort drops the new result and frees the output (NULL: nothing).
 * NULL arguments or a bad name: LMGI_ERR_INVALID; what the file system refuses: LMGI_ERR_IO naming the
 * path. Not thread-safe for one lmgi_output. */
LMGI_API lmgi_status lmgi_output_open(const char *dir, const char *command, int force, const char *const *inputs,
                                      lmgi_output **out, lmgi_error *err);
LMGI_API lmgi_status lmgi_output_file(lmgi_output *o, const char *name, char *path, size_t size, lmgi_error *err);
LMGI_API lmgi_status lmgi_output_work_file(lmgi_output *o, const char *name, char *path, size_t size,
                                           lmgi_error *err);
/* The folder the new result's files go into (DIR/.lmgi-new), for functions that take a directory
 * (lmgi_write_charts); NULL for NULL. */
LMGI_API const char *lmgi_output_folder(const lmgi_output *o);
LMGI_API lmgi_status lmgi_output_commit(lmgi_output *o, lmgi_error *err);
LMGI_API void lmgi_output_abort(lmgi_output *o);

/* ------------------------------------------------------------------------------------------------------
 * Charts as pictures. */
/* Writes DIR/atlas.png (each chart its own colour, free space black) and DIR/surfaces.png (the scene from
 * its camera, or an automatic one, each surface in a flat colour) at width x height (0 = 1024x768).
 * NULL scene or dir: LMGI_ERR_INVALID. */
LMGI_API lmgi_status lmgi_write_charts(const lmgi_scene *scene, const char *dir, int width, int height, lmgi_error *err);

#ifdef __cplusplus
}
#endif

#endif
