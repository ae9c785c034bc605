// Whether a pixel whose diffuse lobe is kd shows a caustic: the composite adds kd / pi x E, so mirror,
// glass, metal, the background and back faces (kd 0) show none. The mask pass and the splat share it.
bool shows_caustic(vec3 kd) { return any(greaterThan(kd, vec3(0.0))); }
