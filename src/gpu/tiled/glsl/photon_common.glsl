// What every per-pixel photon gather shares: the records (binding 0), the kernel, the fixed-point sums
// and the G-buffer lookup (it needs gbuffer_normal.glsl before it). Each *_cs.glsl is a whole compute
// shader but for its first lines: photon_gather.c puts "#version 450 core" and the defines TILE, CHUNK
// and LIMIT first.
// The density estimate of Mara et al. (2013) eq. 1 with the kernel of eq. 2 (kappa = min(c, 1 - s / r),
// c = 1/5), as photonmap/pixel_gather.c computes it on the CPU: a record within r of the visible point x
// on x's surface or on one that continues it smoothly (pixel_gather.h: never the other side of a thin
// wall, nor the wall across a corner) adds flux x kappa. The sums are 64-bit fixed point (two words with carry,
// 2^-40 of the brightest possible term a unit: to_fixed), so they are exact whatever order the records
// come in: the tile and cell lists are filled by atomics in no fixed order, and the picture is the same
// on every run and for every gather (tiled, hash grid and brute force give equal sums). The terms are
// `precise`: no gather's compiler may fuse them differently.
layout(std430, binding = 0) readonly buffer Records { uint rec[]; };
uniform float radius, radius2, to_fixed;
uniform sampler2D kd_tex, g_tex;
const float KERNEL_C = 0.2;
#include "../../gl/glsl/pi.glsl"
vec3 record_flux(uint w3, uint w4) {
    int e = int(w3 >> 24) - 128;
    uvec3 q = uvec3((w3 >> 11) & 8191u, ((w3 & 2047u) << 2) | (w4 >> 30), (w4 >> 17) & 8191u);
    return ldexp(vec3(q), ivec3(e - 13));
}
// the side normal: the octahedron's unfolding, normalised
vec3 record_side(uint w4) {
    precise vec2 o = vec2(float((w4 >> 8) & 255u), float(w4 & 255u)) / 255.0 * 2.0 - 1.0;
    precise vec3 d = vec3(o, 1.0 - abs(o.x) - abs(o.y));
    if (d.z < 0.0) d.xy = (1.0 - abs(d.yx)) * vec2(d.x >= 0.0 ? 1.0 : -1.0, d.y >= 0.0 ? 1.0 : -1.0);
    return d * inversesqrt(dot(d, d));
}
void add_fixed(inout uvec2 a, float v) {
    float hi = floor(v * (1.0 / 4294967296.0));
    uint carry, lo = uint(v - hi * 4294967296.0 + 0.5);
    a.x = uaddCarry(a.x, lo, carry);
    a.y += uint(hi) + carry;
}
float fixed_value(uvec2 a) { return (float(a.y) * 4294967296.0 + float(a.x)) / to_fixed; }
// one decoded photon (position, side normal, flux) at the visible point x, normal n
void gather_photon(vec3 p, vec3 side, vec3 flux, vec3 x, vec3 n, inout uvec2 s[3]) {
    precise vec3 d = p - x;
    precise float d2 = dot(d, d);
    if (d2 >= radius2) return;
    precise float facing = dot(side, n), h = abs(dot(d, n));
    if (facing < 0.5 || h > 0.5 * radius) return;
    precise float kappa = min(KERNEL_C, 1.0 - sqrt(d2) / radius);
    precise vec3 v = flux * (kappa * to_fixed);
    add_fixed(s[0], v.x);
    add_fixed(s[1], v.y);
    add_fixed(s[2], v.z);
}
vec3 record_pos(uint i) { return uintBitsToFloat(uvec3(rec[5u * i], rec[5u * i + 1u], rec[5u * i + 2u])); }
void gather_stored(uint i, vec3 x, vec3 n, inout uvec2 s[3]) {
    uint w3 = rec[5u * i + 3u], w4 = rec[5u * i + 4u];
    if (w3 != 0u) gather_photon(record_pos(i), record_side(w4), record_flux(w3, w4), x, n, s);
}
// a pixel that takes indirect light: a visible front with a diffuse lobe
bool visible_point(ivec2 p, out vec3 x, out vec3 n) {
    vec4 g = texelFetch(g_tex, p, 0);
    vec3 kd = texelFetch(kd_tex, p, 0).rgb;
    x = g.xyz;
    return gbuffer_normal(g.a, n) && max(kd.r, max(kd.g, kd.b)) > 0.0;
}
// the sums of the windows a gather is split into (photon_gather.c: llvmpipe ends a shader invocation's
// loops after 65,535 iterations in all), 6 words a pixel, carried from one window's dispatch to the next
layout(std430, binding = 6) buffer Acc { uint acc[]; };
void load_sums(uint pixel, out uvec2 s[3]) {
    for (int c = 0; c < 3; c++) s[c] = uvec2(acc[6u * pixel + 2u * uint(c)], acc[6u * pixel + 2u * uint(c) + 1u]);
}
void store_sums(uint pixel, uvec2 s[3]) {
    for (int c = 0; c < 3; c++) { acc[6u * pixel + 2u * uint(c)] = s[c].x; acc[6u * pixel + 2u * uint(c) + 1u] = s[c].y; }
}
// E = sum / (pi c (1 - c + c^2 / 3) r^2) (eq. 3, the kernel's integral over the disc), times the share
// of the photons the pixel took (k^2 for the stochastic gather)
uniform float share;
vec4 irradiance(uvec2 s[3], bool live) {
    const float c = KERNEL_C;
    float norm = PI * c * (1.0 - c + c * c / 3.0) * radius2;
    if (!live) return vec4(0.0);
    return vec4(fixed_value(s[0]), fixed_value(s[1]), fixed_value(s[2]), 0.0) * (share / norm) + vec4(0, 0, 0, 1);
}
