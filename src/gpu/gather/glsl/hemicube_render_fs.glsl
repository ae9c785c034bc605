// rgb: what the plane sees; a: 1 on the back of a single-sided surface (counted, shown black). Below the
// plane of the texel's own triangle nothing is seen (black, not counted): where the shading normal
// tilts away from the geometric one (smoothed corners), the plane reaches below the surface and would
// otherwise see the texel's own surface from above, which light from there cannot reach. The back
// of the texel's own surface is dropped in the vertex shader (a surface stays within a 30 degree cone, so
// only a simplified (proxy) copy of it can pass above the texel); no discard here keeps the depth test
// early.
// With samples = 4 the AIM is looked up at four points of the pixel (rotated grid), each found exactly on the triangle's
// plane: ray d' = d + w (dx axis_x + dy axis_y) (w = the pixel's distance along the plane normal, dx, dy
// the offsets in clip units), hit point P' on the plane, uv' = uv + (gu.(P' - p), gv.(P' - p)) kept inside
// the chart. A surface seen nearly edge-on (a ceiling from just below it) squeezes much of itself into
// one pixel row; one sample there lands on a small bright spot or misses it from texel to texel, which
// bands the IIM (docs/gather.md). Sub-rays that miss the plane use the pixel's own uv.
in vec3 v_pos; in vec2 v_uv;
flat in vec3 v_emit; flat in vec3 v_n; flat in float v_one; flat in vec3 v_eye;
flat in vec3 v_gu, v_gv, v_ax, v_ay; flat in vec4 v_rect; flat in vec3 v_ng;
uniform sampler2D aim;
uniform float pixel;   /* a pixel's side in clip units, 2 / R */
out vec4 frag;
const vec2 SUB[4] = vec2[4](vec2(0.125, 0.375), vec2(0.375, -0.125), vec2(-0.125, -0.375), vec2(-0.375, 0.125));
vec3 aim_radiance() {
    vec3 d = v_pos - v_eye;
    float w = 1.0 / gl_FragCoord.w, num = dot(v_n, d);
    vec3 L = vec3(0.0);
    for (int k = 0; k < 4; k++) {
        vec3 dk = d + (w * pixel) * (SUB[k].x * v_ax + SUB[k].y * v_ay);
        float den = dot(v_n, dk);
        vec2 uv = v_uv;
        if (num * den > 0.0) {
            vec3 off = (num / den) * dk - d;
            uv = clamp(v_uv + vec2(dot(v_gu, off), dot(v_gv, off)), v_rect.xy, v_rect.zw);
        }
        L += texture(aim, uv).rgb;
    }
    return 0.25 * L;
}
void main() {
    if (dot(v_ng, v_pos - v_eye) < 0.0) { frag = vec4(0.0); return; }
    if (v_one > 0.5 && dot(v_n, v_pos - v_eye) > 0.0) { frag = vec4(0.0, 0.0, 0.0, 1.0); return; }
#if SAMPLES == 4
    vec3 L = v_uv.x < 0.0 ? vec3(0.0) : aim_radiance();
#else
    vec3 L = v_uv.x < 0.0 ? vec3(0.0) : texture(aim, v_uv).rgb;
#endif
    frag = vec4(L + v_emit, 0.0);
}
