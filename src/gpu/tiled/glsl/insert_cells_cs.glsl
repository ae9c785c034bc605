#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
#include "insert_common.glsl"
#include "cell_hash.glsl"
void main() {
    uint i = base + gl_GlobalInvocationID.x;
    if (i >= n_records || rec[5u * i + 3u] == 0u) return;
    vec3 p = uintBitsToFloat(uvec3(rec[5u * i], rec[5u * i + 1u], rec[5u * i + 2u]));
    insert(bucket_of(ivec3(floor(p / cell))), i);
}
