// One step of filling the premultiplied atlas's holes (gpu/frame/composite.h): a texel that takes indirect
// light but is invalid (w = 0: covered, or seeing back faces) takes the mean colour of its 4-neighbours
// of the same surface that have one, at a weight far under a valid texel's. Where a pixel's bilinear
// footprint holds a valid texel, that texel decides; where it holds none (a floor under a ball hovering
// less than a texel over it), the pixel shows its surface's light around the hole instead of black.
#version 450 core
uniform sampler2D src;     // (E / pi w, w)
uniform sampler2D covered; // r: takes indirect light; g: its surface + 1
out vec4 frag;
const float FILL_WEIGHT = 1.0 / 1024.0;
void main() {
    ivec2 q = ivec2(gl_FragCoord.xy), size = textureSize(src, 0);
    vec4 v = texelFetch(src, q, 0), c = texelFetch(covered, q, 0);
    if (v.a > 0.0 || c.r == 0.0) {
        frag = v;
        return;
    }
    const ivec2 beside[4] = ivec2[4](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1));
    vec4 sum = vec4(0.0);
    for (int k = 0; k < 4; k++) {
        ivec2 n = q + beside[k];
        if (any(lessThan(n, ivec2(0))) || any(greaterThanEqual(n, size)) || texelFetch(covered, n, 0).g != c.g)
            continue;
        vec4 s = texelFetch(src, n, 0);
        if (s.a > 0.0)
            sum += vec4(s.rgb / s.a, 1.0);
    }
    frag = sum.a > 0.0 ? vec4(sum.rgb / sum.a, 1.0) * FILL_WEIGHT : v;
}
