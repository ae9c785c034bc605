#version 450 core
out vec2 ndc;
out float gl_ClipDistance[1]; // drawn in a mirror's picture too, where clip distance 0 is on: never cut
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    ndc = p;
    gl_Position = vec4(p, 0.0, 1.0);
    gl_ClipDistance[0] = 1.0;
}
