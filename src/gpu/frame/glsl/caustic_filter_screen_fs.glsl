// Eq. 4 normalized by its weights' sum: each photon's Phi / A_pix spread over the filter's pixels.
#include "caustic_filter_head.glsl"
void main() {
    ivec2 x = ivec2(gl_FragCoord.xy), hi = ivec2(size) - 1;
    float top = sqrt(1.0 + 2.0 * float(K * K)), wsum = 0.0;
    vec3 e = vec3(0.0);
    for (int j = -K; j <= K; j++)
        for (int i = -K; i <= K; i++) {
            float w = top - sqrt(float(i * i + j * j));
            wsum += w;
            ivec2 q = x + ivec2(i, j);
            if (all(greaterThanEqual(q, ivec2(0))) && all(lessThanEqual(q, hi)))
                e += w * texelFetch(irr, q, 0).rgb;
        }
    frag = vec4(e / wsum, 1.0);
}
