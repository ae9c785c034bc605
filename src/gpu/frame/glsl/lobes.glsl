// For the passes over direct_vs.glsl's outputs: declares `vec3 albedo`, `look_up_albedo()` (call first in
// main(), in uniform control flow; needs uniforms has_tex and base_tex) and `lobes(out vec3 kd, out vec3
// ks)`.
// bsdf.c's lobes (lm_material_lobes) per pixel, base colour texture included: diffuse and emitter kd =
// albedo; glossy ks = mix(0.04, albedo, metallic), kd = albedo (1 - metallic)(1 - max ks); mirror and
// glass none here.
// The albedo: a diffuse surface's light is linear in it, so its texture is read trilinearly, averaged
// over the pixel's footprint as the reference's many paths a pixel average it (a texture finer than the
// pixels, the cornell-suzanne block's checker, does not alias: its pixels' error 0.14 -> 0.05). A glossy
// lobe is not linear in it (kd = a (1 - m)(1 - max ks)): the lobe of the averaged texture is not the
// average of the lobes (the depth-of-field board, copper traces on green, read 1.79 1.16 1.06 so), so a
// glossy surface reads level 0 at the pixel's centre. Both lookups at the top of main(), in uniform
// control flow (a mipmapped lookup in a branch has no defined derivatives); the branch on has_tex, a
// uniform, is uniform too, and spares an untextured draw both lookups (about 5% of the showcase's view
// pass on llvmpipe).
vec3 albedo;
void look_up_albedo() {
    albedo = v_base;
    if (has_tex == 0) return;
    vec3 fine = textureLod(base_tex, v_uv, 0.0).rgb, filtered = texture(base_tex, v_uv).rgb;
    albedo *= int(v_par.w + 0.5) == 1 ? fine : filtered;
}
void lobes(out vec3 kd, out vec3 ks) {
    vec3 a = albedo;
    int cls = int(v_par.w + 0.5);
    kd = vec3(0.0); ks = vec3(0.0);
    if (cls == 0 || cls == 4) kd = a;
    if (cls != 1) return;
    ks = mix(vec3(0.04), a, v_par.z);
    kd = a * (1.0 - v_par.z) * (1.0 - max(ks.r, max(ks.g, ks.b)));
}
