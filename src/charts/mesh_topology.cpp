// The one C++ file of src/charts: triangle adjacency from OpenMesh's half-edge mesh.
#include "mesh_topology.h"

// OpenMesh 9's default-constructed points trip GCC 12's -Wmaybe-uninitialized inside its own headers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>
#pragma GCC diagnostic pop

#include <new>
#include <vector>

namespace {

typedef OpenMesh::TriMesh_ArrayKernelT<> Mesh;

// add_face refuses a face whose winding disagrees with an existing neighbour; such meshes are common
// in scene files, so the reversed winding is tried before the face counts as refused.
Mesh::FaceHandle add_tri(Mesh &m, const std::vector<Mesh::VertexHandle> &vh, const uint32_t *c)
{
    Mesh::FaceHandle f = m.add_face(vh[c[0]], vh[c[1]], vh[c[2]]);
    if (!f.is_valid())
        f = m.add_face(vh[c[0]], vh[c[2]], vh[c[1]]);
    return f;
}

Mesh::EdgeHandle find_edge(const Mesh &m, Mesh::VertexHandle a, Mesh::VertexHandle b)
{
    Mesh::HalfedgeHandle h = m.find_halfedge(a, b);
    if (!h.is_valid())
        h = m.find_halfedge(b, a);
    return h.is_valid() ? m.edge_handle(h) : Mesh::EdgeHandle();
}

// A refused face whose edge already has two faces makes that edge non-manifold.
void mark_nonmanifold(const Mesh &m, const std::vector<Mesh::VertexHandle> &vh, const uint32_t *c,
                      uint32_t t, std::vector<char> &nm_edge, uint32_t *nm_tri, lm_topology_stats *st)
{
    for (int k = 0; k < 3; k++) {
        Mesh::EdgeHandle e = find_edge(m, vh[c[k]], vh[c[(k + 1) % 3]]);
        if (!e.is_valid() || m.is_boundary(e) || nm_edge[e.idx()])
            continue;
        nm_edge[e.idx()] = 1;
        if (nm_tri)
            nm_tri[st->nonmanifold_edges] = t;
        st->nonmanifold_edges++;
    }
}

int corner_of(const uint32_t *c, uint32_t a, uint32_t b)
{
    for (int k = 0; k < 3; k++) {
        uint32_t p = c[k], q = c[(k + 1) % 3];
        if ((p == a && q == b) || (p == b && q == a))
            return k;
    }
    return -1;
}

void fill_adjacency(const Mesh &m, const std::vector<int32_t> &face_tri, const std::vector<char> &nm_edge,
                    const uint32_t *tri_vertex, int32_t *adj)
{
    for (Mesh::FaceHandle f : m.faces()) {
        int32_t t = face_tri[f.idx()];
        const uint32_t *c = tri_vertex + 3 * (size_t)t;
        for (Mesh::HalfedgeHandle h : m.fh_range(f)) {
            int k = corner_of(c, (uint32_t)m.from_vertex_handle(h).idx(), (uint32_t)m.to_vertex_handle(h).idx());
            Mesh::FaceHandle g = m.opposite_face_handle(h);
            if (k >= 0 && g.is_valid() && !nm_edge[m.edge_handle(h).idx()])
                adj[3 * (size_t)t + k] = face_tri[g.idx()];
        }
    }
}

void build(uint32_t vertex_count, uint32_t tri_count, const uint32_t *tri_vertex, const unsigned char *use,
           int32_t *adj, uint32_t *nm_tri, lm_topology_stats *st)
{
    Mesh m;
    std::vector<Mesh::VertexHandle> vh(vertex_count);
    for (uint32_t v = 0; v < vertex_count; v++)
        vh[v] = m.add_vertex(Mesh::Point(0.0f, 0.0f, 0.0f));
    std::vector<int32_t> face_tri;
    std::vector<uint32_t> refused;
    face_tri.reserve(tri_count);
    for (uint32_t t = 0; t < tri_count; t++) {
        if (use && !use[t])
            continue;
        if (add_tri(m, vh, tri_vertex + 3 * (size_t)t).is_valid())
            face_tri.push_back((int32_t)t);
        else
            refused.push_back(t);
    }
    std::vector<char> nm_edge(m.n_edges(), 0);
    st->refused_faces = (uint32_t)refused.size();
    for (uint32_t t : refused)
        mark_nonmanifold(m, vh, tri_vertex + 3 * (size_t)t, t, nm_edge, nm_tri, st);
    fill_adjacency(m, face_tri, nm_edge, tri_vertex, adj);
}

} // namespace

extern "C" int lm_mesh_topology(uint32_t vertex_count, uint32_t tri_count, const uint32_t *tri_vertex,
                                const unsigned char *use, int32_t *adj, uint32_t *nm_tri,
                                lm_topology_stats *stats)
{
    stats->nonmanifold_edges = 0;
    stats->refused_faces = 0;
    for (size_t i = 0; i < 3 * (size_t)tri_count; i++)
        adj[i] = -1;
    // OpenMesh reports every refused face on its error stream; lmgi counts and reports them itself.
    bool was_enabled = omerr().is_enabled();
    omerr().disable();
    int rc = 0;
    try {
        build(vertex_count, tri_count, tri_vertex, use, adj, nm_tri, stats);
    } catch (const std::bad_alloc &) {
        rc = -1;
    }
    if (was_enabled)
        omerr().enable();
    return rc;
}
