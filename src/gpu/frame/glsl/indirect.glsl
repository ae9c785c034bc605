// The indirect term at a pixel: kd / pi x E_IIM, E / pi from the premultiplied atlas `lit`
// (gpu/frame/composite.h) at the lightmap uv (attribute 7, -1 without a chart), rgb / a over the covered, valid
// texels of its bilinear footprint, kd per pixel (the base colour texture at the pixel, not at the texel's
// centre: a texture finer than the lightmap stays sharp).
vec3 indirect() {
    if (use_lit != 1 || v_lm.x < 0.0) return vec3(0.0);
    vec4 t = textureLod(lit, v_lm, 0.0);
    if (t.a <= 0.0) return vec3(0.0);
    vec3 kd, ks;
    lobes(kd, ks);
    return kd * t.rgb / t.a;
}
