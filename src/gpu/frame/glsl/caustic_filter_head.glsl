#version 450 core
uniform sampler2D irr, flux, depth;
uniform mat4 inv_proj;
uniform vec2 size;
uniform int ortho;
uniform float pix_side;
uniform float need;   // photons a filter should hold (0: the paper's fixed filter)
uniform int levels;   // the filter widens up to 2^levels times
out vec4 frag;
const int K = FILTER_K;
#include "../../gl/glsl/pi.glsl"
vec3 view_pos(ivec2 q) {
    vec2 ndc = (vec2(q) + 0.5) / size * 2.0 - 1.0;
    vec4 v = inv_proj * vec4(ndc, texelFetch(depth, q, 0).r * 2.0 - 1.0, 1.0);
    return v.xyz / v.w;
}
// The filter's scale s at pixel centre c: its taps lie s pixels apart, each the splat's mean over about
// 2s pixels (its mipmaps, the nearest level). 1 (the paper's filter) where the window around it (the
// 2^lw >= 2k + 1 pixels a side of one mip level, read bilinearly) holds `need` photons; where it holds
// fewer, the scale whose window of 2^lw s pixels holds about that many, up to 2^levels (photons counted
// from the mipmaps of flux's alpha, photons a pixel; for an even density the count grows 4x a level, so
// s moves continuously from one level to the next); where it holds more than SHARP, smaller, down to
// `smallest`, so that it holds about SHARP (a focal spot stays sharp). 0 when no photon lies within the
// widest window.
const float SHARP = 128.0;
float filter_scale(vec2 c, float smallest) {
    if (need <= 0.0) return 1.0;
    float lw = ceil(log2(float(2 * K + 1))); // the window: the mip level whose texels span 2k + 1 pixels or more
    for (int L = 0; L <= levels; L++) {
        float s = exp2(float(L)), w = exp2(float(L) + lw);
        float n = textureLod(flux, c / size, float(L) + lw).a * w * w;
        if (n >= need && L == 0) return clamp(sqrt(max(SHARP, need) / n), smallest, 1.0);
        if (n >= need) return max(0.5 * s, s * sqrt(need / n));
        if (L == levels && n == 0.0) return 0.0; // no photon within reach: E is 0, no taps read
    }
    return exp2(float(levels));
}
// The mip level a tap s pixels from the next reads: the mean over about twice its spacing (2 log2 s up to
// s = 2, then log2 s + 1), so the taps overlap instead of sampling the mipmaps at a stride that beats
// with their texels; below 0 (s < 1) level 0, read between its texels.
float tap_lod(float s) { return min(2.0 * log2(s), log2(s) + 1.0); }
// Whether pixel c shows a receiver (the mask in irr's alpha): elsewhere nothing shows a caustic, E is 0.
bool receiver(vec2 c) { return texelFetch(irr, ivec2(c), 0).a > 0.0; }
bool on_screen(vec2 q) { return all(greaterThanEqual(q, vec2(0.0))) && all(lessThan(q, size)); }
