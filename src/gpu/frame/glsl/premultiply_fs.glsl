#version 450 core
uniform sampler2D covered;
uniform sampler2D iim;
uniform float limit;
out vec4 frag;
#include "../../gl/glsl/pi.glsl"
void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    vec4 e = texelFetch(iim, q, 0);
    float w = texelFetch(covered, q, 0).r * (e.a <= limit ? 1.0 : 0.0);
    frag = vec4(e.rgb * (w / PI), w);
}
