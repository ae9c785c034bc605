#include "../../frame/glsl/gbuffer_normal.glsl"
#include "photon_common.glsl"
#include "insert_common.glsl"
#include "cell_hash.glsl"
void main() {
    uint i;
    vec3 p;
    if (!record_to_insert(i, p)) return;
    insert(bucket_of(ivec3(floor(p / cell))), i);
}
