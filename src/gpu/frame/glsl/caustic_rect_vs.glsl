// A pixel rectangle [rect.xy, rect.zw) as a quad: 4 vertices of a triangle strip, no attributes.
#version 450 core
uniform vec4 rect;
uniform vec2 size;
void main() {
    vec2 c = vec2(gl_VertexID & 1, gl_VertexID >> 1);
    gl_Position = vec4(mix(rect.xy, rect.zw, c) / size * 2.0 - 1.0, 0.0, 1.0);
}
