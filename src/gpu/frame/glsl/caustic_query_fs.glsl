#version 450 core
out vec4 frag;
void main() { frag = vec4(0.0); }
