// The light fragment shader without its first lines: "#version 450 core", then KIND, PCF, FIRST and GLOSSY
// defined, go before it (direct.c, light_program, compiles one per kind and pass, with the glossy lobe
// when a material of the scene is glossy).
// kind: 0 point, 1 spot, 2 directional. FIRST 1: the frame's first pass, which also writes depth and adds
// the emitted radiance and the indirect term (as emission_fs.glsl); FIRST 0: a further light, added
// over the laid-down depth. texel: world size of a shadow-map texel (directional) or its
// size per unit distance (point, spot; divided by the cosine to the map's axis). The bias: the receiver
// moves normal_offset texels along its normal, and its metric is lowered by
// (const_bias + slope_bias (pcf + 1) min(tan theta, max_slope)) texels.
#include "mesh_inputs.glsl"
uniform int has_tex, use_lit;
uniform sampler2D lit;
const int kind = KIND, pcf = PCF; /* compiled per light kind and PCF radius: no branch on them */
// taps per axis: bilinear compare taps half a texel either side of each texel boundary, so radius 1
// (4 lookups) covers the 3 x 3 texels a nearest-texel 3 x 3 PCF read, with tent weights
const int taps = pcf == 0 ? 1 : 2 * pcf;
float tap(int i) { return float(i) - 0.5 * float(taps - 1); }
uniform sampler2D base_tex;
uniform vec3 eye, view_dir, lpos, ldir, radiant, origin;
uniform int ortho_view;
uniform float cos_outer, spot_width, texel, map_size;
uniform float normal_offset, slope_bias, max_slope, const_bias, range;
uniform float light_range; /* KHR_lights_punctual range, 0: none (lm_light_range_window) */
uniform mat4 light_vp;
uniform sampler2DShadow map2d;   /* metric / range, compared in the sampler (bilinear PCF) */
// directional: the maps fitted to the view, the nearest quarter of its depth and all of it (has_near),
// with the whole map's metric
uniform sampler2DShadow map_near0, map_near1;
uniform mat4 near_vp[2];
uniform float near_texel[2];
uniform int has_near[2];
uniform samplerCubeShadow mapcube;
#if FIRST
layout(location = 0) out vec4 frag;
layout(location = 1) out vec4 kd_out; /* the diffuse lobe at the pixel, for later passes */
layout(location = 2) out vec4 g_out;  /* position and normal (GBUFFER) */
#else
out vec4 frag;
#endif
#include "../../gl/glsl/pi.glsl"
float cube_shadow(vec3 q, float m, float T) {
    vec3 d = q - lpos, a = abs(d);
    float ref = m / range;
    if (taps == 1) return texture(mapcube, vec4(d, ref)); /* no tap frame to build (a constant) */
    vec3 t = normalize(cross(d, a.x < a.y ? vec3(1, 0, 0) : vec3(0, 1, 0)));
    vec3 b = normalize(cross(d, t));
    float lit = 0.0;
    for (int i = 0; i < taps; i++)
        for (int j = 0; j < taps; j++)
            lit += texture(mapcube, vec4(d + (tap(i) * t + tap(j) * b) * T, ref));
    return lit;
}
float map_shadow(sampler2DShadow map, mat4 vp, vec3 q, float m) {
    vec4 c = vp * vec4(q, 1.0);
    vec2 uv = c.xy / c.w * 0.5 + 0.5;
    float lit = 0.0, ref = m / range;
    for (int i = 0; i < taps; i++)
        for (int j = 0; j < taps; j++) {
            vec2 u = uv + vec2(tap(i), tap(j)) / map_size;
            bool out_ = any(lessThan(u, vec2(0.0))) || any(greaterThan(u, vec2(1.0)));
            lit += out_ ? 1.0 : texture(map, vec3(u, ref));
        }
    return lit;
}
// Which of a directional light's maps fitted to the view holds p and its PCF taps, the finer first (-1:
// neither; the light's whole-scene map then) (direct.c, refresh_near_maps).
int view_map(vec3 p) {
    if (kind != 2) return -1;
    float edge = (normal_offset + float(taps) + 1.0) / map_size;
    for (int k = 0; k < 2; k++) {
        if (has_near[k] == 0) continue;
        vec2 uv = (near_vp[k] * vec4(p, 1.0)).xy * 0.5 + 0.5;
        if (all(greaterThan(uv, vec2(edge))) && all(lessThan(uv, vec2(1.0 - edge)))) return k;
    }
    return -1;
}
// Fraction of PCF taps that see the light from p (geometric normal ng, unit L towards the light).
float shadow(vec3 p, vec3 ng, vec3 L, float dist) {
    float c = clamp(dot(ng, L), 1e-4, 1.0);
    float tan_t = min(sqrt(1.0 - c * c) / c, max_slope);
    vec3 a = kind == 0 ? abs(L) : vec3(abs(dot(L, ldir)));
    int vm = view_map(p);
    float T = kind == 2 ? (vm >= 0 ? near_texel[vm] : texel) : texel * dist / max(max(a.x, a.y), max(a.z, 0.2));
    vec3 q = p + ng * (normal_offset * T);
    float bias = T * (const_bias + slope_bias * float(pcf + 1) * tan_t);
    float m = (kind == 2 ? dot(q - origin, ldir) : length(q - lpos)) - bias;
    float lit; /* branches, not ?: (llvmpipe evaluates both sides of a select: twice the lookups) */
    if (kind == 0)
        lit = cube_shadow(q, m, T);
    else if (vm == 0)
        lit = map_shadow(map_near0, near_vp[0], q, m);
    else if (vm == 1)
        lit = map_shadow(map_near1, near_vp[1], q, m);
    else
        lit = map_shadow(map2d, light_vp, q, m);
    return lit / float(taps * taps);
}
#include "lobes.glsl"
vec3 light(vec3 p, vec3 ns, vec3 ng, vec3 V) {
    vec3 L = -ldir, E = radiant;
    float dist = 1.0;
    if (kind != 2) {
        vec3 d = lpos - p;
        dist = length(d); L = d / dist; E /= dist * dist;
        if (kind == 1) {
            float t = clamp((dot(-L, ldir) - cos_outer) / spot_width, 0.0, 1.0);
            E *= t * t;
        }
        if (light_range > 0.0) {
            float r = dist / light_range;
            E *= clamp(1.0 - r * r * r * r, 0.0, 1.0);
        }
    }
    if (dot(ng, L) <= 0.0 || max(E.r, max(E.g, E.b)) <= 0.0) return vec3(0.0);
    vec3 kd, ks;
    lobes(kd, ks);
    vec3 f = kd / PI;
#if GLOSSY /* ks is 0 but on a glossy surface: without one, no pow for every pixel */
    float n = v_par.x;
    f += ks * (n + 2.0) / (2.0 * PI) * pow(max(dot(reflect(-L, ns), V), 0.0), n);
#endif
    return f * E * max(dot(ns, L), 0.0) * shadow(p, ng, L, dist);
}
#include "indirect.glsl"
#include "coverage.glsl"
#include "gbuffer_pack.glsl"
void main() {
    look_up_albedo();
    vec3 V = ortho_view != 0 ? view_dir : normalize(eye - v_pos);
    vec3 ng = normalize(cross(dFdx(v_pos), dFdy(v_pos))), ns = normalize(v_ns);
    if (dot(ng, V) < 0.0) ng = -ng; /* the side seen */
    bool back = !gl_FrontFacing;
    if (back) ns = -ns;
    if (dot(ns, ng) < 0.0) ns = ng;
    bool seen = !back || v_par.y > 0.5;
    vec3 c = light(v_pos, ns, ng, V);
#if FIRST
    c += v_em;
    frag = vec4(seen ? c + indirect() : vec3(0.0), 1.0); /* the back of a single-sided surface: black */
    vec3 kd, ks;
    lobes(kd, ks);
    kd_out = vec4(seen ? kd : vec3(0.0), inv_coverage());
    g_out = gbuffer(v_pos, ns, seen);
#else
    frag = vec4(seen ? c : vec3(0.0), 1.0);
#endif
}
