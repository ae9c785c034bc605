// pi, as core/vecmath.h's LM_PI_GLSL: written once for every shader that needs it (#include it at the
// top level).
const float PI = 3.14159265358979;
