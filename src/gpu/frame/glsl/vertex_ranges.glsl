// Vertex ranges (a node's vertices are contiguous, direct_mesh.h): with keep.y > keep.x only the vertices
// in [keep.x, keep.y) are drawn (one node's reflections), and those in [drop.x, drop.y) never (a node's
// own environment map, drawn from inside it). Every corner of a dropped triangle leaves the clip volume
// on the same side, so it is cut before rasterization. Both 0 (the default): everything.
uniform ivec2 keep, drop;
bool dropped() {
    int v = gl_VertexID;
    return (keep.y > keep.x && (v < keep.x || v >= keep.y)) || (v >= drop.x && v < drop.y);
}
