#include "photon_gather_shaders.h"

#include "../../core/vecmath.h"

/* The density estimate of Mara et al. (2013) eq. 1 with the kernel of eq. 2 (kappa = min(c, 1 - s / r),
 * c = 1/5), as photonmap/pixel_gather.c computes it on the CPU: a record within r of the visible point x
 * on x's surface or on one that continues it smoothly (pixel_gather.h: never the other side of a thin
 * wall, nor the wall across a corner) adds flux x kappa. The sums are 64-bit fixed point (two words with carry,
 * 2^-40 of the brightest possible term a unit: to_fixed), so they are exact whatever order the records
 * come in: the tile and cell lists are filled by atomics in no fixed order, and the picture is the same
 * on every run and for every gather (tiled, hash grid and brute force give equal sums). The terms are
 * `precise`: no gather's compiler may fuse them differently. */
const char *const lm_pg_common_glsl =
    "layout(std430, binding = 0) readonly buffer Records { uint rec[]; };\n"
    "uniform float radius, radius2, to_fixed;\n"
    "uniform sampler2D kd_tex, g_tex;\n"
    "const float KERNEL_C = 0.2;\n"
    "vec3 record_flux(uint w3, uint w4) {\n"
    "    int e = int(w3 >> 24) - 128;\n"
    "    uvec3 q = uvec3((w3 >> 11) & 8191u, ((w3 & 2047u) << 2) | (w4 >> 30), (w4 >> 17) & 8191u);\n"
    "    return ldexp(vec3(q), ivec3(e - 13));\n"
    "}\n"
    /* the side normal: the octahedron's unfolding, normalised */
    "vec3 record_side(uint w4) {\n"
    "    precise vec2 o = vec2(float((w4 >> 8) & 255u), float(w4 & 255u)) / 255.0 * 2.0 - 1.0;\n"
    "    precise vec3 d = vec3(o, 1.0 - abs(o.x) - abs(o.y));\n"
    "    if (d.z < 0.0) d.xy = (1.0 - abs(d.yx)) * vec2(d.x >= 0.0 ? 1.0 : -1.0, d.y >= 0.0 ? 1.0 : -1.0);\n"
    "    return d * inversesqrt(dot(d, d));\n"
    "}\n"
    "void add_fixed(inout uvec2 a, float v) {\n"
    "    float hi = floor(v * (1.0 / 4294967296.0));\n"
    "    uint carry, lo = uint(v - hi * 4294967296.0 + 0.5);\n"
    "    a.x = uaddCarry(a.x, lo, carry);\n"
    "    a.y += uint(hi) + carry;\n"
    "}\n"
    "float fixed_value(uvec2 a) { return (float(a.y) * 4294967296.0 + float(a.x)) / to_fixed; }\n"
    /* one decoded photon (position, side normal, flux) at the visible point x, normal n */
    "void gather_photon(vec3 p, vec3 side, vec3 flux, vec3 x, vec3 n, inout uvec2 s[3]) {\n"
    "    precise vec3 d = p - x;\n"
    "    precise float d2 = dot(d, d);\n"
    "    if (d2 >= radius2) return;\n"
    "    precise float facing = dot(side, n), h = abs(dot(d, n));\n"
    "    if (facing < 0.5 || h > 0.5 * radius) return;\n"
    "    precise float kappa = min(KERNEL_C, 1.0 - sqrt(d2) / radius);\n"
    "    precise vec3 v = flux * (kappa * to_fixed);\n"
    "    add_fixed(s[0], v.x);\n"
    "    add_fixed(s[1], v.y);\n"
    "    add_fixed(s[2], v.z);\n"
    "}\n"
    "vec3 record_pos(uint i) { return uintBitsToFloat(uvec3(rec[5u * i], rec[5u * i + 1u], rec[5u * i + 2u])); }\n"
    "void gather_stored(uint i, vec3 x, vec3 n, inout uvec2 s[3]) {\n"
    "    uint w3 = rec[5u * i + 3u], w4 = rec[5u * i + 4u];\n"
    "    if (w3 != 0u) gather_photon(record_pos(i), record_side(w4), record_flux(w3, w4), x, n, s);\n"
    "}\n"
    /* a pixel that takes indirect light: a visible front with a diffuse lobe */
    "bool visible_point(ivec2 p, out vec3 x, out vec3 n) {\n"
    "    vec4 g = texelFetch(g_tex, p, 0);\n"
    "    vec3 kd = texelFetch(kd_tex, p, 0).rgb;\n"
    "    x = g.xyz;\n"
    "    return gbuffer_normal(g.a, n) && max(kd.r, max(kd.g, kd.b)) > 0.0;\n"
    "}\n"
    /* the sums of the windows a gather is split into (photon_gather.c: llvmpipe ends a shader invocation's
     * loops after 65,535 iterations in all), 6 words a pixel, carried from one window's dispatch to the next */
    "layout(std430, binding = 6) buffer Acc { uint acc[]; };\n"
    "void load_sums(uint pixel, out uvec2 s[3]) {\n"
    "    for (int c = 0; c < 3; c++) s[c] = uvec2(acc[6u * pixel + 2u * uint(c)], acc[6u * pixel + 2u * uint(c) + 1u]);\n"
    "}\n"
    "void store_sums(uint pixel, uvec2 s[3]) {\n"
    "    for (int c = 0; c < 3; c++) { acc[6u * pixel + 2u * uint(c)] = s[c].x; acc[6u * pixel + 2u * uint(c) + 1u] = s[c].y; }\n"
    "}\n"
    /* E = sum / (pi c (1 - c + c^2 / 3) r^2) (eq. 3, the kernel's integral over the disc), times the share
     * of the photons the pixel took (k^2 for the stochastic gather) */
    "uniform float share;\n"
    "vec4 irradiance(uvec2 s[3], bool live) {\n"
    "    const float c = KERNEL_C, PI = " LM_PI_GLSL ";\n"
    "    float norm = PI * c * (1.0 - c + c * c / 3.0) * radius2;\n"
    "    if (!live) return vec4(0.0);\n"
    "    return vec4(fixed_value(s[0]), fixed_value(s[1]), fixed_value(s[2]), 0.0) * (share / norm) + vec4(0, 0, 0, 1);\n"
    "}\n";

/* Depth along the view (-z of view space: vrow2 is the view matrix's third row) of a tile's visible
 * points that take indirect light: (min, max), or (1e30, -1e30) when it has none. */
const char *const lm_pg_tile_bounds_cs =
    "layout(local_size_x = TILE, local_size_y = TILE) in;\n"
    "layout(std430, binding = 1) writeonly buffer Bounds { vec2 bounds[]; };\n"
    "uniform vec4 vrow2;\n"
    "uniform ivec2 size;\n"
    "uniform int tiles_x;\n"
    "shared vec2 z[TILE * TILE];\n"
    "void main() {\n"
    "    ivec2 p = ivec2(gl_GlobalInvocationID.xy);\n"
    "    uint i = gl_LocalInvocationIndex;\n"
    "    vec3 x, n;\n"
    "    z[i] = vec2(1e30, -1e30);\n"
    "    if (all(lessThan(p, size)) && visible_point(p, x, n)) {\n"
    "        float d = -dot(vrow2, vec4(x, 1.0));\n"
    "        z[i] = vec2(d, d);\n"
    "    }\n"
    "    barrier();\n"
    "    for (uint step = uint(TILE * TILE) / 2u; step > 0u; step /= 2u) {\n"
    "        if (i < step) z[i] = vec2(min(z[i].x, z[i + step].x), max(z[i].y, z[i + step].y));\n"
    "        barrier();\n"
    "    }\n"
    "    if (i == 0u) bounds[gl_WorkGroupID.y * uint(tiles_x) + gl_WorkGroupID.x] = z[0];\n"
    "}\n";

/* What the count and fill passes share: the per-segment counters and offsets, the list, and the total
 * with its limit (LIMIT entries; passing it sets `overflow`, which stops the count early, and the caller
 * refuses the frame). fill 0 counts a record into its segments, fill 1 writes it at its segment's offset
 * plus a counter's old value (the counters zeroed between the two). insert() is false once counting has
 * overflowed. `longest`: the most entries of one segment, which sizes the gathers' windows. */
#define INSERT_COMMON \
    "layout(local_size_x = 64) in;\n" \
    "layout(std430, binding = 2) buffer Counts { uint counts[]; };\n" \
    "layout(std430, binding = 3) readonly buffer Offsets { uint offsets[]; };\n" \
    "layout(std430, binding = 4) writeonly buffer List { uint list[]; };\n" \
    "layout(std430, binding = 5) coherent buffer Totals { uint total, overflow, longest; };\n" \
    "uniform uint base, n_records;\n" \
    "uniform int fill;\n" \
    "bool insert(uint seg, uint i) {\n" \
    "    if (fill != 0) {\n" \
    "        list[offsets[seg] + atomicAdd(counts[seg], 1u)] = i;\n" \
    "        return true;\n" \
    "    }\n" \
    "    if (overflow != 0u) return false;\n" \
    "    atomicMax(longest, atomicAdd(counts[seg], 1u) + 1u);\n" \
    "    if (atomicAdd(total, 1u) >= uint(LIMIT)) overflow = 1u;\n" \
    "    return true;\n" \
    "}\n"

/* A record goes to every tile whose frustum, bounded by the tile's depth range, its sphere of radius r
 * meets (the side planes from the view-projection's rows, Gribb & Hartmann; a sphere that reaches behind
 * the eye is tested against every tile), among the tile rows [row0, row0 + rows) of this dispatch.
 * Segment: tile x k^2 + the record's class (slot mod k^2), so that a stochastic pixel reads its class's
 * photons alone. */
const char *const lm_pg_insert_tiles_cs =
    INSERT_COMMON
    "layout(std430, binding = 1) readonly buffer Bounds { vec2 bounds[]; };\n"
    "uniform mat4 vp;\n"
    "uniform vec4 vrow2;\n"
    "uniform ivec2 size;\n"
    "uniform int tiles_x, tiles_y, classes, row0, rows;\n"
    "vec4 row(int i) { return vec4(vp[0][i], vp[1][i], vp[2][i], vp[3][i]); }\n"
    "bool outside(vec4 plane, vec3 p) { return dot(plane, vec4(p, 1.0)) < -radius * length(plane.xyz); }\n"
    "void main() {\n"
    "    uint i = base + gl_GlobalInvocationID.x;\n"
    "    if (i >= n_records || rec[5u * i + 3u] == 0u) return;\n"
    "    vec3 p = uintBitsToFloat(uvec3(rec[5u * i], rec[5u * i + 1u], rec[5u * i + 2u]));\n"
    "    ivec2 t0 = ivec2(0), t1 = ivec2(tiles_x - 1, tiles_y - 1);\n"
    "    vec2 lo = vec2(1e30), hi = vec2(-1e30);\n"
    "    bool in_front = true;\n"
    "    for (int k = 0; k < 8; k++) {\n"
    "        vec3 c = p + radius * vec3((k & 1) != 0 ? 1.0 : -1.0, (k & 2) != 0 ? 1.0 : -1.0, (k & 4) != 0 ? 1.0 : -1.0);\n"
    "        vec4 q = vp * vec4(c, 1.0);\n"
    "        if (!(q.w > 0.0)) { in_front = false; break; }\n"
    "        lo = min(lo, q.xy / q.w); hi = max(hi, q.xy / q.w);\n"
    "    }\n"
    "    if (in_front) {\n"
    "        if (any(lessThan(hi, vec2(-1.0))) || any(greaterThan(lo, vec2(1.0)))) return;\n"
    "        vec2 a = clamp((lo * 0.5 + 0.5) * vec2(size), vec2(0.0), vec2(size - 1));\n"
    "        vec2 b = clamp((hi * 0.5 + 0.5) * vec2(size), vec2(0.0), vec2(size - 1));\n"
    "        t0 = ivec2(a) / TILE; t1 = ivec2(b) / TILE;\n"
    "    }\n"
    "    t0.y = max(t0.y, row0); t1.y = min(t1.y, row0 + rows - 1);\n"
    "    float d = -dot(vrow2, vec4(p, 1.0));\n"
    "    vec4 r0 = row(0), r1 = row(1), r3 = row(3);\n"
    "    for (int ty = t0.y; ty <= t1.y; ty++)\n"
    "        for (int tx = t0.x; tx <= t1.x; tx++) {\n"
    "            int tile = ty * tiles_x + tx;\n"
    "            vec2 z = bounds[tile];\n"
    "            if (z.x > z.y || d + radius < z.x || d - radius > z.y) continue;\n"
    "            vec2 n0 = vec2(tx, ty) * float(TILE) / vec2(size) * 2.0 - 1.0;\n"
    "            vec2 n1 = min(vec2(tx + 1, ty + 1) * float(TILE), vec2(size)) / vec2(size) * 2.0 - 1.0;\n"
    "            if (outside(r0 - n0.x * r3, p) || outside(n1.x * r3 - r0, p) ||\n"
    "                outside(r1 - n0.y * r3, p) || outside(n1.y * r3 - r1, p)) continue;\n"
    "            if (!insert(uint(tile * classes) + i % uint(classes), i)) return;\n"
    "        }\n"
    "}\n";

/* The hash grid (Mara et al., Listing 3): a record goes to the bucket of its cell, cells of side
 * cell >= 2r hashed into `buckets` (a power of two). */
#define CELL_HASH \
    "uniform float cell;\n" \
    "uniform uint buckets;\n" \
    "uint bucket_of(ivec3 c) {\n" \
    "    return (uint(c.x) * 73856093u ^ uint(c.y) * 19349663u ^ uint(c.z) * 83492791u) & (buckets - 1u);\n" \
    "}\n"

const char *const lm_pg_insert_cells_cs =
    INSERT_COMMON
    CELL_HASH
    "void main() {\n"
    "    uint i = base + gl_GlobalInvocationID.x;\n"
    "    if (i >= n_records || rec[5u * i + 3u] == 0u) return;\n"
    "    vec3 p = uintBitsToFloat(uvec3(rec[5u * i], rec[5u * i + 1u], rec[5u * i + 2u]));\n"
    "    insert(bucket_of(ivec3(floor(p / cell))), i);\n"
    "}\n";

/* offsets[s] = counts[0] + ... + counts[s - 1] for s in [0, n], one work group of 1024: each invocation
 * sums a run of ceil(n / 1024) counts, invocation 0 scans those 1024 sums, each writes its run. */
const char *const lm_pg_scan_cs =
    "layout(local_size_x = 1024) in;\n"
    "layout(std430, binding = 2) readonly buffer Counts { uint counts[]; };\n"
    "layout(std430, binding = 3) writeonly buffer Offsets { uint offsets[]; };\n"
    "uniform uint n;\n"
    "shared uint part[1024];\n"
    "void main() {\n"
    "    uint i = gl_LocalInvocationIndex, run = (n + 1023u) / 1024u, a = min(n, i * run), b = min(n, a + run);\n"
    "    uint s = 0u;\n"
    "    for (uint k = a; k < b; k++) s += counts[k];\n"
    "    part[i] = s;\n"
    "    barrier();\n"
    "    if (i == 0u) {\n"
    "        uint sum = 0u;\n"
    "        for (uint k = 0u; k < 1024u; k++) { uint c = part[k]; part[k] = sum; sum += c; }\n"
    "        offsets[n] = sum;\n"
    "    }\n"
    "    barrier();\n"
    "    s = part[i];\n"
    "    for (uint k = a; k < b; k++) { offsets[k] = s; s += counts[k]; }\n"
    "}\n";

/* Mara et al.'s tiled gather (Listings 5-6): a work group per tile; its photons are loaded CHUNK at a
 * time into shared memory, decoded there once, and every pixel of the tile reads them there. The
 * stochastic gather (k > 1) splits the chunk among the k^2 classes, CHUNK / k^2 records each: a pixel of
 * class c (its position mod k, turned by the frame number, so that k^2 frames take every photon once)
 * reads only class c's, and its sum counts k^2 times. One dispatch runs the rounds [round0, round0 +
 * round_count) of loads, adding to the pixel's sums. */
const char *const lm_pg_gather_tiles_cs =
    "layout(local_size_x = TILE, local_size_y = TILE) in;\n"
    "layout(std430, binding = 3) readonly buffer Offsets { uint offsets[]; };\n"
    "layout(std430, binding = 4) readonly buffer List { uint list[]; };\n"
    "uniform ivec2 size;\n"
    "uniform int tiles_x, k, frame;\n"
    "uniform uint round0, round_count;\n"
    "shared vec3 sh_pos[CHUNK], sh_side[CHUNK], sh_flux[CHUNK]; /* decoded once a tile, read by every pixel */\n"
    "void main() {\n"
    "    ivec2 p = ivec2(gl_GlobalInvocationID.xy);\n"
    "    uint classes = uint(k * k), part = uint(CHUNK) / classes, lid = gl_LocalInvocationIndex;\n"
    "    uint first = (gl_WorkGroupID.y * uint(tiles_x) + gl_WorkGroupID.x) * classes;\n"
    "    bool inside = all(lessThan(p, size));\n"
    "    uint pixel = uint(p.y * size.x + p.x);\n"
    "    vec3 x, n;\n"
    "    bool live = inside && visible_point(p, x, n);\n"
    "    uint cls = uint((p.x % k) + k * (p.y % k) + frame) % classes;\n"
    "    uint rounds = 0u;\n"
    "    for (uint c = 0u; c < classes; c++)\n"
    "        rounds = max(rounds, (offsets[first + c + 1u] - offsets[first + c] + part - 1u) / part);\n"
    "    rounds = min(rounds, round0 + round_count);\n"
    "    uint mine = offsets[first + cls + 1u] - offsets[first + cls];\n"
    "    uvec2 s[3];\n"
    "    if (live) load_sums(pixel, s);\n"
    "    for (uint r = round0; r < rounds; r++) {\n"
    "        for (uint slot = lid; slot < part * classes; slot += uint(TILE * TILE)) {\n"
    "            uint c = slot / part, at = r * part + slot % part, from = offsets[first + c];\n"
    "            if (at < offsets[first + c + 1u] - from) {\n"
    "                uint i = list[from + at], w3 = rec[5u * i + 3u], w4 = rec[5u * i + 4u];\n"
    "                sh_pos[slot] = record_pos(i);\n"
    "                sh_side[slot] = record_side(w4);\n"
    "                sh_flux[slot] = record_flux(w3, w4);\n"
    "            }\n"
    "        }\n"
    "        barrier();\n"
    "        uint done = r * part, m = live && mine > done ? min(part, mine - done) : 0u;\n"
    "        for (uint j = cls * part; j < cls * part + m; j++) gather_photon(sh_pos[j], sh_side[j], sh_flux[j], x, n, s);\n"
    "        barrier();\n"
    "    }\n"
    "    if (live) store_sums(pixel, s);\n"
    "}\n";

/* Per pixel from the cells its sphere of radius r reaches: with cells of side >= 2r, at most two a side.
 * Cells that hash to a bucket already read are skipped, so no record counts twice. One dispatch reads
 * the entries [entry0, entry0 + entry_count) of each bucket. */
const char *const lm_pg_gather_cells_cs =
    "layout(local_size_x = 8, local_size_y = 8) in;\n"
    "layout(std430, binding = 3) readonly buffer Offsets { uint offsets[]; };\n"
    "layout(std430, binding = 4) readonly buffer List { uint list[]; };\n"
    "uniform ivec2 size;\n"
    "uniform uint entry0, entry_count;\n"
    CELL_HASH
    "void main() {\n"
    "    ivec2 p = ivec2(gl_GlobalInvocationID.xy);\n"
    "    vec3 x, n;\n"
    "    if (any(greaterThanEqual(p, size)) || !visible_point(p, x, n)) return;\n"
    "    uint pixel = uint(p.y * size.x + p.x);\n"
    "    uvec2 s[3];\n"
    "    load_sums(pixel, s);\n"
    "    ivec3 lo = ivec3(floor((x - radius) / cell)), hi = min(ivec3(floor((x + radius) / cell)), lo + 1);\n"
    "    uint seen[8];\n"
    "    int m = 0;\n"
    "    for (int c = 0; c < 8; c++) {\n"
    "        ivec3 q = lo + ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);\n"
    "        if (any(greaterThan(q, hi))) continue;\n"
    "        uint b = bucket_of(q);\n"
    "        bool again = false;\n"
    "        for (int j = 0; j < m; j++) again = again || seen[j] == b;\n"
    "        if (again) continue;\n"
    "        seen[m++] = b;\n"
    "        uint e1 = min(offsets[b + 1u], offsets[b] + entry0 + entry_count);\n"
    "        for (uint e = offsets[b] + entry0; e < e1; e++) gather_stored(list[e], x, n, s);\n"
    "    }\n"
    "    store_sums(pixel, s);\n"
    "}\n";

/* Every record against every pixel, in slot order: the ground truth the others equal. One dispatch reads
 * the records [first, first + count). */
const char *const lm_pg_gather_all_cs =
    "layout(local_size_x = 8, local_size_y = 8) in;\n"
    "uniform ivec2 size;\n"
    "uniform uint first, count;\n"
    "void main() {\n"
    "    ivec2 p = ivec2(gl_GlobalInvocationID.xy);\n"
    "    vec3 x, n;\n"
    "    if (any(greaterThanEqual(p, size)) || !visible_point(p, x, n)) return;\n"
    "    uint pixel = uint(p.y * size.x + p.x);\n"
    "    uvec2 s[3];\n"
    "    load_sums(pixel, s);\n"
    "    for (uint i = first; i < first + count; i++) gather_stored(i, x, n, s);\n"
    "    store_sums(pixel, s);\n"
    "}\n";

/* The sums of every window made into E (0 where the pixel takes no indirect light). */
const char *const lm_pg_finish_cs =
    "layout(local_size_x = 8, local_size_y = 8) in;\n"
    "layout(rgba32f, binding = 0) writeonly uniform image2D e_out;\n"
    "uniform ivec2 size;\n"
    "void main() {\n"
    "    ivec2 p = ivec2(gl_GlobalInvocationID.xy);\n"
    "    if (any(greaterThanEqual(p, size))) return;\n"
    "    vec3 x, n;\n"
    "    bool live = visible_point(p, x, n);\n"
    "    uvec2 s[3];\n"
    "    load_sums(uint(p.y * size.x + p.x), s);\n"
    "    imageStore(e_out, p, irradiance(s, live));\n"
    "}\n";

/* radiance += kd / pi x E / c, c the kernel's part on the pixel's surface (the kd texture's alpha holds
 * 1 / c: lm_direct_set_coverage), as the AIM divides by the disc's part on the surface. With k > 1, E is
 * first averaged over the k x k pixels around (one of each class), each weighted by how alike its visible point is: its distance off the pixel's tangent plane
 * (a Gaussian of width r / 2) and its normal (cosine to the 8th), so that the average stays on the
 * surface the pixel sees (the reconstruction after the stochastic gather; the kd is the pixel's own, so
 * texture detail stays sharp). */
const char *const lm_pg_resolve_cs =
    "layout(local_size_x = 8, local_size_y = 8) in;\n"
    "layout(rgba32f, binding = 0) readonly uniform image2D e_in;\n"
    "layout(rgba32f, binding = 1) uniform image2D radiance_img;\n"
    "uniform ivec2 size;\n"
    "uniform int k;\n"
    "void main() {\n"
    "    const float PI = " LM_PI_GLSL ";\n"
    "    ivec2 p = ivec2(gl_GlobalInvocationID.xy);\n"
    "    if (any(greaterThanEqual(p, size))) return;\n"
    "    vec3 x, n;\n"
    "    if (!visible_point(p, x, n)) return;\n"
    "    vec4 e = imageLoad(e_in, p);\n"
    "    if (k > 1) {\n"
    "        e = vec4(0.0);\n"
    "        int lo = -(k - 1) / 2;\n"
    "        for (int dy = lo; dy < lo + k; dy++)\n"
    "            for (int dx = lo; dx < lo + k; dx++) {\n"
    "                ivec2 q = clamp(p + ivec2(dx, dy), ivec2(0), size - 1);\n"
    "                vec3 y, m;\n"
    "                if (!visible_point(q, y, m)) continue;\n"
    "                float h = dot(y - x, n) / (0.5 * radius);\n"
    "                float w = exp(-h * h) * pow(max(dot(n, m), 0.0), 8.0);\n"
    "                e += w * vec4(imageLoad(e_in, q).rgb, 1.0);\n"
    "            }\n"
    "        e.rgb /= max(e.a, 1e-30);\n"
    "    }\n"
    "    vec4 kd = texelFetch(kd_tex, p, 0); /* a: 1 / the kernel's part on the surface (gpu/frame/direct.h) */\n"
    "    imageStore(radiance_img, p, imageLoad(radiance_img, p) + vec4(kd.rgb / PI * e.rgb * kd.a, 0.0));\n"
    "}\n";
