// The indirect term at a pixel: kd / pi x E_IIM, E / pi from the premultiplied atlas `lit`
// (gpu/frame/composite.h) at the lightmap uv (attribute 7, -1 without a chart), rgb / a over the covered, valid
// texels of its bilinear footprint, kd per pixel (the base colour texture at the pixel, not at the texel's
// centre: a texture finer than the lightmap stays sharp).
// A footprint texel (one for a whole curved piece) also turns with the pixel's shading normal n: per channel
// E (1 + r . n - r . nbar) from its turn map (channel c's r and r . nbar as RGBA, gpu/gather/iim.h), 0 on
// every other texel. Its chart is that texel alone, every corner at its centre, so the nearest texel is the
// one the bilinear lookup reads. Kept within [1/4, 4] of the texel's value: a normal the piece does not
// hold (a moved node's, before its regather) gets no more than that.
uniform sampler2D turn[3];
uniform int use_turn;
vec3 turned(vec3 e) {
    if (use_turn != 1) return e;
    vec3 n = normalize(v_ns), f;
    for (int c = 0; c < 3; c++) {
        vec4 r = textureLod(turn[c], v_lm, 0.0);
        f[c] = 1.0 + dot(r.xyz, n) - r.w;
    }
    return e * clamp(f, vec3(0.25), vec3(4.0));
}
vec3 indirect() {
    if (use_lit != 1 || v_lm.x < 0.0) return vec3(0.0);
    vec4 t = textureLod(lit, v_lm, 0.0);
    if (t.a <= 0.0) return vec3(0.0);
    vec3 kd, ks;
    lobes(kd, ks);
    return kd * turned(t.rgb / t.a);
}
