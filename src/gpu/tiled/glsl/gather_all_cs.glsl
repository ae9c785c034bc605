// Every record against every pixel, in slot order: the ground truth the others equal. One dispatch reads
// the records [first, first + count).
#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
uniform ivec2 size;
uniform uint first, count;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    vec3 x, n;
    if (any(greaterThanEqual(p, size)) || !visible_point(p, x, n)) return;
    uint pixel = uint(p.y * size.x + p.x);
    uvec2 s[3];
    load_sums(pixel, s);
    for (uint i = first; i < first + count; i++) gather_stored(i, x, n, s);
    store_sums(pixel, s);
}
