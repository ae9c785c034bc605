// The first pass's G-buffer (attachment 2, for the per-pixel photon gathers, gpu/tiled/photon_gather.h): the
// visible point's world position, and its shading normal on the eye's side octahedron-mapped to 12 bits
// a coordinate, packed into one float as the integer 1 + 4096 x + y (exact: under 2^24); 0 where nothing
// or the back of a single-sided surface is seen, or a node whose indirect light is switched off (its
// lightmap uv -2, direct_mesh.c). gbuffer_normal.glsl unpacks it.
vec4 gbuffer(vec3 p, vec3 n, bool seen) {
    vec2 o = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if (n.z < 0.0) o = (1.0 - abs(o.yx)) * vec2(o.x >= 0.0 ? 1.0 : -1.0, o.y >= 0.0 ? 1.0 : -1.0);
    vec2 q = round(clamp(o * 0.5 + 0.5, 0.0, 1.0) * 4095.0);
    return vec4(p, seen && v_lm.x > -1.5 ? 1.0 + q.x * 4096.0 + q.y : 0.0);
}
