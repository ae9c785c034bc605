// With use_lit 2, `lit` holds the photon gathers' kernel coverage instead (lm_direct_set_coverage,
// premultiplied: r / a = 1 / coverage over the valid texels of the footprint), which the first pass writes
// into the kd attachment's alpha (1 without it) for the gathers' resolve.
float inv_coverage() {
    if (use_lit != 2 || v_lm.x < 0.0) return 1.0;
    vec4 t = textureLod(lit, v_lm, 0.0);
    return t.a > 0.0 ? t.r / t.a : 1.0;
}
