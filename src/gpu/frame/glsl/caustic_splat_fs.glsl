#version 450 core
in vec3 v_irr, v_flux;
in float v_count;
layout(location = 0) out vec4 irr;
layout(location = 1) out vec4 flux;
// irr's alpha is the receiver mask the mask pass wrote (blended: + 0); flux's counts the photons
void main() { irr = vec4(v_irr, 0.0); flux = vec4(v_flux, v_count); }
