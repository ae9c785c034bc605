// kd / pi x E at every pixel, kd as the direct light's first pass found it (0 on mirror, glass and the
// back of single-sided surfaces).
#version 450 core
uniform sampler2D irr, kd;
out vec4 frag;
#include "../../gl/glsl/pi.glsl"
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    frag = vec4(texelFetch(kd, p, 0).rgb / PI * texelFetch(irr, p, 0).rgb, 0.0);
}
