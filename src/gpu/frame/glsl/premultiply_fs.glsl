// Per frame, per atlas texel: E / pi premultiplied by w = covered x valid (back-face fraction
// <= the limit), and w; sampled with the texture unit's bilinear filter, rgb / a is then the bilinear filter
// over the four nearest texels that weighs only covered, valid ones, renormalised. Depth 0 marks the
// holes (covered, invalid) for fill_holes_fs.glsl, whose depth test passes there alone.
#version 450 core
uniform sampler2D covered;
uniform sampler2D iim;
uniform sampler2D thin;   // the caustics' thin light, E (composite.h), read where use_thin is 1
uniform int use_thin;
uniform float limit;
out vec4 frag;
#include "../../gl/glsl/pi.glsl"
void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    vec4 e = texelFetch(iim, q, 0);
    if (use_thin == 1) e.rgb += texelFetch(thin, q, 0).rgb;
    float c = texelFetch(covered, q, 0).r, w = c * (e.a <= limit ? 1.0 : 0.0);
    frag = vec4(e.rgb * (w / PI), w);
    gl_FragDepth = c > 0.0 && w == 0.0 ? 0.0 : 1.0;
}
