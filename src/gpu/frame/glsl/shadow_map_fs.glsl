// ortho: depth along dir from origin; else distance to origin. The depth test keeps the smallest
// metric exactly (it is the depth), whatever the projection's depth precision; there is no colour.
#version 450 core
in vec3 v_pos;
uniform vec3 origin, dir;
uniform int ortho;
uniform float range;
void main() {
    vec3 d = v_pos - origin;
    float m = ortho != 0 ? dot(d, dir) : length(d);
    gl_FragDepth = clamp(m / range, 0.0, 1.0);
}
