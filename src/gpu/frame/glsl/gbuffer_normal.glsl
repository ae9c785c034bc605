// Unpacks the G-buffer's a (gbuffer_pack.glsl; frame_targets.h): `bool gbuffer_normal(float a, out vec3
// n)`, false where the pixel has no visible front. For the per-pixel photon gathers (tiled/glsl).
bool gbuffer_normal(float a, out vec3 n) {
    n = vec3(0.0);
    if (a < 1.0) return false;
    float c = a - 1.0, qx = floor(c / 4096.0), qy = c - qx * 4096.0;
    vec2 o = vec2(qx, qy) / 4095.0 * 2.0 - 1.0;
    n = vec3(o, 1.0 - abs(o.x) - abs(o.y));
    if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    n = normalize(n);
    return true;
}
