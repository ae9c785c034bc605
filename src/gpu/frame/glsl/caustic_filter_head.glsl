#version 450 core
uniform sampler2D irr, flux, depth;
uniform mat4 inv_proj;
uniform vec2 size;
uniform int ortho;
uniform float pix_side;
out vec4 frag;
const int K = FILTER_K;
#include "../../gl/glsl/pi.glsl"
vec3 view_pos(ivec2 q) {
    vec2 ndc = (vec2(q) + 0.5) / size * 2.0 - 1.0;
    vec4 v = inv_proj * vec4(ndc, texelFetch(depth, q, 0).r * 2.0 - 1.0, 1.0);
    return v.xyz / v.w;
}
