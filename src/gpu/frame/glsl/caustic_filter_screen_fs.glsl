// Eq. 4 normalized by the weights' sum over the taps that are receivers (irr's alpha, the mask): each
// photon's Phi / A_pix spread over the filter's receiver pixels, so light next to a mirror, glass or the
// background is not diluted by pixels that cannot hold it; taps filter_scale pixels apart (1: the
// paper's filter, texel by texel).
#include "caustic_filter_head.glsl"
void main() {
    vec2 x = gl_FragCoord.xy;
    if (!receiver(x)) { frag = vec4(0.0); return; }
    float s = filter_scale(x, 1.0 / 16.0), lod = tap_lod(s);
    if (s == 0.0) { frag = vec4(0.0); return; }
    float top = sqrt(1.0 + 2.0 * float(K * K)), wsum = 0.0;
    vec3 e = vec3(0.0);
    for (int j = -K; j <= K; j++)
        for (int i = -K; i <= K; i++) {
            vec2 q = x + vec2(i, j) * s;
            if (!on_screen(q)) continue;
            float w = top - sqrt(float(i * i + j * j));
            vec4 t = s == 1.0 ? texelFetch(irr, ivec2(q), 0) : textureLod(irr, q / size, lod);
            e += w * t.rgb;
            wsum += w * t.a;
        }
    frag = vec4(wsum > 0.0 ? e / wsum : vec3(0.0), 1.0);
}
