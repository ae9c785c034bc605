/* Surfaces, lightmap charts, the atlas and its texel table.
 *
 * A surface is a connected set of triangles of one node and one material whose normals stay within a
 * cone: the unit that owns a photon map, an approximated illumination map (AIM) and an indirect
 * illumination map (IIM). Specular triangles (mirror, glass) store no photons and get no surface
 * (tri_surface = -1) and no lightmap texels.
 *
 * Each surface is unwrapped into one or more charts (planar projection, split where the projection
 * would fold or overlap); charts are packed into one atlas. The texel table lists every
 * covered texel with its world position, normal, surface, triangle and world-space area.
 *
 * Pages: a level whose charts do not fit one max_size x max_size atlas at its texel size gets several
 * pages of at most that side. Engines see the pages; inside, the pages lie side by side in a grid in the
 * one atlas every pass samples (width x height, at most LM_ATLAS_MAX_SIDE a side), so texel (x, y),
 * corner_uv and every atlas-sized array keep their meaning. No chart straddles a page. A level that fits
 * one page is that page: page_count 1, the page the whole atlas. */
#ifndef LM_CHARTS_H
#define LM_CHARTS_H

#include <stdint.h>

#include "../core/error.h"
#include "../scene/scene.h"

typedef struct {
    float cone_deg;        /* max angle between a triangle's normal and its surface's seed normal (default 30) */
    float min_fragment_area; /* surfaces smaller than this fraction of the node's area are merged (default 1e-3) */
    float min_surface_area; /* and those smaller than this world area (default 0; a texel's area at a budget too
                             * small for one texel per surface, lm_surface_area_for_budget) */
    int strict;            /* non-manifold edges and degenerate triangles are errors */
} lm_surface_options;

typedef struct {
    int node, material;
    uint32_t tri_count;
    uint32_t *tris;        /* triangle ids, ascending */
    float area;            /* world-space area at load time */
    float normal[3];       /* area-weighted mean normal, world space */
} lm_surface;

typedef struct {
    int surface_count;
    lm_surface *surfaces;
    int *tri_surface;      /* per scene triangle; -1 for specular or degenerate triangles */
    uint32_t degenerate_tris;  /* zero-area triangles (no surface) */
    uint32_t nonmanifold_edges; /* edges shared by more than two triangles */
    /* Topology kept for unwrapping (lm_atlas_build): */
    uint32_t *vertex_weld; /* per scene vertex: the vertex it was welded to (itself if none) */
    int32_t *tri_adj;      /* 3 per scene triangle: triangle across edge (corner k, k+1), -1 if none */
} lm_surfaces;

/* Splits the scene into surfaces. Fails (strict) or warns (default) on degenerate triangles and
 * non-manifold edges, naming the node. */
void lm_surface_options_default(lm_surface_options *o);
lm_status lm_surfaces_build(const lm_scene *s, const lm_surface_options *o, lm_surfaces *out, lm_error *err);
void lm_surfaces_free(lm_surfaces *su);
/* The min_surface_area a texel budget needs: 0 when the surfaces (after the fragment merge) are few
 * enough for one texel each, otherwise the area of one texel at the budget's texel size. A surface takes
 * at least one texel, and a level of thousands of small ones (a sphere's 30-degree facets, a chair's
 * bevels) could never meet a small budget. */
float lm_surface_area_for_budget(const lm_surfaces *su, int target_texels);

/* Texels the derived texel size aims at for the whole scene unless told otherwise. */
#define LM_ATLAS_DEFAULT_TEXELS 65536

typedef struct {
    float texel_size;      /* world units per texel; <= 0 derives it from the scene (lm_atlas_default_texel_size) */
    int target_texels;     /* with texel_size <= 0: the texels the derived size aims at (default and 0:
                            * LM_ATLAS_DEFAULT_TEXELS) */
    int gutter;            /* empty texels between two charts (default 0: corner_uv keeps bilinear lookups
                            * inside each chart; more for engines that mipmap the lightmap) */
    int use_file_uv1;      /* take charts from the file's TEXCOORD_1 instead of unwrapping */
    int max_size;          /* largest side of one page (default 8192): charts that do not fit one page fill
                            * several (lm_atlas.page_count); texel_size grows only where a chart is larger
                            * than a page or the pages would pass LM_ATLAS_MAX_SIDE */
    int wall_texels;       /* each surface of at least LM_WALL_AREA gets about this many texels at least: its
                            * charts a finer texel size than the atlas's where needed, those texels on top
                            * of target_texels (default 0: off) */
    float bend_deg;        /* a surface of LM_BEND_MIN_TEXELS texels or more whose shading normals turn more
                            * than this many degrees across one texel gets a finer texel size, so that
                            * they turn this much, where LM_BEND_REFINE times finer is enough (else it
                            * keeps the atlas's); those texels count against target_texels (default 0:
                            * off) */
    const double *need;    /* per surface, what its texels are worth (trace/surface_need.h); NULL: every
                            * surface at the atlas's texel size */
    const double *sky;     /* with need: per surface, the share of its rays that see the sky (the same) */
    float open_need;       /* with need: an open surface (at least LM_OPEN_SKY of its rays see the sky) whose
                            * need per area is under open_need times the level's gets texels in proportion
                            * to its need instead of its area, coarser than the atlas's by up to
                            * LM_OPEN_COARSEN (a town's open ground, a closed room's outside); its texels count
                            * against target_texels, which the rest then share (default 0: off) */
} lm_atlas_options;

/* The open-surface rule's limits (lm_atlas_options.open_need): the share of a surface's rays that must see
 * the sky (a room's inside, which sees none, keeps its texels however little it needs: the animated Cornell
 * box's dynamic cube read 3% further off the reference when coarsened), and how much coarser than the
 * atlas's its texels may be. */
#define LM_OPEN_SKY 0.5
#define LM_OPEN_COARSEN 64.0

/* The bend rule's limits (lm_atlas_options.bend_deg): how much finer than the atlas's a bending
 * surface's texels may be, the fewest texels a surface refined has at the atlas's texel size, and
 * lmgi_options.bend_deg's default. */
#define LM_BEND_REFINE 2.0
#define LM_BEND_MIN_TEXELS 8.0
#define LM_BEND_DEFAULT_DEG 15.0f

/* A wall's or floor's area in world units: 2 m^2 in glTF's metres (a door's area). */
#define LM_WALL_AREA 2.0f

/* The largest side of the atlas holding several pages: OpenGL 4.5's guaranteed GL_MAX_TEXTURE_SIZE, so
 * every pass can sample it as one texture. */
#define LM_ATLAS_MAX_SIDE 16384

typedef struct {
    int surface;
    int x, y, w, h;        /* rectangle in the atlas, texels, gutters excluded */
    int pad;               /* texels of border of its own around it (0 or 1): what its lookups reach beyond
                            * the rect (corner_uv) */
    int page;              /* the page holding it (0 for a level of one page) */
    float texel_size;      /* world units per texel: the atlas's, or finer on a wall (wall_texels) */
    uint32_t tri_count;
    uint32_t *tris;
} lm_chart;

typedef struct {
    float pos[3];          /* world position: centroid of the texel's overlap with its triangle */
    float local[3];        /* the same point in its node's local space (follows a dynamic node) */
    float bary[3];         /* its barycentric weights on the triangle's corners 0, 1, 2 */
    float normal[3];       /* shading normal, world space: the mean of the interpolated shading normals over
                              the texel's overlap with its surface's triangles, weighted by area (a texel across
                              a sphere's facets or a terrain's coarse triangles stands for all of them, not for
                              the one holding pos) */
    float lnormal[3];      /* the same in its node's local space (follows a dynamic node) */
    int x, y;              /* texel coordinates */
    int surface;
    uint32_t tri;
    float area;            /* world-space area of the texel's overlap with its surface */
} lm_texel;

typedef struct {
    int width, height;
    float texel_size;
    int gutter;
    int chart_count;
    lm_chart *charts;
    float *corner_uv;      /* lightmap UV per triangle corner, 6 floats per scene triangle, in [0,1], for
                              sampling: a bilinear lookup inside a triangle reads only its chart's rect and
                              border (the chart's extent lies between its rect's first and last texel
                              centres, or reaches at most half a texel into its border), so charts need no
                              gutter; NaN for triangles with no surface */
    float *coverage_uv;    /* the corners as the texel table was made (texel (x, y) is the square
                              [x, x+1]/width): which texel a point of a triangle lies in; corner_uv but for
                              charts of one texel (all of whose corners are that texel's centre) */
    int *chart_owner;      /* width*height: the chart whose rect or border holds the texel, -1 in gutters
                              and free space */
    int *tri_chart;        /* chart per triangle, -1 if none */
    uint32_t texel_count;
    lm_texel *texels;
    int *texel_index;      /* width*height: index into texels, -1 where uncovered */
    uint32_t *footprint_first; /* texel_count + 1: texel i is gathered at footprints[footprint_first[i] ..
                              footprint_first[i + 1]) when that is not empty (lm_texel_footprint) */
    lm_texel *footprints;  /* points spread over what a texel stands for, where its shading normals spread
                              past LM_FOOTPRINT_SPREAD and its chart is one texel (a sphere's facet at a
                              level's density) or has triangles that turn (LM_FOOTPRINT_TURNING: a terrain's
                              slope): each a texel of its own (its triangle, barycentrics, the shading normal
                              interpolated there, the area of its part), x, y and surface the texel's */
    uint32_t footprint_count;
    float utilization;     /* covered texels / (width*height) */
    int page_width, page_height; /* one page's size (the atlas's own for one page) */
    int page_count, page_columns; /* pages; page p lies at column p % page_columns, row p / page_columns */
    float page_utilization; /* covered texels / the pages' texels (the grid's empty places not counted) */
    int surface_count;
    int *surface_first_chart, *surface_chart_count; /* per surface: its charts (charts are ordered by surface) */
    float *surface_texel_size; /* per surface: its charts' texel_size (the atlas's where it has none): how far
                                * "within a texel" reaches there (the covered-texel rule, docs/gather.md) */
    int bent_surfaces;     /* surfaces given finer texels for their bending normals (lm_atlas_options.bend_deg) */
    int open_surfaces;     /* surfaces given coarser texels for what they see (lm_atlas_options.open_need) */
    double time_unwrap, time_pack, time_texels; /* seconds spent in each stage of lm_atlas_build */
} lm_atlas;

/* A texel whose chart is one texel stands for a whole piece, and where the piece's shading normals spread
 * so that their area-weighted mean is shorter than this (about 10 degrees off on average), its light
 * changes across it faster than linearly (a sphere's facet beside the next sphere): it is gathered at
 * LM_FOOTPRINT_POINTS points over the piece and their light averaged (docs/charts.md, "Footprints"). So is
 * a texel of a chart of several whose triangles turn (the mean of their unit geometric normals, by area,
 * shorter than LM_FOOTPRINT_TURNING) where its own shading normals spread as much: at its four quarters
 * (a terrain's coarse texel across a hollow; not a flat wall whose corners carry averaged normals). */
#define LM_FOOTPRINT_SPREAD 0.985
#define LM_FOOTPRINT_TURNING 0.999
#define LM_FOOTPRINT_POINTS 4

/* How a footprint texel's light turns with the normal (docs/charts.md, "Turning with the normal"): one
 * value for a curved piece is its mean, but a pixel on the piece's dark side wants less and one on its
 * bright side more. Per channel c, the least-squares plane through the m points' light e[k][c] over their
 * unit normals n[k], E(n) = mean_c (1 + r_c . n - r_c . nbar), nbar the normals' mean (ridge 1% of their
 * spread, so that a direction they hardly spread in, the radial one, stays near 0). out: LM_TURN_FLOATS floats,
 * per channel r_c (3) then r_c . nbar, all 0 where m < 2, the normals do not spread (under 1e-6) or the
 * channel's mean is 0. Relative, so a light's edit that scales a texel's light leaves it true. O(m). */
#define LM_TURN_FLOATS 12
void lm_footprint_turn(int m, const float n[][3], const float e[][3], float out[LM_TURN_FLOATS]);

/* Texel i's footprint points (lm_atlas.footprints): how many, 0 for a texel gathered at its own point (and
 * for every texel of an atlas made by hand, without footprint_first). */
static inline uint32_t lm_texel_footprint(const lm_atlas *a, uint32_t i, const lm_texel **points)
{
    if (!a->footprint_first) {
        *points = NULL;
        return 0;
    }
    *points = a->footprints + a->footprint_first[i];
    return a->footprint_first[i + 1] - a->footprint_first[i];
}

/* Whether texel i turns with the normal (lm_footprint_turn): a footprint texel whose chart is that texel
 * alone, every corner at its centre, so that a pixel's lookup reads it and nothing else (a chart of several
 * would read its turns texel by texel, in steps). */
static inline int lm_texel_turns(const lm_atlas *a, uint32_t i)
{
    const lm_texel *pts, *tx = &a->texels[i];
    if (lm_texel_footprint(a, i, &pts) == 0)
        return 0;
    const lm_chart *ch = &a->charts[a->chart_owner[(size_t)tx->y * a->width + tx->x]];
    return ch->w == 1 && ch->h == 1;
}

void lm_atlas_options_default(lm_atlas_options *o);
/* sqrt(total surface area / target): about `target` texels for the whole scene (fewer where charts round
 * down, a few more at their edges). */
float lm_atlas_default_texel_size(const lm_scene *s, const lm_surfaces *su, int target);
lm_status lm_atlas_build(const lm_scene *s, const lm_surfaces *su, const lm_atlas_options *o,
                         lm_atlas *out, lm_error *err);
void lm_atlas_free(lm_atlas *a);
/* Texel t's overlap with its own triangle cut by a k x k grid of the texel (k >= 1): for each of the k^2
 * squares that overlaps the triangle, the centroid of that overlap in the node's local space (local[i])
 * and its share of the texel's overlap area (share[i], summing to 1). Returns how many (at most k^2; 0
 * for a degenerate triangle). What a quantity that varies within a texel is averaged over. */
int lm_texel_parts(const lm_scene *s, const lm_atlas *a, const lm_texel *t, int k, float local[][3], float share[]);
/* The diffuse lobe kd (lm_material_lobes) of the texel's material at its point: base colour x texture at
 * the uv its barycentrics give on its triangle. What a lightmap's irradiance is turned into radiance with. */
void lm_texel_kd(const lm_scene *s, const lm_texel *t, float kd[3]);
/* The texel's centre (barycentric on its triangle) and unit shading normal (lnormal) under the current
 * node matrices. */
void lm_texel_world(const lm_scene *s, const lm_texel *t, float pos[3], float nrm[3]);
/* The same centre with the shading normal interpolated there, on the one triangle that holds it (the mean
 * where that vanishes). What the cover test looks along (lm_texel_covered): a texel on a sphere's facet
 * beside another sphere is covered only if its own point faces into it; the mean over facets turned towards
 * the neighbour found it covered where it is not (black speckles where room_lit's spheres touch). */
void lm_texel_centre_normal(const lm_scene *s, const lm_texel *t, float pos[3], float nrm[3]);
/* The UV rectangle (lo u, lo v, hi u, hi v) inside which bilinear lookups at chart c's corner_uv read only
 * its own texels: its texel centres' span, or half a texel into its border (lm_chart.pad). What a
 * footprint spread around such a lookup is clamped to, charts touching. */
void lm_chart_lookup_rect(const lm_atlas *a, int c, float rect[4]);

/* Pages (src/charts/page_map.c). The atlas rectangle {x, y, w, h} of page p (0 <= p < page_count). */
void lm_atlas_page_rect(const lm_atlas *a, int p, int rect[4]);
/* The page holding atlas texel (x, y), inside the atlas, and its place in that page (*px, *py; either may
 * be NULL). A texel of the grid's empty places after the last page gives page_count or more. */
int lm_atlas_page_of(const lm_atlas *a, int x, int y, int *px, int *py);
/* An atlas UV (corner_uv's, [0,1] over the atlas) of a point on page p as a UV over that page alone
 * ([0,1] over the page). Computed in double: for one page, uv itself, bit for bit. */
void lm_atlas_page_uv(const lm_atlas *a, int p, const float uv[2], float out[2]);
/* The page of triangle t's texels; -1 for a triangle without (mirror, glass, degenerate). */
int lm_atlas_tri_page(const lm_atlas *a, uint32_t t);

#endif
