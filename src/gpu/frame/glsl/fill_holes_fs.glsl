// The premultiplied atlas's holes (gpu/frame/composite.h), drawn where premultiply_fs.glsl marked them
// (depth 0) and nowhere else: a texel that takes indirect light but is invalid (covered, or seeing back
// faces) takes the mean of its surface's valid texels on the nearest diamond around it (|dx| + |dy| = d,
// d up to reach) at a weight far under a valid texel's. Where a pixel's bilinear footprint holds a valid
// texel, that texel decides; where it holds none (a floor under a ball hovering less than a texel over
// it), the pixel shows its surface's light around the hole instead of black. It reads the IIM and the
// coverage, not the target it writes.
#version 450 core
uniform sampler2D covered; // r: takes indirect light; g: its surface + 1
uniform sampler2D iim;     // E, back-face fraction
uniform float limit;
uniform int reach;         // LM_COMPOSITE_FILL_REACH
out vec4 frag;
#include "../../gl/glsl/pi.glsl"
const float FILL_WEIGHT = 1.0 / 1024.0;

// Adds texel n's E and a count of 1 to sum where it is a valid texel of surface g.
void add_if_valid(ivec2 n, float g, inout vec4 sum) {
    if (any(lessThan(n, ivec2(0))) || any(greaterThanEqual(n, textureSize(iim, 0))))
        return;
    vec4 c = texelFetch(covered, n, 0);
    if (c.r == 0.0 || c.g != g)
        return;
    vec4 e = texelFetch(iim, n, 0);
    if (e.a <= limit)
        sum += vec4(e.rgb, 1.0);
}

void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    float g = texelFetch(covered, q, 0).g;
    for (int d = 1; d <= reach; d++) {
        vec4 sum = vec4(0.0);
        for (int i = 0; i < d; i++) { // the diamond's four sides, each point once
            add_if_valid(q + ivec2(d - i, i), g, sum);
            add_if_valid(q + ivec2(-i, d - i), g, sum);
            add_if_valid(q + ivec2(i - d, -i), g, sum);
            add_if_valid(q + ivec2(i, i - d), g, sum);
        }
        if (sum.a > 0.0) {
            frag = vec4(sum.rgb / (sum.a * PI), 1.0) * FILL_WEIGHT;
            return;
        }
    }
    frag = vec4(0.0);
}
