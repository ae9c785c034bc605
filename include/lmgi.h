/* lmgi — dynamic-scene lightmap global illumination (Larsen & Christensen 2004, made into a library).
 *
 * This header is the whole public API. Every function that can fail returns an lmgi_status and, when
 * given an lmgi_error, fills it with a message that names the file or object and the problem.
 * Nothing the caller passes in is modified unless the function says so.
 *
 * NULL: an `err` may always be NULL (the status is still returned), and so may `o` in lmgi_load (the
 * defaults). Any other NULL pointer is refused: a function that returns an lmgi_status returns
 * LMGI_ERR_INVALID naming it; the others do nothing and return their "none" value (0, -1, NULL, an
 * output zeroed, a hit with hit = 0), as each says. No function aborts its host.
 *
 * Coordinates: positions in and out (node matrices, rays, texel positions, bounds) are in the file's
 * world. A scene that lies farther from its origin than 256 times its size is worked on relative to its centre
 * (float keeps 24 bits: at 1e6 units the frame lost most of its light, at 1e7 all of it); the API converts,
 * so the caller never sees the difference. */
#ifndef LMGI_H
#define LMGI_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    LMGI_OK = 0,
    LMGI_ERR_IO,          /* a file is missing, unreadable or unwritable */
    LMGI_ERR_FORMAT,      /* a malformed file */
    LMGI_ERR_INVALID,     /* an invalid argument or value (NaN, out-of-range id, degenerate data in strict mode) */
    LMGI_ERR_UNSUPPORTED, /* a required glTF extension or feature lmgi does not implement */
    LMGI_ERR_NOMEM,
    LMGI_ERR_BACKEND      /* Embree or OpenGL failed */
} lmgi_status;

typedef struct {
    lmgi_status status;
    char message[1024];
} lmgi_error;

/* Settings for turning a scene file into surfaces, a lightmap atlas and a ray-tracing scene. */
typedef struct {
    float texel_size;       /* world units per lightmap texel; 0 = derived from the scene: about target_texels */
    int target_texels;      /* texels the derived texel size aims at (0, the default: 65536).
                             * 'lmgi run' aims at 90 x its texels per frame (docs/gather.md, "Atlas
                             * density") */
    int gutter;             /* minimum empty texels between charts (default 2) */
    int use_file_uv1;       /* 1 = use the file's TEXCOORD_1 as lightmap UVs instead of unwrapping */
    int strict;             /* 1 = degenerate triangles and non-manifold edges are errors, not warnings */
    float surface_cone_deg; /* max normal deviation within one surface, degrees (default 30) */
    int max_atlas_size;     /* largest atlas side; texel size grows to fit (default 8192) */
} lmgi_options;

typedef struct lmgi_scene lmgi_scene;

/* Time spent in each stage of lmgi_load, seconds. atlas = unwrap + pack + texels. */
typedef struct {
    double load, surfaces, unwrap, pack, texels, atlas, bvh, total;
} lmgi_timings;

typedef struct {
    uint32_t triangles, vertices;
    uint32_t back_triangles; /* the second sides of double-sided surfaces (one per triangle, facing the
                              * other way), beside `triangles`, the file's own; docs/materials.md */
    int nodes, dynamic_nodes, meshes, materials, textures, lights, cameras, animations;
    int materials_by_class[5];  /* diffuse, glossy, mirror, glass, emitter */
    int lights_by_type[3];      /* point, spot, directional */
    int surfaces, charts;
    uint32_t degenerate_triangles, nonmanifold_edges;
    int atlas_width, atlas_height;
    uint32_t texels;
    float texel_size, utilization;
    float bounds_min[3], bounds_max[3];
    lmgi_timings timings;
} lmgi_info;

/* One effect of the pipeline, whether this scene calls for it, and why. */
typedef struct {
    const char *name;   /* "direct", "shadows", "indirect", "caustics", "reflections", "photon updates" */
    int on;
    char reason[256];
} lmgi_effect;

typedef struct {
    int hit;
    float t;
    int node;           /* node index */
    int surface;        /* surface id, -1 for specular triangles */
    uint32_t triangle;  /* scene triangle id */
    float normal[3];    /* world-space geometric normal */
} lmgi_hit;

typedef struct {
    float position[3];  /* world position (centroid of the texel's overlap with its triangle) */
    float normal[3];
    int x, y;           /* texel coordinates in the atlas */
    int surface;
    uint32_t triangle;
    float area;         /* world-space area the texel covers */
} lmgi_texel;

/* The defaults (NULL o: nothing). */
void lmgi_options_init(lmgi_options *o);

/* Loads a .gltf/.glb file and builds surfaces, the lightmap atlas, the texel table and the BVHs.
 * NULL path or out: LMGI_ERR_INVALID. A plan larger than the machine's memory (a tiny texel size) is
 * LMGI_ERR_NOMEM before the work, one above 1 GiB a warning with its estimate. */
lmgi_status lmgi_load(const char *path, const lmgi_options *o, lmgi_scene **out, lmgi_error *err);
void lmgi_free(lmgi_scene *scene); /* NULL: nothing */

/* NULL scene: info zeroed; NULL info: nothing. */
void lmgi_get_info(const lmgi_scene *scene, lmgi_info *info);
/* Writes the human-readable summary `lmgi info` prints (NULL scene or f: nothing). */
void lmgi_print_info(const lmgi_scene *scene, FILE *f);
int lmgi_effect_count(const lmgi_scene *scene); /* 0 for NULL */
/* NULL scene or i out of range: out zeroed (name NULL); NULL out: nothing. */
void lmgi_get_effect(const lmgi_scene *scene, int i, lmgi_effect *out);

/* Node lookup and edits. lmgi_set_node_transform moves a dynamic node (world matrix, column-major); a
 * matrix with NaN or infinite entries, a singular one (a zero scale), or one that mirrors where the
 * node's world matrix at load did not (or the other way round: a node's sides are fixed at load), is
 * refused with LMGI_ERR_INVALID and changes nothing. (An animation may scale a node to zero: the node then leaves the
 * rays until its scale returns.) */
int lmgi_node_count(const lmgi_scene *scene);                 /* 0 for NULL */
int lmgi_find_node(const lmgi_scene *scene, const char *name); /* -1 if absent or either is NULL */
const char *lmgi_node_name(const lmgi_scene *scene, int node); /* NULL for NULL or an id out of range */
int lmgi_node_is_dynamic(const lmgi_scene *scene, int node);   /* 0 for NULL or an id out of range */
/* NULL scene or world: LMGI_ERR_INVALID. */
lmgi_status lmgi_set_node_transform(lmgi_scene *scene, int node, const float world[16], lmgi_error *err);
/* Plays every glTF animation to time t (seconds) and moves the animated nodes. NULL scene or a t that
 * is not finite: LMGI_ERR_INVALID. */
lmgi_status lmgi_set_time(lmgi_scene *scene, float t, lmgi_error *err);

/* Closest hit of the ray org + t dir, t in (0, tmax). A ray with a NaN, infinite or huge (above 1.8e18)
 * number, a zero direction or a NaN or negative tmax hits nothing (hit->hit = 0); tmax may be +inf.
 * NULL scene, org or dir: no hit; NULL hit: nothing. */
void lmgi_intersect(const lmgi_scene *scene, const float org[3], const float dir[3], float tmax, lmgi_hit *hit);

uint32_t lmgi_texel_count(const lmgi_scene *scene); /* 0 for NULL */
/* NULL scene or i out of range: out zeroed with surface -1; NULL out: nothing. */
void lmgi_get_texel(const lmgi_scene *scene, uint32_t i, lmgi_texel *out);
/* The lightmap UVs of a triangle's three corners (6 floats in [0,1]); returns 0 if it has none (or
 * scene or uv is NULL). */
int lmgi_triangle_lightmap_uv(const lmgi_scene *scene, uint32_t triangle, float uv[6]);

/* Writes DIR/atlas.png (each chart its own colour, gutters black) and DIR/surfaces.png (the scene from
 * its camera, or an automatic one, each surface in a flat colour) at width x height (0 = 1024x768).
 * NULL scene or dir: LMGI_ERR_INVALID. */
lmgi_status lmgi_write_charts(const lmgi_scene *scene, const char *dir, int width, int height, lmgi_error *err);

const char *lmgi_status_name(lmgi_status s);
/* What lmgi prints on stderr: 0 errors only, 1 also warnings (default), 2 also progress, 3 debug. */
void lmgi_set_verbosity(int level);

#ifdef __cplusplus
}
#endif

#endif
