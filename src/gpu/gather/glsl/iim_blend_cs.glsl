// Per texel: commit it (old = display, new = fresh, its clock restarted), then display = mix(old, new, t),
// t from the frames since its last commit, clamped to [old, new] so rounding never leaves the interval;
// a texel turning valid or invalid shows its new value at once.
// mode 0: every atlas cell; a cell is committed when its surface is (param[s].x; y: an instant commit).
// mode 1: only commits, of the cells listed in `list` (texels regathered on their own, texel_change.h),
// shown at once when instant.
#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) uniform readonly image2D fresh;
layout(binding = 1, rgba32f) uniform image2D old_map;
layout(binding = 2, rgba32f) uniform image2D new_map;
layout(binding = 3, rgba32f) uniform image2D display;
layout(std430, binding = 0) readonly buffer Surfaces { int surf[]; };
layout(std430, binding = 1) readonly buffer Params { vec2 param[]; }; /* commit, instant */
layout(std430, binding = 2) buffer Starts { int start[]; };          /* per cell: frame of its last commit */
layout(std430, binding = 3) readonly buffer List { int list[]; };
uniform ivec2 size;
uniform int mode, frame, blend_frames, list_count, row, instant;
uniform float limit; /* back-face fraction above which a texel is invalid */
const int NEVER = -1073741824;
void main() {
    ivec2 g = ivec2(gl_GlobalInvocationID.xy);
    if (mode == 1) {
        int k = g.y * row + g.x;
        if (k >= list_count) return;
        int c = list[k];
        ivec2 q = ivec2(c % size.x, c / size.x);
        imageStore(old_map, q, imageLoad(display, q));
        imageStore(new_map, q, imageLoad(fresh, q));
        start[c] = instant != 0 ? NEVER : frame;
        return;
    }
    if (g.x >= size.x || g.y >= size.y) return;
    int c = g.y * size.x + g.x, s = surf[c];
    if (s < 0) return;
    vec4 o, n;
    if (param[s].x > 0.5) {
        o = imageLoad(display, g); n = imageLoad(fresh, g);
        imageStore(old_map, g, o); imageStore(new_map, g, n);
        start[c] = param[s].y > 0.5 ? NEVER : frame;
    } else {
        o = imageLoad(old_map, g); n = imageLoad(new_map, g);
    }
    float t = blend_frames <= 0 ? 1.0 : min(1.0, float(frame - start[c]) / float(blend_frames));
    if ((o.a <= limit) != (n.a <= limit)) t = 1.0; /* turned valid or invalid: no blend with the inside */
    imageStore(display, g, clamp(mix(o, n, t), min(o, n), max(o, n)));
}
