#version 450 core
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 col;
uniform mat4 view_proj;
flat out vec3 v_col;
void main() { v_col = col; gl_Position = view_proj * vec4(pos, 1.0); }
