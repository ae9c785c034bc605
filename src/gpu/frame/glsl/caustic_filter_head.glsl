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
// Whether the light changes across the (2k + 1)^2 pixels around c by more than photon noise: the photons
// in each of its four quadrants (the splat's photon count, flux's alpha, read from the mip level whose
// texels are about a quadrant's side, at the quadrant's centre) against their mean, a difference over
// 3 sqrt(mean) (three standard deviations, were they Poisson; the QMC photons vary less) being
// structure. An edge of the light or a focal spot trips it; an even patch, however dense, does not.
bool structured(vec2 c) {
    float h = float(2 * K + 1) * 0.25, lq = floor(log2(2.0 * h)), a = 4.0 * h * h;
    float q[4], m = 0.0;
    for (int i = 0; i < 4; i++) {
        vec2 o = vec2((i & 1) == 0 ? -h : h, (i & 2) == 0 ? -h : h);
        q[i] = textureLod(flux, (c + o) / size, lq).a * a;
        m += 0.25 * q[i];
    }
    for (int i = 0; i < 4; i++)
        if (abs(q[i] - m) > 3.0 * sqrt(m)) return true;
    return false;
}
// The filter's scale s at pixel centre c: its taps lie s pixels apart, each the splat's mean over about
// 2s pixels (its mipmaps, the nearest level). 1 (the paper's filter) where its (2k + 1)^2 pixels hold
// `need` photons; where they hold fewer, the scale whose (2k + 1) s pixels a side hold about that many,
// up to 2^levels (thin light spread over more pixels); where they hold more and the light there has
// structure (an edge, a focal spot), smaller, down to `smallest`, so that they hold about `need` (the
// spot as sharp as its photons allow, while an even patch keeps the whole filter and its low noise).
// The photons a filter of scale 2^L holds are its area times the density over a window around c: the
// mean of flux's alpha (photons a pixel) over one mip texel of 2^lw s >= (2k + 1) s pixels, read
// bilinearly (for an even density the count grows 4x a level, so s moves continuously from one level
// to the next); counting the window's photons instead would credit k = 2's 5 x 5 filter with its 8 x 8
// window's. 0 when no photon lies within the widest window.
float filter_scale(vec2 c, float smallest) {
    if (need <= 0.0) return 1.0;
    float lw = ceil(log2(float(2 * K + 1))); // the window: the mip level whose texels span 2k + 1 pixels or more
    for (int L = 0; L <= levels; L++) {
        float s = exp2(float(L)), side = float(2 * K + 1) * s;
        float n = textureLod(flux, c / size, float(L) + lw).a * side * side;
        if (n >= need && L == 0)
            return smallest < 1.0 && structured(c) ? clamp(sqrt(need / n), smallest, 1.0) : 1.0;
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
