// offsets[s] = counts[0] + ... + counts[s - 1] for s in [0, n], one work group of 1024: each invocation
// sums a run of ceil(n / 1024) counts, invocation 0 scans those 1024 sums, each writes its run.
#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
layout(local_size_x = 1024) in;
layout(std430, binding = 2) readonly buffer Counts { uint counts[]; };
layout(std430, binding = 3) writeonly buffer Offsets { uint offsets[]; };
uniform uint n;
shared uint part[1024];
void main() {
    uint i = gl_LocalInvocationIndex, run = (n + 1023u) / 1024u, a = min(n, i * run), b = min(n, a + run);
    uint s = 0u;
    for (uint k = a; k < b; k++) s += counts[k];
    part[i] = s;
    barrier();
    if (i == 0u) {
        uint sum = 0u;
        for (uint k = 0u; k < 1024u; k++) { uint c = part[k]; part[k] = sum; sum += c; }
        offsets[n] = sum;
    }
    barrier();
    s = part[i];
    for (uint k = a; k < b; k++) { offsets[k] = s; s += counts[k]; }
}
