// Mara et al.'s tiled gather (Listings 5-6): a work group per tile; its photons are loaded CHUNK at a
// time into shared memory, decoded there once, and every pixel of the tile reads them there. The
// stochastic gather (k > 1) splits the chunk among the k^2 classes, CHUNK / k^2 records each: a pixel of
// class c (its position mod k, turned by the frame number, so that k^2 frames take every photon once)
// reads only class c's, and its sum counts k^2 times. One dispatch runs the rounds [round0, round0 +
// round_count) of loads, adding to the pixel's sums.
#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(std430, binding = 3) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = 4) readonly buffer List { uint list[]; };
uniform ivec2 size;
uniform int tiles_x, k, frame;
uniform uint round0, round_count;
shared vec3 sh_pos[CHUNK], sh_side[CHUNK], sh_flux[CHUNK]; /* decoded once a tile, read by every pixel */
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    uint classes = uint(k * k), part = uint(CHUNK) / classes, lid = gl_LocalInvocationIndex;
    uint first = (gl_WorkGroupID.y * uint(tiles_x) + gl_WorkGroupID.x) * classes;
    bool inside = all(lessThan(p, size));
    uint pixel = uint(p.y * size.x + p.x);
    vec3 x, n;
    bool live = inside && visible_point(p, x, n);
    uint cls = uint((p.x % k) + k * (p.y % k) + frame) % classes;
    uint rounds = 0u;
    for (uint c = 0u; c < classes; c++)
        rounds = max(rounds, (offsets[first + c + 1u] - offsets[first + c] + part - 1u) / part);
    rounds = min(rounds, round0 + round_count);
    uint mine = offsets[first + cls + 1u] - offsets[first + cls];
    uvec2 s[3];
    if (live) load_sums(pixel, s);
    for (uint r = round0; r < rounds; r++) {
        for (uint slot = lid; slot < part * classes; slot += uint(TILE * TILE)) {
            uint c = slot / part, at = r * part + slot % part, from = offsets[first + c];
            if (at < offsets[first + c + 1u] - from) {
                uint i = list[from + at], w3 = rec[5u * i + 3u], w4 = rec[5u * i + 4u];
                sh_pos[slot] = record_pos(i);
                sh_side[slot] = record_side(w4);
                sh_flux[slot] = record_flux(w3, w4);
            }
        }
        barrier();
        uint done = r * part, m = live && mine > done ? min(part, mine - done) : 0u;
        for (uint j = cls * part; j < cls * part + m; j++) gather_photon(sh_pos[j], sh_side[j], sh_flux[j], x, n, s);
        barrier();
    }
    if (live) store_sums(pixel, s);
}
