// A cone of world radius R = k footprints at x over the photons' flux at each pixel's view position.
#include "caustic_filter_head.glsl"
void main() {
    ivec2 x = ivec2(gl_FragCoord.xy), hi = ivec2(size) - 1;
    vec3 px = view_pos(x);
    float R = max(float(K), 0.5) * (ortho != 0 ? pix_side : -px.z * pix_side);
    vec3 e = vec3(0.0);
    for (int j = -K; j <= K; j++)
        for (int i = -K; i <= K; i++) {
            ivec2 q = x + ivec2(i, j);
            if (any(lessThan(q, ivec2(0))) || any(greaterThan(q, hi))) continue;
            vec4 f = texelFetch(flux, q, 0);
            if (f.a == 0.0) continue;
            float w = 1.0 - length(view_pos(q) - px) / R;
            if (w > 0.0) e += w * f.rgb;
        }
    frag = vec4(e / (PI * R * R / 3.0), 1.0);
}
