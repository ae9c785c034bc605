// Per frame, per atlas texel: E / pi premultiplied by w = covered x valid (back-face fraction
// <= limit), and w; sampled with the texture unit's bilinear filter, rgb / a is then the bilinear filter
// over the four nearest texels that weighs only covered, valid ones, renormalised.
#version 450 core
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));
    gl_Position = vec4(p, 0.0, 1.0);
}
