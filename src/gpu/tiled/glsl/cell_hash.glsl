// The hash grid (Mara et al., Listing 3): a record goes to the bucket of its cell, cells of side
// cell >= 2r hashed into `buckets` (a power of two).
uniform float cell;
uniform uint buckets;
uint bucket_of(ivec3 c) {
    return (uint(c.x) * 73856093u ^ uint(c.y) * 19349663u ^ uint(c.z) * 83492791u) & (buckets - 1u);
}
