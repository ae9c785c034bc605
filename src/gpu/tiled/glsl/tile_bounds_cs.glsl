// Depth along the view (-z of view space: vrow2 is the view matrix's third row) of a tile's visible
// points that take indirect light: (min, max), or (1e30, -1e30) when it has none.
#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(std430, binding = 1) writeonly buffer Bounds { vec2 bounds[]; };
uniform vec4 vrow2;
uniform ivec2 size;
uniform int tiles_x;
shared vec2 z[TILE * TILE];
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    uint i = gl_LocalInvocationIndex;
    vec3 x, n;
    z[i] = vec2(1e30, -1e30);
    if (all(lessThan(p, size)) && visible_point(p, x, n)) {
        float d = -dot(vrow2, vec4(x, 1.0));
        z[i] = vec2(d, d);
    }
    barrier();
    for (uint step = uint(TILE * TILE) / 2u; step > 0u; step /= 2u) {
        if (i < step) z[i] = vec2(min(z[i].x, z[i + step].x), max(z[i].y, z[i + step].y));
        barrier();
    }
    if (i == 0u) bounds[gl_WorkGroupID.y * uint(tiles_x) + gl_WorkGroupID.x] = z[0];
}
