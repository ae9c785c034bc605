#version 450 core
layout(location = 0) in vec3 pos;
uniform mat4 vp;
out vec3 v_pos;
void main() { v_pos = pos; gl_Position = vp * vec4(pos, 1.0); }
