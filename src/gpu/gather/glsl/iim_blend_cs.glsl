// Per texel: commit its surface (old = display, new = fresh), then display = mix(old, new, t), clamped
// to [old, new] so rounding never leaves the interval.
#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) uniform readonly image2D fresh;
layout(binding = 1, rgba32f) uniform image2D old_map;
layout(binding = 2, rgba32f) uniform image2D new_map;
layout(binding = 3, rgba32f) uniform image2D display;
layout(std430, binding = 0) readonly buffer Surfaces { int surf[]; };
layout(std430, binding = 1) readonly buffer Params { vec2 param[]; }; /* commit, t */
uniform ivec2 size;
void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (q.x >= size.x || q.y >= size.y) return;
    int s = surf[q.y * size.x + q.x];
    if (s < 0) return;
    vec4 o = imageLoad(old_map, q), n = imageLoad(new_map, q);
    if (param[s].x > 0.5) {
        o = imageLoad(display, q); n = imageLoad(fresh, q);
        imageStore(old_map, q, o); imageStore(new_map, q, n);
    }
    imageStore(display, q, clamp(mix(o, n, param[s].y), min(o, n), max(o, n)));
}
