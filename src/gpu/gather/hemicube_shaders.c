/* The gather's shaders. SCHEME selects how a texel's plane reaches its R x R tile:
 *   0 viewports: one draw per texel, its view in uniforms, its tile a glViewport;
 *   1 instanced: one instanced draw per pass, instance i's view from a buffer, its clip-space position
 *     scaled into tile i of the big target and cut to it by four clip distances;
 *   2 layered: as 1, but instance i renders into layer i of an array target (gl_Layer from the vertex
 *     shader, GL_ARB_shader_viewport_layer_array). */
#include "hemicube_shaders.h"

#include <stdio.h>

#include "../gl/gl_shader.h"

/* Vertex: world position, lightmap UV (-1 when none), emitted radiance, face normal, single-sided (0
 * double-sided, 1 single-sided, 2 one side of a split surface), surface (-1 when none). A view (schemes
 * 1, 2) is 4 vec4: (eye, own surface), b / a, t / a, n; the w of the last three is the texel's
 * geometric normal. */
static const char *RENDER_VS =
    "layout(location = 0) in vec3 pos;\n"
    "layout(location = 1) in vec2 uv;\n"
    "layout(location = 2) in vec3 emit;\n"
    "layout(location = 3) in vec3 face_n;\n"
    "layout(location = 4) in float one_sided;\n"
    "layout(location = 5) in float surface;\n"
    "layout(location = 6) in vec3 grad_u;\n"
    "layout(location = 7) in vec3 grad_v;\n"
    "layout(location = 8) in vec4 rect;\n"
    "out vec3 v_pos; out vec2 v_uv;\n"
    "flat out vec3 v_emit; flat out vec3 v_n; flat out float v_one; flat out vec3 v_eye;\n"
    "flat out vec3 v_gu, v_gv, v_ax, v_ay; flat out vec4 v_rect; flat out vec3 v_ng;\n"
    "#if SCHEME == 0\n"
    "uniform mat4 view_proj; uniform vec3 eye; uniform float own_surface; uniform vec3 axis_x, axis_y, geo_n;\n"
    "#else\n"
    "layout(std430, binding = 2) readonly buffer Views { vec4 views[]; };\n"
    "uniform int tiles; uniform float near;\n"
    "#endif\n"
    "#if SCHEME == 1\n"
    "out float gl_ClipDistance[4];\n"
    "#endif\n"
    "void main() {\n"
    "    v_pos = pos; v_uv = uv; v_emit = emit; v_n = face_n; v_one = one_sided;\n"
    "    v_gu = grad_u; v_gv = grad_v; v_rect = rect;\n"
    "    float own;\n"
    "#if SCHEME == 0\n"
    "    v_eye = eye; own = own_surface; v_ax = axis_x; v_ay = axis_y; v_ng = geo_n;\n"
    "    gl_Position = view_proj * vec4(pos, 1.0);\n"
    "#else\n"
    "    int i = gl_InstanceID;\n"
    "    vec4 e = views[4 * i];\n"
    "    vec3 q = pos - e.xyz;\n"
    "    vec4 c = vec4(dot(views[4 * i + 1].xyz, q), dot(views[4 * i + 2].xyz, q), near, dot(views[4 * i + 3].xyz, q));\n"
    "    v_eye = e.xyz; own = e.w;\n"
    "    v_ng = vec3(views[4 * i + 1].w, views[4 * i + 2].w, views[4 * i + 3].w);\n"
    "    vec3 B = views[4 * i + 1].xyz, T = views[4 * i + 2].xyz;\n"
    "    v_ax = B / dot(B, B); v_ay = T / dot(T, T);\n"
    "#if SCHEME == 1\n"
    "    gl_ClipDistance[0] = c.w + c.x; gl_ClipDistance[1] = c.w - c.x;\n"
    "    gl_ClipDistance[2] = c.w + c.y; gl_ClipDistance[3] = c.w - c.y;\n"
    "    float s = 1.0 / float(tiles);\n"
    "    vec2 cell = vec2(float(i % tiles), float(i / tiles));\n"
    "    c.xy = c.xy * s + c.w * ((2.0 * cell + 1.0) * s - 1.0);\n"
    "#else\n"
    "    gl_Layer = i;\n"
    "#endif\n"
    "    gl_Position = c;\n"
    "#endif\n"
    "    /* the back of the texel's own surface, and the back of one side of a split double-sided surface\n"
    "     * (its twin, on the same plane, shows that side): every corner gets the same n.(p - eye) (a plane),\n"
    "     * so the whole triangle moves outside the clip volume and is dropped before rasterization */\n"
    "    if ((surface >= 0.0 && surface == own || one_sided > 1.5) && dot(face_n, pos - v_eye) > 0.0)\n"
    "        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);\n"
    "}\n";
/* rgb: what the plane sees; a: 1 on the back of a single-sided surface (counted, shown black). Below the
 * plane of the texel's own triangle nothing is seen (black, not counted): where the shading normal
 * tilts away from the geometric one (smoothed corners), the plane reaches below the surface and would
 * otherwise see the texel's own surface from above, which light from there cannot reach. The back
 * of the texel's own surface is dropped in the vertex shader (a surface stays within a 30 degree cone, so
 * only a simplified (proxy) copy of it can pass above the texel); no discard here keeps the depth test
 * early.
 * With samples = 4 the AIM is looked up at four points of the pixel (rotated grid), each found exactly on the triangle's
 * plane: ray d' = d + w (dx axis_x + dy axis_y) (w = the pixel's distance along the plane normal, dx, dy
 * the offsets in clip units), hit point P' on the plane, uv' = uv + (gu.(P' - p), gv.(P' - p)) kept inside
 * the chart. A surface seen nearly edge-on (a ceiling from just below it) squeezes much of itself into
 * one pixel row; one sample there lands on a small bright spot or misses it from texel to texel, which
 * bands the IIM (docs/gather.md). Sub-rays that miss the plane use the pixel's own uv. */
static const char *RENDER_FS =
    "in vec3 v_pos; in vec2 v_uv;\n"
    "flat in vec3 v_emit; flat in vec3 v_n; flat in float v_one; flat in vec3 v_eye;\n"
    "flat in vec3 v_gu, v_gv, v_ax, v_ay; flat in vec4 v_rect; flat in vec3 v_ng;\n"
    "uniform sampler2D aim;\n"
    "uniform float pixel;   /* a pixel's side in clip units, 2 / R */\n"
    "out vec4 frag;\n"
    "const vec2 SUB[4] = vec2[4](vec2(0.125, 0.375), vec2(0.375, -0.125), vec2(-0.125, -0.375), vec2(-0.375, 0.125));\n"
    "vec3 aim_radiance() {\n"
    "    vec3 d = v_pos - v_eye;\n"
    "    float w = 1.0 / gl_FragCoord.w, num = dot(v_n, d);\n"
    "    vec3 L = vec3(0.0);\n"
    "    for (int k = 0; k < 4; k++) {\n"
    "        vec3 dk = d + (w * pixel) * (SUB[k].x * v_ax + SUB[k].y * v_ay);\n"
    "        float den = dot(v_n, dk);\n"
    "        vec2 uv = v_uv;\n"
    "        if (num * den > 0.0) {\n"
    "            vec3 off = (num / den) * dk - d;\n"
    "            uv = clamp(v_uv + vec2(dot(v_gu, off), dot(v_gv, off)), v_rect.xy, v_rect.zw);\n"
    "        }\n"
    "        L += texture(aim, uv).rgb;\n"
    "    }\n"
    "    return 0.25 * L;\n"
    "}\n"
    "void main() {\n"
    "    if (dot(v_ng, v_pos - v_eye) < 0.0) { frag = vec4(0.0); return; }\n"
    "    if (v_one > 0.5 && dot(v_n, v_pos - v_eye) > 0.0) { frag = vec4(0.0, 0.0, 0.0, 1.0); return; }\n"
    "#if SAMPLES == 4\n"
    "    vec3 L = v_uv.x < 0.0 ? vec3(0.0) : aim_radiance();\n"
    "#else\n"
    "    vec3 L = v_uv.x < 0.0 ? vec3(0.0) : texture(aim, v_uv).rgb;\n"
    "#endif\n"
    "    frag = vec4(L + v_emit, 0.0);\n"
    "}\n";
/* One invocation per tile, summing its R^2 weighted pixels in a fixed order (deterministic, and no
 * barriers: cheap on a CPU rasterizer that runs a work group's invocations as SIMD lanes). */
static const char *REDUCE_CS =
    "layout(local_size_x = 8) in;\n"
    "#if SCHEME == 2\n"
    "layout(binding = 0) uniform sampler2DArray tiles;\n"
    "#else\n"
    "layout(binding = 0) uniform sampler2D tiles;\n"
    "#endif\n"
    "layout(binding = 0, rgba32f) uniform writeonly image2D iim;\n"
    "layout(std430, binding = 0) readonly buffer Weights { float w[]; };\n"
    "layout(std430, binding = 1) readonly buffer Targets { ivec2 xy[]; };\n"
    "layout(std430, binding = 3) readonly buffer Cpu { vec4 emit[]; }; /* emitter + rim E, 1 if covered */\n"
    "uniform int R;\n"
    "uniform int tiles_x;\n"
    "uniform int count;\n"
    "uniform float scale;   /* pi / F(a), or pi when the rim is traced */\n"
    "uniform float inv_f;   /* 1 / F(a) */\n"
    "void main() {\n"
    "    int tile = int(gl_GlobalInvocationID.x);\n"
    "    if (tile >= count) return;\n"
    "    vec4 s = vec4(0.0);\n"
    "#if SCHEME == 2\n"
    "    for (int y = 0; y < R; y++)\n"
    "        for (int x = 0; x < R; x++)\n"
    "            s += w[y * R + x] * texelFetch(tiles, ivec3(x, y, tile), 0);\n"
    "#else\n"
    "    ivec2 origin = ivec2(tile % tiles_x, tile / tiles_x) * R;\n"
    "    for (int y = 0; y < R; y++)\n"
    "        for (int x = 0; x < R; x++)\n"
    "            s += w[y * R + x] * texelFetch(tiles, origin + ivec2(x, y), 0);\n"
    "#endif\n"
    "    imageStore(iim, xy[tile], vec4(scale * s.rgb + emit[tile].rgb, inv_f * s.a + emit[tile].a));\n"
    "}\n";

/* "#version", the scheme's and sample count's defines and extension, then the body. Returns 0 if it
 * does not fit. */
static int with_header(char *out, size_t size, lm_gather_scheme scheme, int samples, int vertex, const char *body)
{
    int n = snprintf(out, size, "#version 450 core\n%s#define SCHEME %d\n#define SAMPLES %d\n%s",
                     vertex && scheme == LM_GATHER_LAYERED ? "#extension GL_ARB_shader_viewport_layer_array : require\n" : "",
                     (int)scheme, samples, body);
    return n > 0 && (size_t)n < size;
}

lm_status lm_hemicube_programs(lm_gather_scheme scheme, int samples, unsigned *render, unsigned *reduce, lm_error *err)
{
    char vs[5120], fs[4096], cs[2560];
    if (!with_header(vs, sizeof vs, scheme, samples, 1, RENDER_VS) ||
        !with_header(fs, sizeof fs, scheme, samples, 0, RENDER_FS) ||
        !with_header(cs, sizeof cs, scheme, samples, 0, REDUCE_CS))
        return lm_fail(err, LM_ERR_BACKEND, "hemicube shaders: source buffer too small");
    lm_status st = lm_gl_program("hemicube_render", vs, fs, render, err);
    if (st == LM_OK)
        st = lm_gl_compute_program("hemicube_reduce", cs, reduce, err);
    return st;
}
