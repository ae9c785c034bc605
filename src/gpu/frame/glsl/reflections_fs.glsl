// Mirror: F x env(r), F the metal's Fresnel (Schlick's, the albedo as F0: lm_mirror_fresnel). Glossy: ks (n + 2) / (n + 1) max(n.r, 0) x env(r) at the mip level whose texel
// is the lobe's width 1 / sqrt(n) (lod_base = log2(size / (pi / 2)), a face spanning pi / 2). Glass (ior
// in the vertex's n): F env(r) + (1 - F) albedo env(t), F the dielectric Fresnel reflectance at the eye
// ray's angle (Schlick's approximation to it; 1 for KHR_materials_ior's 0), t the ray refracted into the
// glass at this first surface (F 1 under total internal reflection, leaving the inside), looked up as if it
// left unbent: the glass's far side and the parallax of what lies behind are not modelled. albedo and ks
// from the direct light's lobes (lobes.glsl), so both passes read a material alike. The back of a
// single-sided surface reflects nothing. Class numbers as there (1 glossy, 2 mirror, 3 glass).
#version 450 core
#include "mesh_inputs.glsl"
uniform int has_tex;
uniform sampler2D base_tex;
uniform samplerCube env;
uniform vec3 eye;
uniform float lod_base;
uniform int use_box;
uniform vec3 box_lo, box_hi, centre;
out vec4 frag;
// box-projected lookup: the ray from the pixel to the proxy box, looked up from the map's centre
vec3 parallax(vec3 d) {
    if (use_box == 0) return d;
    vec3 tf = max((box_hi - v_pos) / d, (box_lo - v_pos) / d);
    float t = min(min(tf.x, tf.y), tf.z);
    return t > 0.0 ? v_pos + d * t - centre : d;
}
#include "lobes.glsl"
void main() {
    look_up_albedo();
    bool two = v_par.y > 0.5;
    if (!gl_FrontFacing && !two) { frag = vec4(0.0); return; }
    vec3 n = normalize(gl_FrontFacing ? v_ns : -v_ns);
    vec3 r = reflect(normalize(v_pos - eye), n);
    int cls = int(v_par.w + 0.5);
    if (cls == 2) { /* a metal's Fresnel, Schlick's with the albedo as F0 (bsdf.c's lm_mirror_fresnel) */
        float m = 1.0 - clamp(abs(dot(normalize(v_pos - eye), n)), 0.0, 1.0);
        vec3 F = albedo + (1.0 - albedo) * (m * m * m * m * m);
        frag = vec4(F * textureLod(env, parallax(r), 0.0).rgb, 0.0);
        return;
    }
    if (cls == 3) {
        vec3 d = normalize(v_pos - eye);
        if (v_par.x == 0.0) { frag = vec4(textureLod(env, parallax(r), 0.0).rgb, 0.0); return; } /* ior 0 */
        float eta = gl_FrontFacing ? 1.0 / v_par.x : v_par.x, c = clamp(-dot(d, n), 0.0, 1.0);
        vec3 t = refract(d, n, eta);
        float f0 = (1.0 - v_par.x) / (1.0 + v_par.x), F = f0 * f0 + (1.0 - f0 * f0) * pow(1.0 - c, 5.0);
        if (dot(t, t) == 0.0) F = 1.0;
        vec3 through = dot(t, t) > 0.0 ? albedo * textureLod(env, parallax(t), 0.0).rgb : vec3(0.0);
        frag = vec4(F * textureLod(env, parallax(r), 0.0).rgb + (1.0 - F) * through, 0.0);
        return;
    }
    vec3 kd, ks;
    lobes(kd, ks);
    float e = v_par.x;
    float lod = max(0.0, lod_base - 0.5 * log2(e));
    float w = (e + 2.0) / (e + 1.0) * max(dot(n, r), 0.0);
    frag = vec4(ks * w * textureLod(env, parallax(r), lod).rgb, 0.0);
}
