// Per photon: projected to its pixel's centre, or out of the clip volume when dropped (caustic_pass.h):
// also where that pixel shows no diffuse lobe (kd 0), so that light lies only where the mask says.
#version 450 core
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 ng;
layout(location = 2) in vec3 flux;
layout(location = 3) in float count; /* the photons the point stands for (caustic_pass.c, make_points) */
uniform mat4 view_proj, inv_proj;
uniform vec3 eye, view_dir;
uniform int ortho;
uniform vec2 size;
uniform float pix_area, pix_side;
uniform sampler2D depth, kd;
uniform int have_kd;
out vec3 v_irr, v_flux;
out float v_count;
#include "caustic_receiver.glsl"
float view_depth(vec2 ndc, float z) {
    vec4 v = inv_proj * vec4(ndc, z, 1.0);
    return -v.z / v.w;
}
void main() {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    vec4 c = view_proj * vec4(pos, 1.0);
    if (c.w <= 0.0) return;
    vec3 ndc = c.xyz / c.w;
    if (any(greaterThanEqual(abs(ndc.xy), vec2(1.0))) || abs(ndc.z) > 1.0) return;
    ivec2 px = clamp(ivec2(floor((ndc.xy * 0.5 + 0.5) * size)), ivec2(0), ivec2(size) - 1);
    if (have_kd != 0 && !shows_caustic(texelFetch(kd, px, 0).rgb))
        return; // a pixel whose surface shows no caustic (the mask pass's rule)
    vec3 V = ortho != 0 ? view_dir : normalize(eye - pos);
    float cv = dot(ng, V);
    if (cv <= 1e-4) return;
    float tp = view_depth(ndc.xy, ndc.z);
    float ts = view_depth(ndc.xy, texelFetch(depth, px, 0).r * 2.0 - 1.0);
    float s = ortho != 0 ? pix_side : tp * pix_side;
    float tan_v = sqrt(max(0.0, 1.0 - cv * cv)) / cv;
    if (tp > ts + s * (1.0 + 2.0 * min(tan_v, 50.0)) + 1e-5 * tp) return;
    float area = pix_area / cv;
    if (ortho == 0) {
        float d = length(pos - eye), ca = tp / d;
        area *= d * d * ca * ca * ca;
    }
    v_irr = flux / area;
    v_flux = flux;
    v_count = count;
    gl_Position = vec4((vec2(px) + 0.5) / size * 2.0 - 1.0, 0.0, 1.0);
}
