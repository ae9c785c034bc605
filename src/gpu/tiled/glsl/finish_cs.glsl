// The sums of every window made into E (0 where the pixel takes no indirect light).
#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = 0) writeonly uniform image2D e_out;
uniform ivec2 size;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size))) return;
    vec3 x, n;
    bool live = visible_point(p, x, n);
    uvec2 s[3];
    load_sums(uint(p.y * size.x + p.x), s);
    imageStore(e_out, p, irradiance(s, live));
}
