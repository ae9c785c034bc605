/* The frame's render targets, in one place (docs/direct.md): the picture of the view, the picture of
 * an environment map's face (the probe) and the picture of the view mirrored in a flat reflector (the
 * mirror, reflections.h), each an RGBA32F target of colour attachments (three the view's, two the others')
 * and a depth texture that the direct light's first pass lays down and the later passes read or add to:
 *
 *   attachment 0  radiance (rgb; the passes after the first add to it: the direct light's further
 *                 lights, the caustics, the reflections, the per-pixel photon gathers)
 *   attachment 1  kd, the diffuse lobe at the visible point (rgb; a: 1, or 1 / c, lm_direct_set_coverage),
 *                 for the passes that add kd / pi x an irradiance per pixel (caustics, photon gathers)
 *   attachment 2  the G-buffer: world position (rgb) and the packed eye-side shading normal (a;
 *                 glsl/gbuffer_normal.glsl unpacks it), for the per-pixel photon gathers; the view's alone
 *   depth         24-bit GL window depth, for the caustic splat's depth test and the reflections'
 *
 * Every texture is GL rows bottom-up. The targets are kept between frames and re-made only when a size
 * changes (offscreen.h, lm_float_target). The direct-light pass (direct.h) holds one lm_frame_targets and
 * draws into it; every other pass reaches the targets through lm_direct_targets and the functions here.
 * Needs a current GL context; zero-initialise before the first lm_frame_targets_ensure. Not thread-safe
 * (GL state). */
#ifndef LM_FRAME_TARGETS_H
#define LM_FRAME_TARGETS_H

#include <stddef.h>

#include "../../core/error.h"
#include "../gl/offscreen.h"

/* Which picture: the view's frame, the environment map face being drawn, or the view mirrored in a flat
 * reflector. */
enum { LM_FRAME_VIEW = 0, LM_FRAME_PROBE = 1, LM_FRAME_MIRROR = 2, LM_FRAME_PICTURES = 3 };

typedef struct {
    lm_float_target t[LM_FRAME_PICTURES];
    float *scratch;       /* read-back of the view's radiance, width x height RGBA */
    size_t scratch_px;
} lm_frame_targets;

void lm_frame_targets_free(lm_frame_targets *f);
/* Makes picture `which` width x height (re-made only when its size changed) and binds it, every
 * attachment drawn to, the viewport set; does not clear. Errors: out of GL memory. */
lm_status lm_frame_targets_ensure(lm_frame_targets *f, int which, int width, int height, lm_error *err);
/* The framebuffer of picture `which`, for a pass that binds it with its own draw buffers and viewport. */
unsigned lm_frame_targets_fbo(const lm_frame_targets *f, int which);
/* Binds picture `which` for a pass that adds radiance: attachment 0 only (kd and the G-buffer stay as
 * they are), the viewport its size. */
void lm_frame_targets_bind_radiance(const lm_frame_targets *f, int which);
/* The textures of picture `which` (0 before its first lm_frame_targets_ensure); the G-buffer is the
 * view's. */
unsigned lm_frame_targets_radiance(const lm_frame_targets *f, int which);
unsigned lm_frame_targets_kd(const lm_frame_targets *f, int which);
unsigned lm_frame_targets_depth(const lm_frame_targets *f, int which);
unsigned lm_frame_targets_gbuffer(const lm_frame_targets *f);
/* The view's radiance read back as RGB floats (width x height x 3, row 0 at the top). Errors: out of
 * memory for the read-back, a GL error. */
lm_status lm_frame_targets_read(lm_frame_targets *f, float *rgb, lm_error *err);
/* The view's kd (attachment 1) read back the same way. */
lm_status lm_frame_targets_read_kd(const lm_frame_targets *f, float *rgb, lm_error *err);

#endif
