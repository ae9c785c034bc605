// Mirror: F x env(r), F the metal's Fresnel (Schlick's, the albedo as F0: lm_mirror_fresnel). Glossy: ks (n + 2) / (n + 1) max(n.r, 0) x env(r) at the mip level whose texel
// is the lobe's width 1 / sqrt(n) (lod_base = log2(size / (pi / 2)), a face spanning pi / 2). Glass (ior
// in the vertex's n): F env(r) + (1 - F) albedo env(t), F the dielectric Fresnel reflectance at the eye
// ray's angle (Schlick's approximation to it; 1 for KHR_materials_ior's 0), t the ray refracted into the
// glass at this first surface (F 1 under total internal reflection, leaving the inside), looked up as if it
// left unbent: the glass's far side and the parallax of what lies behind are not modelled. albedo and ks
// from the direct light's lobes (lobes.glsl), so both passes read a material alike. The back of a
// single-sided surface reflects nothing. Class numbers as there (1 glossy, 2 mirror, 3 glass).
// A flat reflector (planar; reflections.h) looks its mirrored picture up at this pixel instead of the
// cube map: what the plane reflects towards the eye is there (the shading normal's bend is not followed),
// blurred for a glossy lobe to the mip level whose texel is the lobe's width where it reaches the
// reflected surface: (distance behind the plane) x width, seen from the mirrored eye, in pixels.
#version 450 core
#include "mesh_inputs.glsl"
uniform int has_tex;
uniform sampler2D base_tex;
uniform samplerCube env;
uniform vec3 eye;
uniform float lod_base;
uniform int use_box;
uniform vec3 box_lo, box_hi, centre;
uniform int planar;
uniform sampler2D plane_tex, plane_depth;
uniform vec3 plane_size; // the picture's width, height, and its last mip level
uniform vec4 lens;       // the view's P10, P14, P5 and whether it is orthographic
out vec4 frag;
// box-projected lookup: the ray from the pixel to the proxy box, looked up from the map's centre
vec3 parallax(vec3 d) {
    if (use_box == 0) return d;
    vec3 tf = max((box_hi - v_pos) / d, (box_lo - v_pos) / d);
    float t = min(min(tf.x, tf.y), tf.z);
    return t > 0.0 ? v_pos + d * t - centre : d;
}
// distance along the view's axis of a window depth (the frame's and the mirrored picture's projection)
float axial(float depth) {
    float z = 2.0 * depth - 1.0;
    return lens.w > 0.5 ? (lens.y - z) / lens.x : lens.y / (z + lens.x);
}
// the mirrored picture at this pixel, blurred to an angular width (0: sharp)
vec3 plane_seen(float width) {
    vec2 uv = gl_FragCoord.xy / plane_size.xy;
    if (width <= 0.0) return textureLod(plane_tex, uv, 0.0).rgb;
    float here = axial(gl_FragCoord.z), hit = axial(texelFetch(plane_depth, ivec2(gl_FragCoord.xy), 0).r);
    float pixels = 0.5 * lens.z * plane_size.y; // a unit across at axial distance 1
    float behind = max(hit - here, 0.0) * length(v_pos - eye) / here; // along the reflected ray
    float across = behind * width * pixels / (lens.w > 0.5 ? 1.0 : hit);
    return textureLod(plane_tex, uv, clamp(log2(max(across, 1.0)), 0.0, plane_size.z)).rgb;
}
// what the surface reflects along r, blurred to an angular width (0: sharp); cube lod as the header says
vec3 seen(vec3 r, float width) {
    if (planar == 1) return plane_seen(width);
    return textureLod(env, parallax(r), width > 0.0 ? max(0.0, lod_base + log2(width)) : 0.0).rgb;
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
        frag = vec4(F * seen(r, 0.0), 0.0);
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
    float w = (e + 2.0) / (e + 1.0) * max(dot(n, r), 0.0);
    frag = vec4(ks * w * seen(r, inversesqrt(e)), 0.0);
}
