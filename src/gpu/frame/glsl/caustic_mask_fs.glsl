// Where the caustic filter may read light, into the splat's alpha: pixels with a diffuse lobe (kd > 0),
// not mirror, glass, metal, the background or a back face, where a caustic would not show. Without kd
// (a pass run with no frame targets) every pixel.
#version 450 core
uniform sampler2D kd;
uniform int have_kd;
layout(location = 0) out vec4 frag;
#include "caustic_receiver.glsl"
void main() {
    bool shows = have_kd == 0 || shows_caustic(texelFetch(kd, ivec2(gl_FragCoord.xy), 0).rgb);
    frag = vec4(0.0, 0.0, 0.0, shows ? 1.0 : 0.0);
}
