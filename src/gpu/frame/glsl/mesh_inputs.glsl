// What the fragment shaders over direct_vs.glsl's triangles read (direct_fs, emission_fs,
// reflections_fs): the world position and shading normal, the material's flat parameters (base colour,
// emitted radiance; Phong exponent or ior, double-sided, metallic, material class) and the texture and
// lightmap uvs.
in vec3 v_pos, v_ns;
flat in vec3 v_base, v_em;
flat in vec4 v_par;
in vec2 v_uv, v_lm;
