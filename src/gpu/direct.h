/* Direct light per pixel (docs/direct.md): the scene seen from an lm_view, each pixel holding the
 * radiance (linear RGB) leaving the visible surface towards the eye from the direct light of every point,
 * spot and directional light, shadowed by shadow maps with PCF, plus the emitted radiance of emissive
 * materials. Light from emissive meshes onto other surfaces is not here (it reaches the image through the
 * IIMs); mirror and glass are black (their reflections are a later item). */
#ifndef LM_DIRECT_H
#define LM_DIRECT_H

#include "../core/error.h"
#include "../scene/scene.h"
#include "../trace/lights.h"
#include "camera.h"

typedef struct {
    int map_size;         /* 2D shadow maps (spot, directional), texels per side. Default 1024 */
    int cube_size;        /* point-light cube map, texels per face side. Default 512 */
    int pcf_radius;       /* PCF taps: (2r+1)^2, 1 texel apart. Default 1 (3x3); 0 = hard shadows */
    float normal_offset;  /* receiver moved along its normal by this many texels. Default 1 */
    float slope_bias;     /* depth bias per texel and unit slope tan(theta), times (pcf_radius + 1). Default 1 */
    float max_slope;      /* tan(theta) is clamped here (theta near 90 degrees). Default 10 */
    float const_bias;     /* constant depth bias in texels. Default 0.5 */
} lm_direct_settings;

void lm_direct_settings_default(lm_direct_settings *s);

/* Renders width x height RGB floats into rgb (3 per pixel, row 0 at the top). em must be current
 * (lm_emitters_update) and s->bounds current (lm_scene_update_bounds) for the directional fit.
 * Needs a current GL context. settings NULL = defaults. */
lm_status lm_render_direct(const lm_scene *s, const lm_emitters *em, const lm_view *view, int width,
                           int height, const lm_direct_settings *settings, float *rgb, lm_error *err);

#endif
