// The start of the per-pixel gathers (gather_cells_cs, gather_all_cs; after their `uniform ivec2
// size`): this invocation's pixel, its visible point x, n and the sums its earlier windows left in s;
// false where the pixel takes no indirect light (outside the picture, nothing visible, no diffuse lobe)
// and has nothing to gather.
bool pixel_sums(out vec3 x, out vec3 n, out uint pixel, out uvec2 s[3]) {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size)) || !visible_point(p, x, n)) return false;
    pixel = uint(p.y * size.x + p.x);
    load_sums(pixel, s);
    return true;
}
