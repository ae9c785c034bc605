#version 450 core
flat in vec3 v_col;
out vec4 frag;
void main() { frag = vec4(v_col, 1.0); }
