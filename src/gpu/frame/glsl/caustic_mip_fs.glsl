// One mip level of a splat texture from the level below it, over the rectangles the caustic filter reads
// (caustic_pass.c, mip_region): each texel the mean of its 2 x 2 texels there. The source level is the
// texture's base level while this runs, so the level written is not one sampled.
#version 450 core
uniform sampler2D src;
layout(location = 0) out vec4 frag;
void main() {
    ivec2 p = 2 * ivec2(gl_FragCoord.xy), last = textureSize(src, 0) - 1;
    frag = 0.25 * (texelFetch(src, min(p, last), 0) + texelFetch(src, min(p + ivec2(1, 0), last), 0) +
                   texelFetch(src, min(p + ivec2(0, 1), last), 0) + texelFetch(src, min(p + ivec2(1, 1), last), 0));
}
