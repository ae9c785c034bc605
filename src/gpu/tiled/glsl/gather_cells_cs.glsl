// Per pixel from the cells its sphere of radius r reaches: with cells of side >= 2r, at most two a side.
// Cells that hash to a bucket already read are skipped, so no record counts twice. One dispatch reads
// the entries [entry0, entry0 + entry_count) of each bucket.
#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 3) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = 4) readonly buffer List { uint list[]; };
uniform ivec2 size;
uniform uint entry0, entry_count;
#include "cell_hash.glsl"
#include "pixel_sums.glsl"
void main() {
    vec3 x, n;
    uint pixel;
    uvec2 s[3];
    if (!pixel_sums(x, n, pixel, s)) return;
    ivec3 lo = ivec3(floor((x - radius) / cell)), hi = min(ivec3(floor((x + radius) / cell)), lo + 1);
    uint seen[8];
    int m = 0;
    for (int c = 0; c < 8; c++) {
        ivec3 q = lo + ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        if (any(greaterThan(q, hi))) continue;
        uint b = bucket_of(q);
        bool again = false;
        for (int j = 0; j < m; j++) again = again || seen[j] == b;
        if (again) continue;
        seen[m++] = b;
        uint e1 = min(offsets[b + 1u], offsets[b] + entry0 + entry_count);
        for (uint e = offsets[b] + entry0; e < e1; e++) gather_stored(list[e], x, n, s);
    }
    store_sums(pixel, s);
}
