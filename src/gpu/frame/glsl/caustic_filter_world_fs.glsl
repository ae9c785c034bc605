// A cone of world radius R = k footprints x filter_scale at x over the photons' flux at each tap's view
// position (a tap, s pixels from the next, holds the flux of s x s pixels: the splat's mean over about
// twice that, as the screen filter reads it, times s^2). Never narrower than the paper's (s >= 1): the
// cone's world radius would fall below a pixel's footprint, between the pixels it sums.
#include "caustic_filter_head.glsl"
void main() {
    vec2 xc = gl_FragCoord.xy;
    if (!receiver(xc)) { frag = vec4(0.0); return; }
    ivec2 x = ivec2(xc);
    vec3 px = view_pos(x);
    float s = filter_scale(xc, 1.0), lod = tap_lod(s);
    if (s == 0.0) { frag = vec4(0.0); return; }
    float R = max(float(K), 0.5) * s * (ortho != 0 ? pix_side : -px.z * pix_side);
    vec3 e = vec3(0.0);
    for (int j = -K; j <= K; j++)
        for (int i = -K; i <= K; i++) {
            vec2 q = xc + vec2(i, j) * s;
            if (!on_screen(q)) continue;
            vec4 f = s == 1.0 ? texelFetch(flux, ivec2(q), 0) : textureLod(flux, q / size, lod) * (s * s);
            if (f.a == 0.0) continue;
            float w = 1.0 - length(view_pos(ivec2(q)) - px) / R;
            if (w > 0.0) e += w * f.rgb;
        }
    frag = vec4(e / (PI * R * R / 3.0), 1.0);
}
