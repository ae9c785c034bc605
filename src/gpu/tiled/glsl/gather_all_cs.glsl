// Every record against every pixel, in slot order: the ground truth the others equal. One dispatch reads
// the records [first, first + count).
#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
uniform ivec2 size;
uniform uint first, count;
#include "pixel_sums.glsl"
void main() {
    vec3 x, n;
    uint pixel;
    uvec2 s[3];
    if (!pixel_sums(x, n, pixel, s)) return;
    for (uint i = first; i < first + count; i++) gather_stored(i, x, n, s);
    store_sums(pixel, s);
}
