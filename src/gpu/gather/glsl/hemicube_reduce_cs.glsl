// One invocation per tile, summing its R^2 weighted pixels in a fixed order (deterministic, and no
// barriers: cheap on a CPU rasterizer that runs a work group's invocations as SIMD lanes).
layout(local_size_x = 8) in;
#if SCHEME == 2
layout(binding = 0) uniform sampler2DArray tiles;
#else
layout(binding = 0) uniform sampler2D tiles;
#endif
layout(binding = 0, rgba32f) uniform image2D iim;
layout(std430, binding = 0) readonly buffer Weights { float w[]; };
layout(std430, binding = 1) readonly buffer Targets { ivec2 xy[]; };
layout(std430, binding = 3) readonly buffer Cpu { vec4 emit[]; }; /* emitter + rim E, 1 if covered */
uniform int R;
uniform int tiles_x;
uniform int count;
uniform float scale;   /* pi / F(a), or pi when the rim is traced */
uniform float inv_f;   /* 1 / F(a) */
uniform float keep;    /* the share of what the texel held that stays: a footprint's later points (0: none) */
void main() {
    int tile = int(gl_GlobalInvocationID.x);
    if (tile >= count || xy[tile].x < 0) return; /* past the pass, or an empty tile (gather_passes.h) */
    vec4 s = vec4(0.0);
#if SCHEME == 2
    for (int y = 0; y < R; y++)
        for (int x = 0; x < R; x++)
            s += w[y * R + x] * texelFetch(tiles, ivec3(x, y, tile), 0);
#else
    ivec2 origin = ivec2(tile % tiles_x, tile / tiles_x) * R;
    for (int y = 0; y < R; y++)
        for (int x = 0; x < R; x++)
            s += w[y * R + x] * texelFetch(tiles, origin + ivec2(x, y), 0);
#endif
    vec4 v = vec4(scale * s.rgb + emit[tile].rgb, inv_f * s.a + emit[tile].a);
    if (keep > 0.0)
        v = mix(v, imageLoad(iim, xy[tile]), keep);
    imageStore(iim, xy[tile], v);
}
