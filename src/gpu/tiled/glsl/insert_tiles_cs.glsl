// A record goes to every tile whose frustum, bounded by the tile's depth range, its sphere of radius r
// meets (the side planes from the view-projection's rows, Gribb & Hartmann; a sphere that reaches behind
// the eye is tested against every tile), among the tile rows [row0, row0 + rows) of this dispatch.
// Segment: tile x k^2 + the record's class (slot mod k^2), so that a stochastic pixel reads its class's
// photons alone.
#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
#include "insert_common.glsl"
layout(std430, binding = 1) readonly buffer Bounds { vec2 bounds[]; };
uniform mat4 vp;
uniform vec4 vrow2;
uniform ivec2 size;
uniform int tiles_x, tiles_y, classes, row0, rows;
vec4 row(int i) { return vec4(vp[0][i], vp[1][i], vp[2][i], vp[3][i]); }
bool outside(vec4 plane, vec3 p) { return dot(plane, vec4(p, 1.0)) < -radius * length(plane.xyz); }
void main() {
    uint i;
    vec3 p;
    if (!record_to_insert(i, p)) return;
    ivec2 t0 = ivec2(0), t1 = ivec2(tiles_x - 1, tiles_y - 1);
    vec2 lo = vec2(1e30), hi = vec2(-1e30);
    bool in_front = true;
    for (int k = 0; k < 8; k++) {
        vec3 c = p + radius * vec3((k & 1) != 0 ? 1.0 : -1.0, (k & 2) != 0 ? 1.0 : -1.0, (k & 4) != 0 ? 1.0 : -1.0);
        vec4 q = vp * vec4(c, 1.0);
        if (!(q.w > 0.0)) { in_front = false; break; }
        lo = min(lo, q.xy / q.w); hi = max(hi, q.xy / q.w);
    }
    if (in_front) {
        if (any(lessThan(hi, vec2(-1.0))) || any(greaterThan(lo, vec2(1.0)))) return;
        vec2 a = clamp((lo * 0.5 + 0.5) * vec2(size), vec2(0.0), vec2(size - 1));
        vec2 b = clamp((hi * 0.5 + 0.5) * vec2(size), vec2(0.0), vec2(size - 1));
        t0 = ivec2(a) / TILE; t1 = ivec2(b) / TILE;
    }
    t0.y = max(t0.y, row0); t1.y = min(t1.y, row0 + rows - 1);
    float d = -dot(vrow2, vec4(p, 1.0));
    vec4 r0 = row(0), r1 = row(1), r3 = row(3);
    for (int ty = t0.y; ty <= t1.y; ty++)
        for (int tx = t0.x; tx <= t1.x; tx++) {
            int tile = ty * tiles_x + tx;
            vec2 z = bounds[tile];
            if (z.x > z.y || d + radius < z.x || d - radius > z.y) continue;
            vec2 n0 = vec2(tx, ty) * float(TILE) / vec2(size) * 2.0 - 1.0;
            vec2 n1 = min(vec2(tx + 1, ty + 1) * float(TILE), vec2(size)) / vec2(size) * 2.0 - 1.0;
            if (outside(r0 - n0.x * r3, p) || outside(n1.x * r3 - r0, p) ||
                outside(r1 - n0.y * r3, p) || outside(n1.y * r3 - r1, p)) continue;
            if (!insert(uint(tile * classes) + i % uint(classes), i)) return;
        }
}
