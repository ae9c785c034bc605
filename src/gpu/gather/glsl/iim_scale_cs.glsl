// A light's edit (iim.h, lm_iim_scale): every texel's colour in all six maps times its own factor, and
// its values (fresh, old, new, display) plus its own addition (update/light_scale.h: where it saw no light
// before), so that what is shown, what blends in and what the waiting texels borrow all follow the edit at
// once. Its change and what its estimate carries are differences, which an addition common to the values
// leaves as they are. Alpha (back-face fraction, or delta's commit frame) stays.
#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) uniform image2D fresh;
layout(binding = 1, rgba32f) uniform image2D old_map;
layout(binding = 2, rgba32f) uniform image2D new_map;
layout(binding = 3, rgba32f) uniform image2D display;
layout(binding = 4, rgba32f) uniform image2D delta;
layout(binding = 5, rgba32f) uniform image2D carry;
layout(std430, binding = 0) readonly buffer Surfaces { int surf[]; };
layout(std430, binding = 1) readonly buffer Factors { vec4 factor[]; }; /* per cell: factor, addition */
uniform ivec2 size;

#define SCALE(map, d) { vec4 v = imageLoad(map, g); imageStore(map, g, vec4(v.rgb * f + d, v.a)); }

void main() {
    ivec2 g = ivec2(gl_GlobalInvocationID.xy);
    if (g.x >= size.x || g.y >= size.y) return;
    int s = surf[g.y * size.x + g.x];
    if (s < 0) return;
    int c = g.y * size.x + g.x;
    vec3 f = factor[2 * c].rgb, d = factor[2 * c + 1].rgb;
    if (f == vec3(1.0) && d == vec3(0.0)) return;
    SCALE(fresh, d) SCALE(old_map, d) SCALE(new_map, d) SCALE(display, d) SCALE(delta, vec3(0.0)) SCALE(carry, vec3(0.0))
}
