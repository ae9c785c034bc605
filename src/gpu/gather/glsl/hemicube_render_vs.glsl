// Vertex: world position, lightmap UV (-1 when none), emitted radiance, face normal, single-sided (0
// double-sided, 1 single-sided, 2 one side of a split surface), surface (-1 when none). A view (schemes
// 1, 2) is 4 vec4: (eye, own surface), b / a, t / a, n; the w of the last three is the texel's
// geometric normal.
layout(location = 0) in vec3 pos;
layout(location = 1) in vec2 uv;
layout(location = 2) in vec3 emit;
layout(location = 3) in vec3 face_n;
layout(location = 4) in float one_sided;
layout(location = 5) in float surface;
layout(location = 6) in vec3 grad_u;
layout(location = 7) in vec3 grad_v;
layout(location = 8) in vec4 rect;
out vec3 v_pos; out vec2 v_uv;
flat out vec3 v_emit; flat out vec3 v_n; flat out float v_one; flat out vec3 v_eye;
flat out vec3 v_gu, v_gv, v_ax, v_ay; flat out vec4 v_rect; flat out vec3 v_ng;
#if SCHEME == 0
uniform mat4 view_proj; uniform vec3 eye; uniform float own_surface; uniform vec3 axis_x, axis_y, geo_n;
#else
layout(std430, binding = 2) readonly buffer Views { vec4 views[]; };
uniform int tiles; uniform float near;
#endif
#if SCHEME == 1
out float gl_ClipDistance[4];
#endif
void main() {
    v_pos = pos; v_uv = uv; v_emit = emit; v_n = face_n; v_one = one_sided;
    v_gu = grad_u; v_gv = grad_v; v_rect = rect;
    float own;
#if SCHEME == 0
    v_eye = eye; own = own_surface; v_ax = axis_x; v_ay = axis_y; v_ng = geo_n;
    gl_Position = view_proj * vec4(pos, 1.0);
#else
    int i = gl_InstanceID;
    vec4 e = views[4 * i];
    vec3 q = pos - e.xyz;
    vec4 c = vec4(dot(views[4 * i + 1].xyz, q), dot(views[4 * i + 2].xyz, q), near, dot(views[4 * i + 3].xyz, q));
    v_eye = e.xyz; own = e.w;
    v_ng = vec3(views[4 * i + 1].w, views[4 * i + 2].w, views[4 * i + 3].w);
    vec3 B = views[4 * i + 1].xyz, T = views[4 * i + 2].xyz;
    v_ax = B / dot(B, B); v_ay = T / dot(T, T);
#if SCHEME == 1
    gl_ClipDistance[0] = c.w + c.x; gl_ClipDistance[1] = c.w - c.x;
    gl_ClipDistance[2] = c.w + c.y; gl_ClipDistance[3] = c.w - c.y;
    float s = 1.0 / float(tiles);
    vec2 cell = vec2(float(i % tiles), float(i / tiles));
    c.xy = c.xy * s + c.w * ((2.0 * cell + 1.0) * s - 1.0);
#else
    gl_Layer = i;
#endif
    gl_Position = c;
#endif
    /* the back of the texel's own surface, and the back of one side of a split double-sided surface
     * (its twin, on the same plane, shows that side): every corner gets the same n.(p - eye) (a plane),
     * so the whole triangle moves outside the clip volume and is dropped before rasterization */
    if ((surface >= 0.0 && surface == own || one_sided > 1.5) && dot(face_n, pos - v_eye) > 0.0)
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
}
