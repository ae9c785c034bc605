// The vertex shader of the direct-light passes (direct.c: the light programs and the emission-only one)
// and of the reflections (reflections_fs.glsl): every program over the direct-light mesh computes
// gl_Position with this same invariant expression, so their depths match exactly.
// Attributes (world space): position, shading normal, base colour factor, (Phong exponent, double-sided,
// metallic, material class), emitted radiance, base colour texture uv (KHR_texture_transform applied).
// The per-material ones are flat (no interpolation: cheaper on llvmpipe). The geometric normal is the
// cross product of the position's screen derivatives, exact on a planar triangle, so vertices are shared
// between triangles; gl_FrontFacing says which side of the triangle (by its winding) is seen.
#version 450 core
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 ns;
layout(location = 2) in vec3 base;
layout(location = 3) in vec4 par;
layout(location = 4) in vec3 em;
layout(location = 5) in vec2 uv;
layout(location = 7) in vec2 lm_uv;
uniform mat4 view_proj;
uniform vec4 clip_plane; // a mirror's picture keeps dot(clip_plane, (pos, 1)) >= 0 (GL_CLIP_DISTANCE0 on)
out float gl_ClipDistance[1];
out vec3 v_pos, v_ns;
flat out vec3 v_base, v_em;
flat out vec4 v_par;
out vec2 v_uv, v_lm;
invariant gl_Position;
#include "vertex_ranges.glsl"
void main() {
    v_pos = pos; v_ns = ns; v_base = base; v_par = par; v_em = em; v_uv = uv; v_lm = lm_uv;
    gl_Position = dropped() ? vec4(2.0, 2.0, 2.0, 1.0) : view_proj * vec4(pos, 1.0);
    gl_ClipDistance[0] = dot(clip_plane, vec4(pos, 1.0));
}
