// An atlas of irradiance seen from a view (lightmap_view.h, lm_render_atlas_irradiance): rgb / a of the
// bilinear filter, a the texels' weights (rgb is 0 where a is), so texels without light of their own
// neither darken nor leak into a chart's border; 0 on triangles without lightmap texels.
#version 450 core
in vec2 v_uv;
uniform sampler2D atlas;
out vec4 frag;
void main() {
    vec4 t = v_uv.x < 0.0 ? vec4(0.0) : texture(atlas, v_uv);
    frag = vec4(t.a > 0.0 ? t.rgb / t.a : vec3(0.0), 1.0);
}
