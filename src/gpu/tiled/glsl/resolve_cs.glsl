// radiance += kd / pi x E / c, c the kernel's part on the pixel's surface (the kd texture's alpha holds
// 1 / c: lm_direct_set_coverage), as the AIM divides by the disc's part on the surface. With k > 1, E is
// first averaged over the k x k pixels around (one of each class), each weighted by how alike its visible point is: its distance off the pixel's tangent plane
// (a Gaussian of width r / 2) and its normal (cosine to the 8th), so that the average stays on the
// surface the pixel sees (the reconstruction after the stochastic gather; the kd is the pixel's own, so
// texture detail stays sharp).
#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = 0) readonly uniform image2D e_in;
layout(rgba32f, binding = 1) uniform image2D radiance_img;
uniform ivec2 size;
uniform int k;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size))) return;
    vec3 x, n;
    if (!visible_point(p, x, n)) return;
    vec4 e = imageLoad(e_in, p);
    if (k > 1) {
        e = vec4(0.0);
        int lo = -(k - 1) / 2;
        for (int dy = lo; dy < lo + k; dy++)
            for (int dx = lo; dx < lo + k; dx++) {
                ivec2 q = clamp(p + ivec2(dx, dy), ivec2(0), size - 1);
                vec3 y, m;
                if (!visible_point(q, y, m)) continue;
                float h = dot(y - x, n) / (0.5 * radius);
                float w = exp(-h * h) * pow(max(dot(n, m), 0.0), 8.0);
                e += w * vec4(imageLoad(e_in, q).rgb, 1.0);
            }
        e.rgb /= max(e.a, 1e-30);
    }
    vec4 kd = texelFetch(kd_tex, p, 0); /* a: 1 / the kernel's part on the surface (gpu/frame/direct.h) */
    imageStore(radiance_img, p, imageLoad(radiance_img, p) + vec4(kd.rgb / PI * e.rgb * kd.a, 0.0));
}
