/* The two sides of a double-sided surface as two single-sided triangles (DESIGN.md "Surfaces have two
 * sides"). A double-sided lamp millimetres under a ceiling, a poster on a wall or a leaf receives
 * different light on each side; one triangle with one chart would mix them (a lamp's chart collecting the
 * light bouncing in the gap above it). With a twin per triangle every later stage keeps the sides apart
 * without knowing about them: surfaces, charts, photons, AIMs and IIMs are per triangle and a
 * single-sided triangle is lit only from its front. Mirror and glass keep one double-sided triangle:
 * they store no light. So does a material whose every use closes a surface (each node's triangles of
 * it meet along every edge, as a box's six faces do): one of its sides is inside a solid, where no light
 * and no eye goes, and a chart for it would only take texels from the sides that are seen. */
#include <stdlib.h>
#include <string.h>

#include "scene.h"

static int may_split(const lm_material *m)
{
    return m->double_sided && !lm_material_is_specular(m->cls);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* A corner's position as sortable bits, with the corner's number in the low bits' place (a separate key). */
typedef struct {
    uint32_t p[3];
    uint32_t corner;
} corner_key;

static int cmp_corner(const void *a, const void *b)
{
    const corner_key *x = a, *y = b;
    int c = memcmp(x->p, y->p, sizeof x->p);
    return c ? c : (x->corner > y->corner) - (x->corner < y->corner);
}

/* Whether triangles tris[0, n) close a surface: every edge, between positions equal bit for bit, used by
 * exactly two of them, once in each direction. -1 when out of memory. */
static int closed(const lm_scene *s, const uint32_t *tris, uint32_t n)
{
    corner_key *ck = malloc(sizeof *ck * 3 * (size_t)n + 1);
    uint32_t *id = malloc(sizeof *id * 3 * (size_t)n + 1);
    uint64_t *edge = malloc(sizeof *edge * 3 * (size_t)n + 1);
    int ok = ck && id && edge;
    for (uint32_t c = 0; ok && c < 3 * n; c++) {
        memcpy(ck[c].p, s->positions + 3 * (size_t)s->tris[3 * (size_t)tris[c / 3] + c % 3], sizeof ck[c].p);
        ck[c].corner = c;
    }
    if (ok) { /* the same id for corners at the same place */
        qsort(ck, 3 * (size_t)n, sizeof *ck, cmp_corner);
        for (uint32_t c = 0, next = 0; c < 3 * n; c++) {
            next += c > 0 && memcmp(ck[c].p, ck[c - 1].p, sizeof ck[c].p) != 0;
            id[ck[c].corner] = next;
        }
        for (uint32_t c = 0; c < 3 * n; c++) { /* undirected edge, and which way this triangle runs along it */
            uint32_t a = id[c], b = id[c - c % 3 + (c % 3 + 1) % 3];
            uint64_t lo = a < b ? a : b, hi = a < b ? b : a;
            edge[c] = (lo << 33) | (hi << 1) | (uint64_t)(a > b);
        }
        qsort(edge, 3 * (size_t)n, sizeof *edge, cmp_u64);
    }
    int result = ok && n > 0;
    for (uint32_t c = 0; ok && result && c < 3 * n; c += 2)
        result = c + 1 < 3 * n && (edge[c] >> 1) == (edge[c + 1] >> 1) && !(edge[c] & 1) && (edge[c + 1] & 1) &&
                 (c + 2 >= 3 * n || (edge[c + 2] >> 1) != (edge[c] >> 1)) &&
                 (edge[c] >> 33) != ((edge[c] >> 1) & 0xFFFFFFFFu);
    free(ck), free(id), free(edge);
    return ok ? result : -1;
}

typedef struct {
    uint32_t node, material, tri;
} group_key;

static int cmp_group(const void *a, const void *b)
{
    const group_key *x = a, *y = b;
    if (x->node != y->node)
        return x->node < y->node ? -1 : 1;
    if (x->material != y->material)
        return x->material < y->material ? -1 : 1;
    return (x->tri > y->tri) - (x->tri < y->tri);
}

/* split[m] for every material: double-sided, not specular, and some node's triangles of it do not close
 * a surface. The candidates sorted by (node, material) make each node's triangles of one material a run:
 * O(T log T) whatever the counts of nodes and materials. 0 when out of memory. */
static int decide(const lm_scene *s, uint8_t *split)
{
    uint32_t n = 0;
    for (uint32_t t = 0; t < s->tri_count; t++)
        n += (uint32_t)may_split(&s->materials[s->tri_material[t]]);
    group_key *g = malloc(sizeof *g * (size_t)(n ? n : 1));
    uint32_t *tris = malloc(sizeof *tris * (size_t)(n ? n : 1));
    int ok = g && tris;
    for (uint32_t t = 0, k = 0; ok && t < s->tri_count; t++)
        if (may_split(&s->materials[s->tri_material[t]]))
            g[k++] = (group_key){s->tri_node[t], (uint32_t)s->tri_material[t], t};
    if (ok)
        qsort(g, n, sizeof *g, cmp_group);
    for (uint32_t a = 0, b; ok && a < n; a = b) {
        for (b = a; b < n && g[b].node == g[a].node && g[b].material == g[a].material; b++)
            tris[b - a] = g[b].tri;
        if (split[g[a].material])
            continue;
        int c = closed(s, tris, b - a);
        ok = c >= 0;
        split[g[a].material] = (uint8_t)(c == 0);
    }
    free(g);
    free(tris);
    return ok;
}

/* Node indices ordered by their first triangle (each node's triangles are contiguous): (first_tri, node)
 * pairs sorted as 64-bit keys. */
static int *nodes_by_first_tri(const lm_scene *s)
{
    size_t n = (size_t)s->node_count;
    int *order = malloc(sizeof *order * (n ? n : 1));
    uint64_t *key = malloc(sizeof *key * (n ? n : 1));
    if (order && key) {
        for (size_t i = 0; i < n; i++)
            key[i] = (uint64_t)s->nodes[i].first_tri << 32 | (uint64_t)i;
        qsort(key, n, sizeof *key, cmp_u64);
        for (size_t i = 0; i < n; i++)
            order[i] = (int)(key[i] & 0xFFFFFFFFu);
    } else {
        free(order);
        order = NULL;
    }
    free(key);
    return order;
}

typedef struct {
    uint32_t *tris, *tri_node, vertices;
    int *tri_material;
    int32_t *twin;
    uint32_t *twin_vertex; /* per file vertex: its back-side copy, UINT32_MAX until made */
    float *positions, *normals, *uv0, *uv1;
    uint32_t *vertex_node;
} grown;

/* The back-side copy of vertex v (made on first use): same place and texture coordinates, normal negated. */
static uint32_t twin_vertex(const lm_scene *s, grown *g, uint32_t v)
{
    if (g->twin_vertex[v] != UINT32_MAX)
        return g->twin_vertex[v];
    uint32_t w = g->vertices++;
    memcpy(g->positions + 3 * (size_t)w, s->positions + 3 * (size_t)v, 3 * sizeof(float));
    for (int k = 0; k < 3; k++)
        g->normals[3 * (size_t)w + k] = -s->normals[3 * (size_t)v + k];
    memcpy(g->uv0 + 2 * (size_t)w, s->uv0 + 2 * (size_t)v, 2 * sizeof(float));
    if (s->uv1)
        memcpy(g->uv1 + 2 * (size_t)w, s->uv1 + 2 * (size_t)v, 2 * sizeof(float));
    g->vertex_node[w] = s->vertex_node[v];
    return g->twin_vertex[v] = w;
}

static void put_tri(const lm_scene *s, grown *g, uint32_t at, uint32_t from, const uint32_t c[3])
{
    memcpy(g->tris + 3 * (size_t)at, c, 3 * sizeof(uint32_t));
    g->tri_material[at] = s->tri_material[from];
    g->tri_node[at] = s->tri_node[from];
    g->twin[at] = -1;
}

/* Node by node: the file's triangles, then the twins of those that split. */
static void fill(lm_scene *s, grown *g, const int *order, const uint8_t *split)
{
    uint32_t at = 0;
    for (int o = 0; o < s->node_count; o++) {
        lm_node *nd = &s->nodes[order[o]];
        uint32_t first = at;
        for (uint32_t t = nd->first_tri; t < nd->first_tri + nd->tri_count; t++)
            put_tri(s, g, at++, t, s->tris + 3 * (size_t)t);
        for (uint32_t t = nd->first_tri, f = first; t < nd->first_tri + nd->tri_count; t++, f++) {
            if (!split[s->tri_material[t]])
                continue;
            const uint32_t *c = s->tris + 3 * (size_t)t;
            uint32_t back[3] = {twin_vertex(s, g, c[0]), twin_vertex(s, g, c[2]), twin_vertex(s, g, c[1])};
            put_tri(s, g, at, t, back);
            g->twin[f] = (int32_t)at, g->twin[at] = (int32_t)f;
            at++;
        }
        nd->front_tri_count = nd->tri_count;
        nd->first_tri = first, nd->tri_count = at - first;
    }
}

static void free_grown(grown *g)
{
    free(g->tris), free(g->tri_node), free(g->tri_material), free(g->twin), free(g->twin_vertex);
    free(g->positions), free(g->normals), free(g->uv0), free(g->uv1), free(g->vertex_node);
}

static lm_status add_twins(lm_scene *s, const uint8_t *split, uint32_t twins, lm_error *err)
{
    size_t nt = (size_t)s->tri_count + twins, nv = (size_t)s->vertex_count + 3 * (size_t)twins;
    grown g = {0};
    g.vertices = s->vertex_count;
    g.tris = malloc(3 * nt * sizeof *g.tris), g.tri_node = malloc(nt * sizeof *g.tri_node);
    g.tri_material = malloc(nt * sizeof *g.tri_material), g.twin = malloc(nt * sizeof *g.twin);
    g.twin_vertex = malloc(s->vertex_count * sizeof *g.twin_vertex + 1);
    g.positions = malloc(3 * nv * sizeof(float)), g.normals = malloc(3 * nv * sizeof(float));
    g.uv0 = malloc(2 * nv * sizeof(float)), g.uv1 = s->uv1 ? malloc(2 * nv * sizeof(float)) : NULL;
    g.vertex_node = malloc(nv * sizeof *g.vertex_node);
    int *order = nodes_by_first_tri(s);
    if (!g.tris || !g.tri_node || !g.tri_material || !g.twin || !g.twin_vertex || !g.positions || !g.normals ||
        !g.uv0 || (s->uv1 && !g.uv1) || !g.vertex_node || !order || !s->normals) {
        free_grown(&g);
        free(order);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the back sides of %u double-sided triangles", s->path,
                       twins);
    }
    memset(g.twin_vertex, 0xFF, s->vertex_count * sizeof *g.twin_vertex);
    memcpy(g.positions, s->positions, 3 * (size_t)s->vertex_count * sizeof(float));
    memcpy(g.normals, s->normals, 3 * (size_t)s->vertex_count * sizeof(float));
    memcpy(g.uv0, s->uv0, 2 * (size_t)s->vertex_count * sizeof(float));
    if (s->uv1)
        memcpy(g.uv1, s->uv1, 2 * (size_t)s->vertex_count * sizeof(float));
    memcpy(g.vertex_node, s->vertex_node, (size_t)s->vertex_count * sizeof *g.vertex_node);
    fill(s, &g, order, split);
    free(order);
    free(s->tris), free(s->tri_node), free(s->tri_material), free(s->tri_twin);
    free(s->positions), free(s->normals), free(s->uv0), free(s->uv1), free(s->vertex_node);
    s->tris = g.tris, s->tri_node = g.tri_node, s->tri_material = g.tri_material, s->tri_twin = g.twin;
    s->positions = g.positions, s->normals = g.normals, s->uv0 = g.uv0, s->uv1 = g.uv1;
    s->vertex_node = g.vertex_node;
    s->tri_count = (uint32_t)nt, s->vertex_count = g.vertices;
    free(g.twin_vertex);
    return LM_OK;
}

lm_status lm_scene_split_sides(lm_scene *s, lm_error *err)
{
    s->file_tri_count = s->tri_count;
    for (int i = 0; i < s->node_count; i++)
        s->nodes[i].front_tri_count = s->nodes[i].tri_count;
    uint8_t *split = calloc((size_t)s->material_count + 1, 1);
    if (!split || !decide(s, split)) {
        free(split);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory to find the double-sided surfaces", s->path);
    }
    uint32_t twins = 0;
    for (uint32_t t = 0; t < s->tri_count; t++)
        twins += split[s->tri_material[t]];
    lm_status st = twins ? add_twins(s, split, twins, err) : LM_OK;
    for (int i = 0; st == LM_OK && i < s->material_count; i++)
        if (split[i])
            s->materials[i].double_sided = 0, s->materials[i].split_sides = 1;
    free(split);
    return st;
}
