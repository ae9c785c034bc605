/* A small test level for the edit tests (lights, node motion, material classes), built through the public
 * API: a closed room 4 x 3 x 4 seen from inside (plaster, 0.7 grey) with a block on its floor, optionally
 * a dynamic stool in a corner, lit as the spec says; and the few steps those tests repeat on it. Each
 * helper fails the calling cmocka test on an error. */
#ifndef LMT_EDIT_ROOM_H
#define LMT_EDIT_ROOM_H

#include <lmgi_tools.h>
#include <stddef.h>
#include <stdint.h>

typedef struct {
    const lmgi_light_desc *lights;      /* may be NULL (a level without lights) */
    int light_count;
    const lmgi_material_desc *block;    /* the block's material (NULL: diffuse red 0.8 0.2 0.1) */
    float block_lo[3], block_hi[3];     /* its box (all 0: [-0.4, 0.4] x [0, 1] x [-0.4, 0.4]) */
    int block_dynamic;
    int stool;                          /* 1: a dynamic 0.3 x 0.3 x 0.3 stool at x, z in [1.6, 1.9] x [-1.9, -1.6] */
    float texel_size;                   /* world units per lightmap texel (0: about 1,500 texels) */
} lmt_room_spec;

/* lmgi_load_desc / lmgi_load at about target_texels texels (0: the default), or texels of texel_size world
 * units (0: derived); fails the test on an error. */
lmgi_scene *lmt_load_desc(const lmgi_scene_desc *d, int target_texels, float texel_size);
/* lmgi_load_desc with options o (NULL: the defaults); a failure fails the test. */
lmgi_scene *lmt_load_desc_with(const lmgi_scene_desc *d, const lmgi_options *o);
lmgi_scene *lmt_load(const char *path, int target_texels);
/* lmgi_load at about target_texels texels on lightmap pages of at most `side` texels a side
 * (lmgi_options.max_atlas_size; 0: the default); fails the test on an error. */
lmgi_scene *lmt_load_paged(const char *path, int target_texels, int side);
/* Where each texel lies in the atlas: atlas_width x atlas_height ints (malloc'd), the lmgi_get_texel index of
 * the texel at each position, -1 where there is none (gutters, empty space). */
int *lmt_texel_ids(const lmgi_scene *sc);
/* The project's Cornell box at 6,000 texels on pages of 64 texels: several pages (else the test fails). */
lmgi_scene *lmt_paged_cornell(void);
/* A perspective camera at eye looking at `at` (y up), square, vertical field of view fov radians, near 0.05,
 * far 30. */
void lmt_look_at(const float eye[3], const float at[3], float fov, lmgi_camera *cam);
/* A UV sphere of radius r at c, seg segments around and rings pole to pole (the poles' rings one triangle a
 * segment, no zero-area ones): positions and normals ((seg + 1)(rings + 1) x 3 floats each) and indices
 * (at most 6 seg rings); returns the triangles, *vertices the vertices. */
uint32_t lmt_uv_sphere(float r, const float c[3], int seg, int rings, float *pos, float *nrm, uint32_t *idx,
                       uint32_t *vertices);
/* An axis-aligned box [lo, hi]: 24 vertices (4 a face, so its normals are the faces') into pos (72 floats)
 * and 12 triangles into idx (36), wound to face out of it, or into it with `inward`. */
void lmt_box(const float lo[3], const float hi[3], int inward, float *pos, uint32_t *idx);
/* A context with the default GL backend. */
lmgi_context *lmt_context(void);
/* The room as a scene; its nodes are "room", "block" and "stool". */
lmgi_scene *lmt_room(const lmt_room_spec *spec);
/* The edit tests' updater settings: 100 photons a group, hemicube 16, 16 rim rays, no frame of its own. */
void lmt_room_desc(lmgi_updater_desc *d);
/* An updater with them (lmt_room_desc). */
lmgi_updater *lmt_room_updater(lmgi_context *ctx, lmgi_scene *sc);
/* The same leaving out the effects in effects_off (lmgi_updater_desc). */
lmgi_updater *lmt_room_updater_without(lmgi_context *ctx, lmgi_scene *sc, unsigned effects_off);
/* The displayed IIM (malloc'd, atlas-sized RGBA; *n floats). */
float *lmt_iim(lmgi_updater *u, const lmgi_scene *sc, size_t *n);
void lmt_bake(lmgi_updater *u, lmgi_bake_report *r);
/* n updates at time 0 without a time budget; fails the test on an error. */
void lmt_updates(lmgi_updater *u, int n);
/* One such update, and what it did. */
lmgi_update_stats lmt_update(lmgi_updater *u);
/* The frame (malloc'd, LMT_SIDE x LMT_SIDE x 3) from the room's corner at (1.9, 2, 1.9), looking at
 * (-1, 0.5, -1) with a 90 degree field of view. */
#define LMT_SIDE 48
float *lmt_corner_frame(lmgi_updater *u);
void lmt_corner_camera(lmgi_camera *cam);
/* Relative L1 distance of a from b over n floats. */
double lmt_relative_l1(const float *a, const float *b, size_t n);
/* The largest relative L1 distance of one surface's texels (16 or more valid in both) in an IIM `shown`
 * from want's (lmt_iim's layout): the lag tables' "lightmap's worst surface" (lmgi tradeoff --edits). */
double lmt_worst_surface(const lmgi_scene *sc, const float *shown, const float *want);
/* `updates` updates at time 0 without a budget, the worst surface against want after each: *first after the
 * first, *last after the last. Returns the update (from 1) from which it stays within 5%, -1 if it ends
 * over. */
int lmt_worst_surface_lag(lmgi_updater *u, const lmgi_scene *sc, const float *want, int updates, double *first,
                          double *last);
/* Mean and largest irradiance (R + G + B) over the valid texels of triangles [first, first + count) in an
 * IIM (more than 20 of them, or the test fails). */
void lmt_triangles_stats(const lmgi_scene *sc, const float *iim, uint32_t first, uint32_t count, double *mean,
                         double *top);
/* The mean over node `node` ("room", "block", "stool") in an IIM of a room. */
double lmt_node_mean(const lmgi_scene *sc, const float *iim, const char *node);
/* The id of the light on the node named `name` (every light read must succeed: none removed), and of the
 * material named `name` (the test fails where there is none). */
int lmt_light_on_node(const lmgi_scene *sc, const char *name);
int lmt_material_named(const lmgi_scene *sc, const char *name);
/* An updater with the default settings (a zeroed lmgi_updater_desc). */
lmgi_updater *lmt_updater(lmgi_context *ctx, lmgi_scene *sc);
/* lmgi_export_gltf of the updater's scene as `name` into a fresh folder, loaded back at target_texels. */
lmgi_scene *lmt_export_reload(lmgi_updater *u, const char *name, int target_texels);
/* The mean RGB of the valid texels (alpha > 0) of an atlas-sized RGBA lightmap of n floats; returns how
 * many (the test fails on none). */
int lmt_texel_mean(const float *rgba, size_t n, double mean[3]);
/* The reference's texels for sc (lmgi_reference_texels at target_error, uncached): their mean over the
 * atlas's texels (the gutters are 0); returns how many. */
int lmt_reference_mean(lmgi_scene *sc, float target_error, double mean[3]);
/* The reference's pixels (side x side) of sc from cam at target_error, solved anew (no cache); fails the
 * test on an error. */
void lmt_reference_pixels(lmgi_scene *sc, const lmgi_camera *cam, int side, float target_error, lmgi_reference *ref);
/* Asserts that st is LMGI_ERR_INVALID with a message naming `words`. */
void lmt_expect_invalid(lmgi_status st, const lmgi_error *e, const char *words);

#endif
