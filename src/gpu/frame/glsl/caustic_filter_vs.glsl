// The filter's quads come from a vertex buffer of pixel positions (two triangles per grown tile).
#version 450 core
layout(location = 0) in vec2 p;
uniform vec2 size;
void main() { gl_Position = vec4(p / size * 2.0 - 1.0, 0.0, 1.0); }
