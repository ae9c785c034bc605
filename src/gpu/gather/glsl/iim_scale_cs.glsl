// A light changed in power alone (iim.h, lm_iim_scale): every texel's colour in all six maps times its
// own factor (update/light_scale.h), so that what is shown, what blends in and what the waiting texels borrow all follow
// the edit at once. Alpha (back-face fraction, or delta's commit frame) stays.
#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) uniform image2D fresh;
layout(binding = 1, rgba32f) uniform image2D old_map;
layout(binding = 2, rgba32f) uniform image2D new_map;
layout(binding = 3, rgba32f) uniform image2D display;
layout(binding = 4, rgba32f) uniform image2D delta;
layout(binding = 5, rgba32f) uniform image2D carry;
layout(std430, binding = 0) readonly buffer Surfaces { int surf[]; };
layout(std430, binding = 1) readonly buffer Factors { vec4 factor[]; }; /* per cell */
uniform ivec2 size;

#define SCALE(map) { vec4 v = imageLoad(map, g); imageStore(map, g, vec4(v.rgb * f, v.a)); }

void main() {
    ivec2 g = ivec2(gl_GlobalInvocationID.xy);
    if (g.x >= size.x || g.y >= size.y) return;
    int s = surf[g.y * size.x + g.x];
    if (s < 0) return;
    vec3 f = factor[g.y * size.x + g.x].rgb;
    if (f == vec3(1.0)) return;
    SCALE(fresh) SCALE(old_map) SCALE(new_map) SCALE(display) SCALE(delta) SCALE(carry)
}
