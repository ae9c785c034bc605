// the rule of scene/sky.h: kind 1 gradient, 2 image
#version 450 core
in vec2 ndc;
layout(location = 0) out vec4 radiance;
uniform mat4 inv_view;
uniform vec4 lens; /* the projection's x, y scales and offsets (perspective); x = 0: orthographic */
uniform int kind;
uniform vec3 zenith, horizon;
uniform sampler2D image;
#include "../../gl/glsl/pi.glsl"
void main() {
    vec3 dv = lens.x == 0.0 ? vec3(0.0, 0.0, -1.0)
                            : vec3((ndc.x + lens.z) / lens.x, (ndc.y + lens.w) / lens.y, -1.0);
    vec3 d = normalize(mat3(inv_view) * dv);
    vec3 L;
    if (kind == 1)
        L = horizon + (zenith - horizon) * clamp(d.y, 0.0, 1.0);
    else
        L = zenith * texture(image, vec2(atan(d.x, -d.z) / (2.0 * PI) + 0.5, acos(clamp(d.y, -1.0, 1.0)) / PI)).rgb;
    radiance = vec4(L, 1.0);
}
