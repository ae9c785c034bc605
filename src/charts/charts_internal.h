/* Helpers shared by the files of src/charts; not part of the module's interface. */
#ifndef LM_CHARTS_INTERNAL_H
#define LM_CHARTS_INTERNAL_H

#include <stdint.h>

#include "../core/error.h"
#include "../scene/scene.h"
#include "charts.h"

/* Checks that triangle, vertex, node and material indices are in range and arrays present. */
lm_status lmc_check_scene(const lm_scene *s, lm_error *err);

/* World-space positions of all vertices (3 floats each) under the current node matrices, and the
 * diagonal of their bounds (the scene size used for tolerances). NULL when memory ran out. */
float *lmc_world_positions(const lm_scene *s, float *size);
/* World-space unit shading normals of all vertices (3 floats each). */
float *lmc_world_normals(const lm_scene *s);

/* Welds vertices of the same node closer than tol: returns, per vertex, its representative (the
 * lowest-numbered vertex of its cluster, itself if alone). NULL when memory ran out. */
uint32_t *lmc_weld(const lm_scene *s, const float *pos, float tol);

/* Relative tolerances, as fractions of the scene size. */
#define LMC_WELD_TOL 1e-6f
#define LMC_DEGENERATE_AREA 1e-12 /* times size^2 */

/* A chart while it is being built: triangles (ascending), extent of its oriented projection in world
 * units, and per-triangle corner coordinates (6 doubles per scene triangle, chart-local, >= 0). */
typedef struct {
    int surface;
    uint32_t tri_count;
    uint32_t *tris;
    double ext[2];
    double texel_scale; /* its texel size over the atlas's, set where charts are laid out (atlas.c): 1, or
                         * less where a wall-sized surface would get too few texels or a surface's normals
                         * bend (lm_atlas_options.bend_deg) */
    int on_top;         /* its texels come on top of the texel budget (a wall's, lm_atlas_options.wall_texels) */
} lmc_chart;

/* A chart's extent along axis (0, 1) in its own texels at the atlas's texel size ts. */
static inline double lmc_chart_texels(const lmc_chart *c, int axis, float ts)
{
    return c->ext[axis] / ((double)ts * c->texel_scale);
}

typedef struct {
    int count;
    lmc_chart *charts;  /* ordered by surface, then by first triangle */
    double *tri_uv;     /* 6 per scene triangle; world units (unwrap) or uv1 units scaled (uv1) */
} lmc_charts;

/* Planar-projection charts of every surface, split where the projection folds or overlaps. */
lm_status lmc_unwrap(const lm_scene *s, const lm_surfaces *su, const float *pos, lmc_charts *out,
                     lm_error *err);
/* One chart per surface from the file's TEXCOORD_1, scaled to world units. */
lm_status lmc_charts_from_uv1(const lm_scene *s, const lm_surfaces *su, const float *pos, lmc_charts *out,
                              lm_error *err);
void lmc_charts_free(lmc_charts *c);

/* Packs the charts at texel_size into out->width/height and out->charts (rects): into one atlas of at
 * most max_size a side where they fit one, else onto pages of that side (lmc_pack_pages); grows the
 * texel size (with a warning) only where a chart is larger than a page or the pages would pass
 * LM_ATLAS_MAX_SIDE. Sets out->texel_size and the page geometry. */
lm_status lmc_pack(const lmc_charts *c, const lm_surfaces *su, float texel_size, int gutter, int max_size,
                   lm_atlas *out, lm_error *err);

/* A chart's rect with its border (lm_chart.pad) as the packers place it, and the chart's index. */
typedef struct {
    int w, h, id;
} lmc_rect;

/* Shelf-packs the rects k (c->count of them, tallest first) onto pages of side x side with gutter empty
 * texels around each, every rect at most side - 2 gutter a side: a node's charts on one page where they
 * fit one, a larger node split by surface, a surface larger than a page by chart; units of charts placed
 * first fit, tallest first, on the first page they fit. The pages go into a grid in out (rects, page of
 * each chart, width, height, page geometry). *grow: 0 when the grid fits LM_ATLAS_MAX_SIDE a side, else
 * the factor (> 1) by which the texel size must at least grow, out left unset. */
lm_status lmc_pack_pages(const lmc_charts *c, const lm_surfaces *su, const lmc_rect *k, int side, int gutter,
                         lm_atlas *out, double *grow, lm_error *err);

/* Charts at least this many texels wide keep a border of their own rather than get a texel more
 * (lmc_pack). The texel more puts a chart's edge texels nearer its edge, where the AIM's estimate is
 * darkened (its disc half off the surface): a wall that sees a box of 6-texel faces read 3.3% under the
 * reference against 2.7% (tests/test_gather.c, shared Cornell box at 40 units a texel). The border costs
 * atlas: many_rooms is 54% used at 200,000 texels with 4 here, 67% with 5, 71% with 8. Stretching charts
 * onto their texel centres instead moved the light by up to half a texel (a box face -5.6%). */
#define LMC_PAD_MIN 5

/* Texel offset of a chart's projection inside its rect (centres the extent in the rect). */
void lmc_chart_offset(const lmc_chart *c, const lm_chart *r, float texel_size, double off[2]);

/* Fills corner_uv, tri_chart, the texel table, texel_index and utilization. */
lm_status lmc_texels(const lm_scene *s, const lmc_charts *c, const float *pos, lm_atlas *a, lm_error *err);

/* A point on a triangle: its barycentric weights on the corners 0, 1, 2, and the area it stands for. */
typedef struct {
    uint32_t tri;
    float w[3];
    float area;
} lmc_point;

/* Where a texel that stands for a whole curved piece is gathered (lm_atlas.footprints): triangles
 * tris[0..n) (world positions pos) cut into up to 4 parts of about equal area, at the area median of
 * their centroids along the widest axis and each half again, and each part's point the one of its
 * triangles nearest its area-weighted centroid. Returns how many points (0 for fewer than two triangles
 * of positive area; -1 out of memory). Deterministic (ties by triangle index). Cost O(n log n). */
int lmc_footprint(const lm_scene *s, const float *pos, const uint32_t *tris, uint32_t n, lmc_point out[LM_FOOTPRINT_POINTS]);

/* Area and unnormalized normal (cross product) of triangle t from world positions, in double. */
double lmc_tri_area(const lm_scene *s, const float *pos, uint32_t t, double n[3]);

#endif
