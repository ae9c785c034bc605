#version 450 core
layout(location = 0) in vec3 pos;
layout(location = 1) in vec2 uv;
uniform mat4 view_proj;
out vec2 v_uv;
void main() { v_uv = uv; gl_Position = view_proj * vec4(pos, 1.0); }
