// The emission-only first pass (a scene without punctual lights), over direct_vs.glsl: depth, and Le on
// the front side (or both sides when double-sided; the back of a single-sided surface is black, lightmap
// and all, as the reference sees it), plus the indirect term (indirect.glsl).
#version 450 core
#include "mesh_inputs.glsl"
uniform sampler2D lit, base_tex;
uniform int use_lit, has_tex;
uniform vec3 eye, view_dir;
uniform int ortho_view;
layout(location = 0) out vec4 frag;
layout(location = 1) out vec4 kd_out;
layout(location = 2) out vec4 g_out;
#include "lobes.glsl"
#include "indirect.glsl"
#include "coverage.glsl"
#include "gbuffer_pack.glsl"
void main() {
    look_up_albedo();
    bool seen = gl_FrontFacing || v_par.y > 0.5; /* the back of a single-sided surface: black */
    vec3 V = ortho_view != 0 ? view_dir : normalize(eye - v_pos);
    vec3 ng = normalize(cross(dFdx(v_pos), dFdy(v_pos))), ns = normalize(v_ns);
    if (dot(ng, V) < 0.0) ng = -ng;
    if (!gl_FrontFacing) ns = -ns;
    if (dot(ns, ng) < 0.0) ns = ng;
    frag = vec4(seen ? v_em + indirect() : vec3(0.0), 1.0);
    vec3 kd, ks;
    lobes(kd, ks);
    kd_out = vec4(seen ? kd : vec3(0.0), inv_coverage());
    g_out = gbuffer(v_pos, ns, seen);
}
