// Exposure, clamp, then the sRGB transfer: the same tone map as lm_tonemap_srgb8.
#version 450 core
in vec2 v_uv;
uniform sampler2D atlas;
uniform float exposure;
out vec4 frag;
vec3 srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
void main() {
    if (v_uv.x < 0.0) { frag = vec4(0.5, 0.5, 0.5, 1.0); return; }
    frag = vec4(srgb(exposure * texture(atlas, v_uv).rgb), 1.0);
}
