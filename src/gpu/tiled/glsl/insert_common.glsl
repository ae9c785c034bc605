// What the count and fill passes share: the per-segment counters and offsets, the list, and the total
// with its limit (LIMIT entries; passing it sets `overflow`, which stops the count early, and the caller
// refuses the frame). fill 0 counts a record into its segments, fill 1 writes it at its segment's offset
// plus a counter's old value (the counters zeroed between the two). insert() is false once counting has
// overflowed. `longest`: the most entries of one segment, which sizes the gathers' windows.
layout(local_size_x = 64) in;
layout(std430, binding = 2) buffer Counts { uint counts[]; };
layout(std430, binding = 3) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = 4) writeonly buffer List { uint list[]; };
layout(std430, binding = 5) coherent buffer Totals { uint total, overflow, longest; };
uniform uint base, n_records;
uniform int fill;
bool insert(uint seg, uint i) {
    if (fill != 0) {
        list[offsets[seg] + atomicAdd(counts[seg], 1u)] = i;
        return true;
    }
    if (overflow != 0u) return false;
    atomicMax(longest, atomicAdd(counts[seg], 1u) + 1u);
    if (atomicAdd(total, 1u) >= uint(LIMIT)) overflow = 1u;
    return true;
}
// The record this invocation inserts (base + its index) and its position; false past the records and
// for an empty slot.
bool record_to_insert(out uint i, out vec3 p) {
    i = base + gl_GlobalInvocationID.x;
    if (i >= n_records || rec[5u * i + 3u] == 0u) return false;
    p = record_pos(i);
    return true;
}
