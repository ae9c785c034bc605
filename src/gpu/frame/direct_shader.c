#include "direct_shader.h"

#include "../../core/vecmath.h"

/* Attributes (world space): position, shading normal, base colour factor, (Phong exponent, double-sided,
 * metallic, material class), emitted radiance, base colour texture uv (KHR_texture_transform applied).
 * The per-material ones are flat (no interpolation: cheaper on llvmpipe). The geometric normal is the
 * cross product of the position's screen derivatives, exact on a planar triangle, so vertices are shared
 * between triangles; gl_FrontFacing says which side of the triangle (by its winding) is seen. */
/* Vertex ranges (a node's vertices are contiguous, direct_mesh.h): with keep.y > keep.x only the vertices
 * in [keep.x, keep.y) are drawn (one node's reflections), and those in [drop.x, drop.y) never (a node's
 * own environment map, drawn from inside it). Every corner of a dropped triangle leaves the clip volume
 * on the same side, so it is cut before rasterization. Both 0 (the default): everything. */
#define VERTEX_RANGES \
    "uniform ivec2 keep, drop;\n" \
    "bool dropped() {\n" \
    "    int v = gl_VertexID;\n" \
    "    return (keep.y > keep.x && (v < keep.x || v >= keep.y)) || (v >= drop.x && v < drop.y);\n" \
    "}\n"

/* bsdf.c's lobes (lm_material_lobes) per pixel, base colour texture included: diffuse and emitter kd =
 * albedo; glossy ks = mix(0.04, albedo, metallic), kd = albedo (1 - metallic)(1 - max ks); mirror and
 * glass none here.
 * The albedo: a diffuse surface's light is linear in it, so its texture is read trilinearly, averaged
 * over the pixel's footprint as the reference's many paths a pixel average it (a texture finer than the
 * pixels, the cornell-suzanne block's checker, does not alias: its pixels' error 0.14 -> 0.05). A glossy
 * lobe is not linear in it (kd = a (1 - m)(1 - max ks)): the lobe of the averaged texture is not the
 * average of the lobes (the depth-of-field board, copper traces on green, read 1.79 1.16 1.06 so), so a
 * glossy surface reads level 0 at the pixel's centre. Both lookups at the top of main(), in uniform
 * control flow (a mipmapped lookup in a branch has no defined derivatives). */
#define LOBES \
    "vec3 albedo;\n" \
    "void look_up_albedo() {\n" \
    "    vec3 fine = textureLod(base_tex, v_uv, 0.0).rgb, filtered = texture(base_tex, v_uv).rgb;\n" \
    "    albedo = v_base * (has_tex == 0 ? vec3(1.0) : int(v_par.w + 0.5) == 1 ? fine : filtered);\n" \
    "}\n" \
    "void lobes(out vec3 kd, out vec3 ks) {\n" \
    "    vec3 a = albedo;\n" \
    "    int cls = int(v_par.w + 0.5);\n" \
    "    kd = vec3(0.0); ks = vec3(0.0);\n" \
    "    if (cls == 0 || cls == 4) kd = a;\n" \
    "    if (cls != 1) return;\n" \
    "    ks = mix(vec3(0.04), a, v_par.z);\n" \
    "    kd = a * (1.0 - v_par.z) * (1.0 - max(ks.r, max(ks.g, ks.b)));\n" \
    "}\n"

const char *const lm_direct_lobes_glsl = LOBES;

/* The first pass's G-buffer (attachment 2, for the per-pixel photon gathers, gpu/tiled/photon_gather.h): the
 * visible point's world position, and its shading normal on the eye's side octahedron-mapped to 12 bits
 * a coordinate, packed into one float as the integer 1 + 4096 x + y (exact: under 2^24); 0 where nothing
 * or the back of a single-sided surface is seen, or a node whose indirect light is switched off (its
 * lightmap uv -2, direct_mesh.c). lm_direct_gbuffer_glsl unpacks it. */
#define GBUFFER \
    "vec4 gbuffer(vec3 p, vec3 n, bool seen) {\n" \
    "    vec2 o = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));\n" \
    "    if (n.z < 0.0) o = (1.0 - abs(o.yx)) * vec2(o.x >= 0.0 ? 1.0 : -1.0, o.y >= 0.0 ? 1.0 : -1.0);\n" \
    "    vec2 q = round(clamp(o * 0.5 + 0.5, 0.0, 1.0) * 4095.0);\n" \
    "    return vec4(p, seen && v_lm.x > -1.5 ? 1.0 + q.x * 4096.0 + q.y : 0.0);\n" \
    "}\n"

const char *const lm_direct_gbuffer_glsl =
    "bool gbuffer_normal(float a, out vec3 n) {\n"
    "    n = vec3(0.0);\n"
    "    if (a < 1.0) return false;\n"
    "    float c = a - 1.0, qx = floor(c / 4096.0), qy = c - qx * 4096.0;\n"
    "    vec2 o = vec2(qx, qy) / 4095.0 * 2.0 - 1.0;\n"
    "    n = vec3(o, 1.0 - abs(o.x) - abs(o.y));\n"
    "    if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);\n"
    "    n = normalize(n);\n"
    "    return true;\n"
    "}\n";


/* The indirect term at a pixel: kd / pi x E_IIM, E / pi from the premultiplied atlas `lit`
 * (gpu/frame/composite.h) at the lightmap uv (attribute 7, -1 without a chart), rgb / a over the covered, valid
 * texels of its bilinear footprint, kd per pixel (the base colour texture at the pixel, not at the texel's
 * centre: a texture finer than the lightmap stays sharp). */
#define INDIRECT \
    "vec3 indirect() {\n" \
    "    if (use_lit != 1 || v_lm.x < 0.0) return vec3(0.0);\n" \
    "    vec4 t = textureLod(lit, v_lm, 0.0);\n" \
    "    if (t.a <= 0.0) return vec3(0.0);\n" \
    "    vec3 kd, ks;\n" \
    "    lobes(kd, ks);\n" \
    "    return kd * t.rgb / t.a;\n" \
    "}\n"

/* With use_lit 2, `lit` holds the photon gathers' kernel coverage instead (lm_direct_set_coverage,
 * premultiplied: r / a = 1 / coverage over the valid texels of the footprint), which the first pass writes
 * into the kd attachment's alpha (1 without it) for the gathers' resolve. */
#define COVERAGE \
    "float inv_coverage() {\n" \
    "    if (use_lit != 2 || v_lm.x < 0.0) return 1.0;\n" \
    "    vec4 t = textureLod(lit, v_lm, 0.0);\n" \
    "    return t.a > 0.0 ? t.r / t.a : 1.0;\n" \
    "}\n"

const char *const lm_direct_vs =
    "#version 450 core\n"
    "layout(location = 0) in vec3 pos;\n"
    "layout(location = 1) in vec3 ns;\n"
    "layout(location = 2) in vec3 base;\n"
    "layout(location = 3) in vec4 par;\n"
    "layout(location = 4) in vec3 em;\n"
    "layout(location = 5) in vec2 uv;\n"
    "layout(location = 7) in vec2 lm_uv;\n"
    "uniform mat4 view_proj;\n"
    "out vec3 v_pos, v_ns;\n"
    "flat out vec3 v_base, v_em;\n"
    "flat out vec4 v_par;\n"
    "out vec2 v_uv, v_lm;\n"
    "invariant gl_Position;\n"
    VERTEX_RANGES
    "void main() {\n"
    "    v_pos = pos; v_ns = ns; v_base = base; v_par = par; v_em = em; v_uv = uv; v_lm = lm_uv;\n"
    "    gl_Position = dropped() ? vec4(2.0, 2.0, 2.0, 1.0) : view_proj * vec4(pos, 1.0);\n"
    "}\n";

/* kind: 0 point, 1 spot, 2 directional. FIRST 1: the frame's first pass, which also writes depth and adds
 * the emitted radiance and the indirect term (as lm_direct_emission_fs); FIRST 0: a further light, added
 * over the laid-down depth. texel: world size of a shadow-map texel (directional) or its
 * size per unit distance (point, spot; divided by the cosine to the map's axis). The bias: the receiver
 * moves normal_offset texels along its normal, and its metric is lowered by
 * (const_bias + slope_bias (pcf + 1) min(tan theta, max_slope)) texels. */
const char *const lm_direct_fs_body =
    "in vec3 v_pos, v_ns;\n"
    "flat in vec3 v_base, v_em;\n"
    "flat in vec4 v_par;\n"
    "in vec2 v_uv, v_lm;\n"
    "uniform int has_tex, use_lit;\n"
    "uniform sampler2D lit;\n"
    "const int kind = KIND, pcf = PCF; /* compiled per light kind and PCF radius: no branch on them */\n"
    /* taps per axis: bilinear compare taps half a texel either side of each texel boundary, so radius 1
     * (4 lookups) covers the 3 x 3 texels a nearest-texel 3 x 3 PCF read, with tent weights */
    "const int taps = pcf == 0 ? 1 : 2 * pcf;\n"
    "float tap(int i) { return float(i) - 0.5 * float(taps - 1); }\n"
    "uniform sampler2D base_tex;\n"
    "uniform vec3 eye, view_dir, lpos, ldir, radiant, origin;\n"
    "uniform int ortho_view;\n"
    "uniform float cos_outer, spot_width, texel, map_size;\n"
    "uniform float normal_offset, slope_bias, max_slope, const_bias, range;\n"
    "uniform float light_range; /* KHR_lights_punctual range, 0: none (lm_light_range_window) */\n"
    "uniform mat4 light_vp;\n"
    "uniform sampler2DShadow map2d;   /* metric / range, compared in the sampler (bilinear PCF) */\n"
    "uniform samplerCubeShadow mapcube;\n"
    "#if FIRST\n"
    "layout(location = 0) out vec4 frag;\n"
    "layout(location = 1) out vec4 kd_out; /* the diffuse lobe at the pixel, for later passes */\n"
    "layout(location = 2) out vec4 g_out;  /* position and normal (GBUFFER) */\n"
    "#else\n"
    "out vec4 frag;\n"
    "#endif\n"
    "const float PI = " LM_PI_GLSL ";\n"
    "float cube_shadow(vec3 q, float m, float T) {\n"
    "    vec3 d = q - lpos, a = abs(d);\n"
    "    vec3 t = normalize(cross(d, a.x < a.y ? vec3(1, 0, 0) : vec3(0, 1, 0)));\n"
    "    vec3 b = normalize(cross(d, t));\n"
    "    float lit = 0.0, ref = m / range;\n"
    "    for (int i = 0; i < taps; i++)\n"
    "        for (int j = 0; j < taps; j++)\n"
    "            lit += texture(mapcube, vec4(d + (tap(i) * t + tap(j) * b) * T, ref));\n"
    "    return lit;\n"
    "}\n"
    "float map_shadow(vec3 q, float m) {\n"
    "    vec4 c = light_vp * vec4(q, 1.0);\n"
    "    vec2 uv = c.xy / c.w * 0.5 + 0.5;\n"
    "    float lit = 0.0, ref = m / range;\n"
    "    for (int i = 0; i < taps; i++)\n"
    "        for (int j = 0; j < taps; j++) {\n"
    "            vec2 u = uv + vec2(tap(i), tap(j)) / map_size;\n"
    "            bool out_ = any(lessThan(u, vec2(0.0))) || any(greaterThan(u, vec2(1.0)));\n"
    "            lit += out_ ? 1.0 : texture(map2d, vec3(u, ref));\n"
    "        }\n"
    "    return lit;\n"
    "}\n"
    /* Fraction of PCF taps that see the light from p (geometric normal ng, unit L towards the light). */
    "float shadow(vec3 p, vec3 ng, vec3 L, float dist) {\n"
    "    float c = clamp(dot(ng, L), 1e-4, 1.0);\n"
    "    float tan_t = min(sqrt(1.0 - c * c) / c, max_slope);\n"
    "    vec3 a = kind == 0 ? abs(L) : vec3(abs(dot(L, ldir)));\n"
    "    float T = kind == 2 ? texel : texel * dist / max(max(a.x, a.y), max(a.z, 0.2));\n"
    "    vec3 q = p + ng * (normal_offset * T);\n"
    "    float bias = T * (const_bias + slope_bias * float(pcf + 1) * tan_t);\n"
    "    float m = (kind == 2 ? dot(q - origin, ldir) : length(q - lpos)) - bias;\n"
    "    float lit = kind == 0 ? cube_shadow(q, m, T) : map_shadow(q, m);\n"
    "    return lit / float(taps * taps);\n"
    "}\n"
    LOBES
    "vec3 light(vec3 p, vec3 ns, vec3 ng, vec3 V) {\n"
    "    vec3 L = -ldir, E = radiant;\n"
    "    float dist = 1.0;\n"
    "    if (kind != 2) {\n"
    "        vec3 d = lpos - p;\n"
    "        dist = length(d); L = d / dist; E /= dist * dist;\n"
    "        if (kind == 1) {\n"
    "            float t = clamp((dot(-L, ldir) - cos_outer) / spot_width, 0.0, 1.0);\n"
    "            E *= t * t;\n"
    "        }\n"
    "        if (light_range > 0.0) {\n"
    "            float r = dist / light_range;\n"
    "            E *= clamp(1.0 - r * r * r * r, 0.0, 1.0);\n"
    "        }\n"
    "    }\n"
    "    if (dot(ng, L) <= 0.0 || max(E.r, max(E.g, E.b)) <= 0.0) return vec3(0.0);\n"
    "    float n = v_par.x, lobe = pow(max(dot(reflect(-L, ns), V), 0.0), n);\n"
    "    vec3 kd, ks;\n"
    "    lobes(kd, ks);\n"
    "    vec3 f = kd / PI + ks * (n + 2.0) / (2.0 * PI) * lobe;\n"
    "    return f * E * max(dot(ns, L), 0.0) * shadow(p, ng, L, dist);\n"
    "}\n"
    INDIRECT
    COVERAGE
    GBUFFER
    "void main() {\n"
    "    look_up_albedo();\n"
    "    vec3 V = ortho_view != 0 ? view_dir : normalize(eye - v_pos);\n"
    "    vec3 ng = normalize(cross(dFdx(v_pos), dFdy(v_pos))), ns = normalize(v_ns);\n"
    "    if (dot(ng, V) < 0.0) ng = -ng; /* the side seen */\n"
    "    bool back = !gl_FrontFacing;\n"
    "    if (back) ns = -ns;\n"
    "    if (dot(ns, ng) < 0.0) ns = ng;\n"
    "    bool seen = !back || v_par.y > 0.5;\n"
    "    vec3 c = light(v_pos, ns, ng, V);\n"
    "#if FIRST\n"
    "    c += v_em;\n"
    "    frag = vec4(seen ? c + indirect() : vec3(0.0), 1.0); /* the back of a single-sided surface: black */\n"
    "    vec3 kd, ks;\n"
    "    lobes(kd, ks);\n"
    "    kd_out = vec4(seen ? kd : vec3(0.0), inv_coverage());\n"
    "    g_out = gbuffer(v_pos, ns, seen);\n"
    "#else\n"
    "    frag = vec4(seen ? c : vec3(0.0), 1.0);\n"
    "#endif\n"
    "}\n";

/* The emission-only first pass (a scene without punctual lights): depth, and Le on the front side (or
 * both sides when double-sided; the back of a single-sided surface is black, lightmap and all, as the
 * reference sees it), plus the indirect term (INDIRECT above); the same attributes and gl_Position as
 * lm_direct_vs. */
const char *const lm_direct_emission_vs =
    "#version 450 core\n"
    "layout(location = 0) in vec3 pos;\n"
    "layout(location = 1) in vec3 ns;\n"
    "layout(location = 2) in vec3 base;\n"
    "layout(location = 3) in vec4 par;\n"
    "layout(location = 4) in vec3 em;\n"
    "layout(location = 5) in vec2 uv;\n"
    "layout(location = 7) in vec2 lm_uv;\n"
    "uniform mat4 view_proj;\n"
    "out vec3 v_pos, v_ns;\n"
    "flat out vec3 v_em, v_base;\n"
    "flat out vec4 v_par;\n"
    "out vec2 v_uv, v_lm;\n"
    "invariant gl_Position;\n"
    VERTEX_RANGES
    "void main() {\n"
    "    v_pos = pos; v_ns = ns; v_em = em; v_base = base; v_par = par; v_uv = uv; v_lm = lm_uv;\n"
    "    gl_Position = dropped() ? vec4(2.0, 2.0, 2.0, 1.0) : view_proj * vec4(pos, 1.0);\n"
    "}\n";

const char *const lm_direct_emission_fs =
    "#version 450 core\n"
    "in vec3 v_pos, v_ns;\n"
    "flat in vec3 v_em, v_base;\n"
    "flat in vec4 v_par;\n"
    "in vec2 v_uv, v_lm;\n"
    "uniform sampler2D lit, base_tex;\n"
    "uniform int use_lit, has_tex;\n"
    "uniform vec3 eye, view_dir;\n"
    "uniform int ortho_view;\n"
    "layout(location = 0) out vec4 frag;\n"
    "layout(location = 1) out vec4 kd_out;\n"
    "layout(location = 2) out vec4 g_out;\n"
    LOBES
    INDIRECT
    COVERAGE
    GBUFFER
    "void main() {\n"
    "    look_up_albedo();\n"
    "    bool seen = gl_FrontFacing || v_par.y > 0.5; /* the back of a single-sided surface: black */\n"
    "    vec3 V = ortho_view != 0 ? view_dir : normalize(eye - v_pos);\n"
    "    vec3 ng = normalize(cross(dFdx(v_pos), dFdy(v_pos))), ns = normalize(v_ns);\n"
    "    if (dot(ng, V) < 0.0) ng = -ng;\n"
    "    if (!gl_FrontFacing) ns = -ns;\n"
    "    if (dot(ns, ng) < 0.0) ns = ng;\n"
    "    frag = vec4(seen ? v_em + indirect() : vec3(0.0), 1.0);\n"
    "    vec3 kd, ks;\n"
    "    lobes(kd, ks);\n"
    "    kd_out = vec4(seen ? kd : vec3(0.0), inv_coverage());\n"
    "    g_out = gbuffer(v_pos, ns, seen);\n"
    "}\n";
