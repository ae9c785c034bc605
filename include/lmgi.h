/* lmgi — dynamic-scene lightmap global illumination (Larsen & Christensen 2004, made into a library).
 *
 * This header is the runtime: contexts, scenes and their edits, updaters, lightmaps and their export.
 * The lab beside it (the reference solver, checks against it, pictures, output directories) is
 * lmgi_tools.h, which includes this one. Every function that can fail returns an lmgi_status and, when
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

#include "lmgi_knobs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What liblmgi.so exports: these functions only (it is built with hidden visibility). */
#if defined(__GNUC__) || defined(__clang__)
#define LMGI_API __attribute__((visibility("default")))
#else
#define LMGI_API
#endif

/* The version of this header: a major change breaks sources or binaries built against an earlier one
 * (liblmgi.so.MAJOR), a minor one adds to the API, a patch changes neither. LMGI_VERSION orders as the
 * versions do. lmgi_version() (below) says which version the library itself was built as. */
#define LMGI_VERSION_MAJOR 0
#define LMGI_VERSION_MINOR 1
#define LMGI_VERSION_PATCH 0
#define LMGI_VERSION (LMGI_VERSION_MAJOR * 10000 + LMGI_VERSION_MINOR * 100 + LMGI_VERSION_PATCH)

typedef enum {
    LMGI_OK = 0,
    LMGI_ERR_IO,          /* a file is missing, unreadable or unwritable */
    LMGI_ERR_FORMAT,      /* a malformed file */
    LMGI_ERR_INVALID,     /* an invalid argument or value (NaN, out-of-range id, degenerate data in strict mode) */
    LMGI_ERR_UNSUPPORTED, /* a required glTF extension or feature lmgi does not implement */
    LMGI_ERR_NOMEM,
    LMGI_ERR_BACKEND,     /* Embree or OpenGL failed */
    LMGI_ERR_CANCELLED    /* a cancel flag stopped the work (nothing half done is shown) */
} lmgi_status;

typedef struct {
    lmgi_status status;
    char message[1024];
} lmgi_error;

/* Settings for turning a scene file into surfaces, a lightmap atlas and a ray-tracing scene. 0 means the
 * default in every field: a zeroed lmgi_options is the defaults (lmgi_options_init writes them out). */
typedef struct {
    float texel_size;       /* world units per lightmap texel; 0 = derived from the scene: about target_texels */
    int target_texels;      /* texels the derived texel size aims at (0, the default: 65536).
                             * 'lmgi run' aims at 90 x its texels per frame (docs/gather.md, "Atlas
                             * density") */
    int gutter;             /* empty texels between charts (default 0; more for engines that mipmap lightmaps) */
    int use_file_uv1;       /* 1 = use the file's TEXCOORD_1 as lightmap UVs instead of unwrapping */
    int strict;             /* 1 = degenerate triangles and non-manifold edges are errors, not warnings */
    int untrusted;          /* 1 = a scene from a stranger: every file it names (buffers, images, its sky)
                             * must lie inside its own folder once "..", percent-encoding and symbolic links
                             * are resolved, else the load fails naming it (LMGI_ERR_IO); 0 (the default):
                             * such files are read, each with a warning that it lies outside */
    float surface_cone_deg; /* max normal deviation within one surface, degrees (0: 30) */
    int max_atlas_size;     /* the largest side of one lightmap page, 64 to 32768 (0: 8192): a level
                             * whose charts do not fit one page gets several (lmgi_info.pages; docs/levels.md,
                             * "Pages"); the texel size grows only where one chart is larger than a page or
                             * the pages would pass 16384 x 16384 together */
    int wall_texels;        /* with a derived texel size: each surface of at least 2 m^2 (a wall, a floor)
                             * gets at least about this many texels, at a finer texel size than the rest
                             * where needed, on top of target_texels; 0, the default: one texel size for
                             * all ('lmgi run': 16; docs/levels.md, "Density") */
    float bend_deg;         /* with a derived texel size: a surface of 8 texels or more whose shading normals
                             * turn more than this many degrees across one of its texels (a column's smooth
                             * faces) gets finer texels, so that they turn at most this much, where 2 x finer
                             * is enough (else it keeps the atlas's); they count against target_texels. 0:
                             * the default, 15; LMGI_OFF: one texel size for all (docs/charts.md, "Bending
                             * normals") */
    float open_need;        /* with a derived texel size: a surface whose texels are worth less than this
                             * fraction of the level's, per area, by what its points see (its need, the
                             * integral of 1/R^2 over it, R the harmonic mean distance its rays hit, misses
                             * infinitely far: a town's open ground) gets texels in proportion to that
                             * worth, up to 64 x coarser, and the rest of target_texels goes to the others
                             * (a fraction in (0, 1]). 0, the default, and LMGI_OFF: texels in proportion to
                             * area ('lmgi run' and 'lmgi check': 0.25; docs/charts.md, "Open surfaces") */
} lmgi_options;

typedef struct lmgi_scene lmgi_scene;
typedef struct lmgi_output lmgi_output; /* an output directory being written (lmgi_output_open, lmgi_tools.h) */

/* Time spent in each stage of lmgi_load, seconds. atlas = unwrap + pack + texels. */
typedef struct {
    double load, surfaces, unwrap, pack, texels, atlas, bvh, total;
} lmgi_timings;

typedef struct {
    uint32_t triangles, vertices;
    uint32_t back_triangles; /* the second sides of double-sided surfaces (one per triangle, facing the
                              * other way), beside `triangles`, the file's own; docs/materials.md */
    int nodes, dynamic_nodes, meshes, materials, textures, lights, cameras, animations;
    float animation_seconds;    /* the longest animation's last key time (0: none) */
    int materials_by_class[5];  /* diffuse, glossy, mirror, glass, emitter */
    int lights_by_type[3];      /* point, spot, directional */
    int surfaces, charts;
    uint32_t degenerate_triangles, nonmanifold_edges;
    int atlas_width, atlas_height; /* the atlas: its pages side by side (one page: the page itself), what
                                    * lmgi_get_lightmap, texel x, y and lmgi_triangle_lightmap_uv are in */
    int pages;                  /* lightmap pages (1 unless the level does not fit max_atlas_size) */
    int page_width, page_height; /* each page's size (all the same) */
    uint32_t texels;
    float texel_size, utilization; /* utilization: covered texels / the pages' texels */
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
    int material;       /* the triangle's material (lmgi_get_material), -1 where nothing was hit */
    float uv[2];        /* barycentrics of the hit: p = (1 - u - v) corner 0 + u corner 1 + v corner 2, as the
                         * corners of lmgi_triangle_lightmap_uv */
} lmgi_hit;

typedef struct {
    float position[3];  /* world position (centroid of the texel's overlap with its triangle) */
    float normal[3];    /* shading normal: the mean over the texel's part of its surface, by area (at load) */
    int x, y;           /* texel coordinates in the atlas */
    int surface;
    uint32_t triangle;
    float area;         /* world-space area the texel covers */
    int page;           /* its lightmap page, and its coordinates there */
    int page_x, page_y;
} lmgi_texel;

/* The defaults (NULL o: nothing). */
LMGI_API void lmgi_options_init(lmgi_options *o);

/* Loads a .gltf/.glb file and builds surfaces, the lightmap atlas, the texel table and the BVHs.
 * NULL path or out: LMGI_ERR_INVALID. A plan larger than the machine's memory (a tiny texel size) is
 * LMGI_ERR_NOMEM before the work, one above 1 GiB a warning with its estimate. */
LMGI_API lmgi_status lmgi_load(const char *path, const lmgi_options *o, lmgi_scene **out, lmgi_error *err);
LMGI_API void lmgi_free(lmgi_scene *scene); /* NULL: nothing */
/* The same from a .gltf or .glb held in memory (size bytes; `name`, may be NULL, names it in messages).
 * It may not name external files: its buffers and images are the .glb's own or data: URIs. NULL data or
 * size 0: LMGI_ERR_INVALID. The bytes are not kept. */
LMGI_API lmgi_status lmgi_load_memory(const void *data, size_t size, const char *name, const lmgi_options *o,
                                      lmgi_scene **out, lmgi_error *err);

/* NULL scene: info zeroed; NULL info: nothing. */
LMGI_API void lmgi_get_info(const lmgi_scene *scene, lmgi_info *info);
/* Writes the human-readable summary `lmgi info` prints (NULL scene or f: nothing). */
LMGI_API void lmgi_print_info(const lmgi_scene *scene, FILE *f);
LMGI_API int lmgi_effect_count(const lmgi_scene *scene); /* 0 for NULL */
/* NULL scene or i out of range: out zeroed (name NULL); NULL out: nothing. */
LMGI_API void lmgi_get_effect(const lmgi_scene *scene, int i, lmgi_effect *out);

/* Edits (node transforms, static or dynamic, effect switches, lights, materials, the sky) are made
 * between an updater's calls, on the thread that uses it (a scene with an updater follows its context's
 * one thread at a time). Each is checked at once (a refused one changes nothing) and staged: reads
 * (lmgi_get_light, lmgi_get_material, lmgi_get_node_effects, lmgi_node_is_dynamic, lmgi_light_count,
 * lmgi_get_environment) see it at once, and the scene takes the whole batch at the next commit
 * (lmgi_commit, or the next update, bake or picture, or a call that reads the scene as a whole: info,
 * effects, export, a check, the reference, an updater made on it), which waits once for the photon work
 * the last update left running. Staging itself waits for nothing. Node moves and lmgi_set_time change the
 * scene model at once (after waiting for that work) and reach the BVH at the commit. Without an updater a
 * scene may be edited from any one thread at a time.
 *
 * Node lookup and edits. lmgi_set_node_transform moves a dynamic node (world matrix, column-major) and
 * its children with it; a static node, a matrix with NaN or infinite entries, a singular one (a zero
 * scale), or one that mirrors where the node's world matrix at load did not (or the other way round: a
 * node's sides are fixed at load), is refused with LMGI_ERR_INVALID and changes nothing. (An animation
 * may scale a node to zero: the node then leaves the rays until its scale returns.)
 * The rule between edits and animations: an edit wins. A moved node's own animation channels stop
 * driving it (lmgi_set_time and updates play the others), until lmgi_node_resume_animation hands it
 * back; its children's channels still play, relative to where it now is. An updater sees an edit at
 * its next lmgi_update, as it sees an animation's move. Without a time budget, a move after an update
 * without edits is caught up in one go: the photon paths it changed are re-traced and the AIMs they
 * reach refreshed in that update (lmgi_update_stats.groups_at_once), whatever photons.group_budget and
 * aim.surfaces_per_frame say, and the lightmap texels it changed most, 32 updates' worth of
 * gather.texels_per_frame, gathered and shown at once, without the blend; edits made update after update
 * (a drag committed every frame) stay within those counts while they last, and what their moves left is
 * caught up the same way at the first update without edits after them (the drag released; docs/api.md). */
LMGI_API int lmgi_node_count(const lmgi_scene *scene);                 /* 0 for NULL */
LMGI_API int lmgi_find_node(const lmgi_scene *scene, const char *name); /* -1 if absent or either is NULL */
/* A fingerprint of the scene's geometry: the names of the nodes that hold triangles, in order, and each
 * node's triangles in the node's own space (vertex positions, corners, which material each has). Two loads
 * of files that differ only in node transforms, material values, lights, nodes without triangles (a lamp,
 * a camera, an empty) or the sky give the same; a moved vertex, a triangle more or less, a node with
 * triangles more or renamed give another (lmgi view --watch tells edits from a new scene by it). FNV-1a,
 * 64 bits: not for what an adversary chooses. 0 for NULL or no memory. */
LMGI_API uint64_t lmgi_geometry_hash(const lmgi_scene *scene);
LMGI_API const char *lmgi_node_name(const lmgi_scene *scene, int node); /* NULL for NULL or an id out of range */
LMGI_API int lmgi_node_is_dynamic(const lmgi_scene *scene, int node);   /* 0 for NULL or an id out of range */
/* A node's world matrix now (column-major; in the file's world). Returns 0 (world untouched) for a NULL
 * argument or an id out of range. */
LMGI_API int lmgi_get_node_transform(const lmgi_scene *scene, int node, float world[16]);
/* Moves a node (its world matrix, column-major, in the file's world; its children follow). The scene
 * model takes it at once (lmgi_get_node_transform, the next picture); the ray-tracing BVH at the next
 * commit, which moves every node edited since in one go: lmgi_commit, or the next lmgi_update, lmgi_bake
 * or lmgi_render, or anything of lmgi's own that traces rays (lmgi_intersect, the reference, an updater
 * made on the scene). Moving many nodes costs one BVH commit, not one a node. NULL scene or world, an
 * id out of range, a static node with triangles, a matrix with NaN or Inf, a singular one, or one that
 * would mirror a node that was not mirrored at load (or the reverse): LMGI_ERR_INVALID naming it. */
LMGI_API lmgi_status lmgi_set_node_transform(lmgi_scene *scene, int node, const float world[16], lmgi_error *err);
/* Commits the edits staged since the last commit now: light, material, sky and switch edits into the
 * scene in the order made, the nodes moved (lmgi_set_node_transform, lmgi_set_time) into the ray-tracing
 * BVH with one instance update per dynamic node and one top-level commit (Embree's rtcCommitScene), or one
 * rebuild when nodes were switched dynamic or static; an updater re-traces only the lights and materials
 * whose values changed. It first waits for an updater's photon work still running. Optional: every call
 * that traces rays or reads the scene commits first. NULL scene: LMGI_ERR_INVALID; an error of the BVH's
 * (out of memory): LMGI_ERR_BACKEND or LMGI_ERR_NOMEM, the edits kept for the next commit. */
LMGI_API lmgi_status lmgi_commit(lmgi_scene *scene, lmgi_error *err);
/* Switches a node and every node under it between static (0: in the static BVH, shadows cached) and
 * dynamic (1: lmgi_set_node_transform may move it), where they are now. The ray-tracing BVH is rebuilt at
 * once (as at load: milliseconds for thousands of triangles) and the direct pass's casters at the next
 * frame; no photon, AIM or IIM work follows, since nothing moved. A node under a dynamic parent, or one
 * with an animation driving it or a node under it, stays dynamic: LMGI_ERR_INVALID naming it; so is a
 * dynamic other than 0 or 1 or an id out of range. Asking for what the nodes already are: LMGI_OK, nothing
 * done. */
LMGI_API lmgi_status lmgi_set_node_dynamic(lmgi_scene *scene, int node, int dynamic, lmgi_error *err);
/* A node's effect switches (1 on, 0 off), as its glTF extras {"lmgi": {...}} set them at load (unset:
 * its parent's; on at the roots):
 *   shadows      its triangles cast shadows of the point, spot and directional lights;
 *   indirect     its lightmap is gathered and the frame shows it (the light of emissive triangles, which
 *                the lightmap carries, included); off: no gather work at all for it, and the frame shows
 *                its direct light alone; it still blocks and reflects light for the others;
 *   reflections  a mirror, glossy or glass node gets an environment map (off: no map, no cost; mirrors
 *                black);
 *   caustics     a mirror or glass node focuses light: caustic photons are shot at it (off: none, no cost).
 * lmgi_set_node_effects sets them on the node and every node under it; an updater follows at its next
 * update (the casters, the maps and the caustic photons are made again; a node whose indirect comes back
 * on is regathered in full). NULL argument, an id out of range, a switch other than 0 or 1:
 * LMGI_ERR_INVALID, nothing changed. The extras' names are these ("casts_shadows" also for shadows). */
typedef struct {
    int shadows, indirect, reflections, caustics;
} lmgi_node_effects;
LMGI_API lmgi_status lmgi_get_node_effects(const lmgi_scene *scene, int node, lmgi_node_effects *out, lmgi_error *err);
LMGI_API lmgi_status lmgi_set_node_effects(lmgi_scene *scene, int node, const lmgi_node_effects *e, lmgi_error *err);
/* Lights (KHR_lights_punctual). A light of the file shines from its node (lmgi_set_node_transform moves
 * it; a node with no triangles in or under it may be moved even when static); a light added by
 * lmgi_add_light has no node and is placed by its own position and direction. Edits reach an updater at
 * its next update: the light's photon groups are traced (no other light's), its shadow map is redrawn,
 * and the surfaces its photons reach are refreshed.
 * Ids: a light keeps its id for the scene's life; a removed light's id is not given to another, and
 * lmgi_light_count counts it (lmgi_light_is_removed tells). */
typedef enum { LMGI_LIGHT_POINT = 0, LMGI_LIGHT_SPOT, LMGI_LIGHT_DIRECTIONAL } lmgi_light_type;
typedef struct {
    lmgi_light_type type;     /* fixed once the light exists (lmgi_set_light refuses a change) */
    int node;                 /* the node placing it, -1 for an added light (read only) */
    float color[3];           /* linear RGB, each in [0, 1000] */
    float intensity;          /* candela (point, spot) or lux (directional), >= 0 */
    float range;              /* 0: infinite */
    float inner_cone, outer_cone; /* spot: radians, 0 <= inner <= outer <= pi/2, outer > 0 */
    int enabled;              /* 0: switched off (emits nothing; colour and intensity kept) */
    float position[3];        /* world position (point, spot), in the file's world */
    float direction[3];       /* unit direction it shines (spot, directional; unused for point lights).
                               * Both read only for a light with a node (its node places it); for an
                               * added light lmgi_set_light moves it (any length but 0: normalised) */
} lmgi_light;
LMGI_API int lmgi_light_count(const lmgi_scene *scene); /* ids 0 .. count - 1, removed ones included; 0 for NULL */
/* 1 for a removed light; 0 otherwise (a NULL scene or an id out of range included). */
LMGI_API int lmgi_light_is_removed(const lmgi_scene *scene, int light);
/* NULL argument, an id out of range or a removed light's: LMGI_ERR_INVALID (out zeroed when given). */
LMGI_API lmgi_status lmgi_get_light(const lmgi_scene *scene, int light, lmgi_light *out, lmgi_error *err);
/* Recolours, dims, brightens, switches on or off, or reshapes (range, cones) a light, and moves an
 * added one. A NaN, a value out of range, a type or node other than the light's, or an id out of range or
 * removed: LMGI_ERR_INVALID, nothing changed. */
LMGI_API lmgi_status lmgi_set_light(lmgi_scene *scene, int light, const lmgi_light *l, lmgi_error *err);
/* Adds a light of any type, placed by l's position and direction (l->node is ignored), and returns its
 * id in *id (the next one; -1 on failure). An updater traces its photons at its next update: as many
 * per unit of power as the scene's lights at the updater's creation got (the mean light's count for a
 * light added dark), in its own groups, all at once for a light that gives light, whatever the budget
 * (docs/tradeoff.md, "Lights added or switched on"); no other light's photons change. The values as lmgi_set_light checks
 * them, plus a spot or directional light's direction not 0: LMGI_ERR_INVALID, nothing added. */
LMGI_API lmgi_status lmgi_add_light(lmgi_scene *scene, const lmgi_light *l, int *id, lmgi_error *err);
/* Removes a light (the file's or an added one): from the next update on it emits nothing, its photons'
 * hits leave the lightmaps (its groups re-traced: no other light's) and it casts no light in the frame.
 * An id out of range or already removed: LMGI_ERR_INVALID. */
LMGI_API lmgi_status lmgi_remove_light(lmgi_scene *scene, int light, lmgi_error *err);

/* The sky: an environment of uniform radiance (linear RGB, the units of an emissive surface's radiance)
 * around the scene, for outdoor levels and the windows of interiors (docs/levels.md, "Sky"). It lights
 * through photons, the gather (what a texel's hemisphere sees of it), the frame's background and
 * reflections, and the reference; an edit (a darker or bluer sky) is taken up like a light's: its photons
 * re-traced at the next updates. Set it before lmgi_updater_create when the scene has no other light (an
 * updater made for a scene with nothing to light does no indirect work). A NaN, a negative or a value
 * above 1e20: LMGI_ERR_INVALID, nothing changed. Thread-safety: as lmgi_set_light. */
LMGI_API lmgi_status lmgi_set_environment(lmgi_scene *scene, const float radiance[3], lmgi_error *err);
/* 1 and the radiance in out when the scene has a sky (0 and out zeroed otherwise, NULL scene included): the
 * uniform sky's, the gradient's at the zenith, the image's scale. */
LMGI_API int lmgi_get_environment(const lmgi_scene *scene, float out[3]);
/* A two-colour sky: zenith overhead, horizon at and below the horizon, in between linear in the height of
 * the direction (L = horizon + (zenith - horizon) max(y, 0)). An HDR equirectangular image (Radiance .hdr or
 * OpenEXR .exr; row 0 at the zenith, column 0 towards -z) times scale. Either is gathered by rays (a
 * hemicube clears to one colour): an updater made with a hemicube scheme refuses them (LMGI_ERR_INVALID;
 * give the sky before lmgi_updater_create, whose default then takes rays); the frame's background and
 * reflections show it by direction. Bad values as lmgi_set_environment; an image that cannot be read or is
 * not HDR: LMGI_ERR_IO or LMGI_ERR_FORMAT naming it; nothing changed on any error. */
LMGI_API lmgi_status lmgi_set_environment_gradient(lmgi_scene *scene, const float zenith[3], const float horizon[3],
                                                   lmgi_error *err);
LMGI_API lmgi_status lmgi_set_environment_image(lmgi_scene *scene, const char *path, float scale, lmgi_error *err);

/* An application's own level, handed over without a file: meshes (vertex and index arrays placed by a
 * matrix), materials and lights. lmgi_load_desc writes them into a .glb in memory and loads that, so they
 * are checked, classified and lit exactly as a file would be (docs/loading.md). Zero means the default:
 * a zero transform is the identity, a zero base colour white, a zero light colour white. */
typedef struct {
    const char *name;          /* the node's name (lmgi_find_node); NULL: "mesh" */
    const float *positions;    /* 3 floats per vertex, in the node's space */
    const float *normals;      /* 3 per vertex, or NULL: from the faces */
    const float *uvs;          /* 2 per vertex (base colour texture coordinates), or NULL */
    uint32_t vertex_count;
    const uint32_t *indices;   /* 3 per triangle, counter-clockwise seen from the front */
    uint32_t triangle_count;
    int material;              /* index into the desc's materials */
    float transform[16];       /* the node's matrix, column-major (all 0: identity) */
    int dynamic;               /* 1: may move (lmgi_set_node_transform) */
} lmgi_mesh_desc;
typedef struct {
    const char *name;
    float base_color[4];       /* linear RGBA in [0, 1] (all 0: white) */
    float metallic, roughness; /* roughness 0: 1 */
    float emissive[3];         /* emitted radiance (any size) */
    float transmission, ior;   /* glass: transmission 1, ior e.g. 1.5 (0: none) */
    int double_sided;
} lmgi_material_desc;
typedef struct {
    const char *name;          /* its node's name */
    int type;                  /* lmgi_light_type: LMGI_LIGHT_POINT (0), _SPOT, _DIRECTIONAL */
    float color[3];            /* all 0: white */
    float intensity;           /* candela (point, spot) or lux (directional) */
    float range;               /* 0: infinite */
    float inner_cone, outer_cone; /* spot, radians (outer 0: pi/4) */
    float position[3], direction[3]; /* direction 0: down -z */
} lmgi_light_desc;
typedef struct {
    const char *name;          /* names the scene in messages; NULL: "(scene desc)" */
    const lmgi_mesh_desc *meshes;
    int mesh_count;
    const lmgi_material_desc *materials;
    int material_count;
    const lmgi_light_desc *lights;
    int light_count;
} lmgi_scene_desc;
/* Builds a scene from a desc. No meshes, an index past its mesh's vertices, a material out of range,
 * NaN or infinite numbers: LMGI_ERR_INVALID naming the mesh or light; otherwise as lmgi_load. */
LMGI_API lmgi_status lmgi_load_desc(const lmgi_scene_desc *desc, const lmgi_options *o, lmgi_scene **out,
                                    lmgi_error *err);

/* Materials. An edit reaches an updater at its next update: the photons that touch the material are
 * re-traced (no others), the AIMs of its surfaces refreshed, and the frame's direct light and indirect
 * term use the new material at once. The class (diffuse, glossy, mirror, glass, emitter) follows from
 * metallic, roughness and transmission by the rule loading applies (docs/materials.md), so changing those
 * may change it: a diffuse or glossy material may become any of the four (a mirror's or glass's
 * triangles keep their lightmap texels, unused, so it may come back); one that was mirror or glass at
 * load has no texels and stays mirror or glass; an emitter (emissive at load) stays an emitter. */
typedef enum { LMGI_MATERIAL_DIFFUSE = 0, LMGI_MATERIAL_GLOSSY, LMGI_MATERIAL_MIRROR, LMGI_MATERIAL_GLASS,
               LMGI_MATERIAL_EMITTER } lmgi_material_class;
typedef struct {
    lmgi_material_class cls;  /* read only: what the parameters make (lmgi_set_material accepts the old
                               * class or the new one here, and refuses any other) */
    float base_color[4];      /* linear RGBA factor, each in [0, 1] (a base colour texture multiplies it) */
    float emissive[3];        /* emitted radiance (emissiveFactor x strength), >= 0; non-zero only for a
                               * material that was emissive at load (its triangles are the emitters) */
    float metallic, roughness; /* each in [0, 1] (fixed for an emitter) */
    float transmission;       /* KHR_materials_transmission, in [0, 1] (0.5 and above: glass) */
    float ior;                /* KHR_materials_ior, in [1, 10] */
} lmgi_material;
LMGI_API int lmgi_material_count(const lmgi_scene *scene); /* 0 for NULL */
LMGI_API const char *lmgi_material_name(const lmgi_scene *scene, int material); /* NULL when out of range */
/* NULL argument or an id out of range: LMGI_ERR_INVALID (out zeroed when given). */
LMGI_API lmgi_status lmgi_get_material(const lmgi_scene *scene, int material, lmgi_material *out, lmgi_error *err);
/* Recolours a material, changes its emission, or its class through metallic, roughness, transmission and
 * ior. NaN or values out of range, emission on a material that was not emissive at load, a class the
 * material cannot take (above), a cls that is neither its class nor the parameters', or an id out of
 * range: LMGI_ERR_INVALID naming it, nothing changed. */
LMGI_API lmgi_status lmgi_set_material(lmgi_scene *scene, int material, const lmgi_material *m, lmgi_error *err);

/* Hands an edited node back to its animations from the next lmgi_set_time or update on. NULL scene or
 * an id out of range: LMGI_ERR_INVALID. */
LMGI_API lmgi_status lmgi_node_resume_animation(lmgi_scene *scene, int node, lmgi_error *err);
/* Plays every glTF animation to time t (seconds) and moves the animated nodes (the BVH at the next
 * commit, as lmgi_set_node_transform says). NULL scene or a t that is not finite: LMGI_ERR_INVALID. */
LMGI_API lmgi_status lmgi_set_time(lmgi_scene *scene, float t, lmgi_error *err);

/* Closest hit of the ray org + t dir, t in (0, tmax). A ray with a NaN, infinite or huge (above 1.8e18)
 * number, a zero direction or a NaN or negative tmax hits nothing (hit->hit = 0); tmax may be +inf.
 * NULL scene, org or dir: no hit; NULL hit: nothing. */
LMGI_API void lmgi_intersect(const lmgi_scene *scene, const float org[3], const float dir[3], float tmax, lmgi_hit *hit);

LMGI_API uint32_t lmgi_texel_count(const lmgi_scene *scene); /* 0 for NULL */
/* NULL scene or i out of range: out zeroed with surface -1; NULL out: nothing. */
LMGI_API void lmgi_get_texel(const lmgi_scene *scene, uint32_t i, lmgi_texel *out);
/* The lightmap UVs of a triangle's three corners (6 floats in [0,1]); returns 0 if it has none (or
 * scene or uv is NULL). */
LMGI_API int lmgi_triangle_lightmap_uv(const lmgi_scene *scene, uint32_t triangle, float uv[6]);
/* Pages (docs/api.md, "Lightmap pages"): a level too large for one max_atlas_size page has several, each
 * an engine's lightmap texture; inside lmgi they lie side by side in the atlas. The triangle's page and
 * its corners' UVs over that page alone (6 floats in [0,1]); returns -1 (uv untouched) where it has none,
 * or scene or uv is NULL. With one page, page 0 and lmgi_triangle_lightmap_uv's UVs, bit for bit. */
LMGI_API int lmgi_triangle_lightmap_page(const lmgi_scene *scene, uint32_t triangle, float uv[6]);
/* The atlas rectangle {x, y, width, height} of page `page`; returns 0 (rect zeroed) for NULL or a page
 * out of range. */
LMGI_API int lmgi_page_rect(const lmgi_scene *scene, int page, int rect[4]);

/* ------------------------------------------------------------------------------------------------------
 * Context: where messages go and the OpenGL context every updater made from it renders with.
 *
 * Thread-safety: a context, and every updater made from it, is used from one thread at a time (the
 * GL context is made current on the calling thread at each call); a call from a second thread while
 * another is inside one is refused with LMGI_ERR_INVALID ("in use by another thread"), not raced (docs/
 * api.md, "Threads"). Two contexts may be used on two threads at once; nothing is shared between them but
 * read-only scenes. */
typedef struct lmgi_context lmgi_context;

typedef enum { LMGI_LOG_ERROR = 1, LMGI_LOG_WARN, LMGI_LOG_INFO, LMGI_LOG_DEBUG } lmgi_log_level;
/* One message, without a prefix or newline; called on the thread that made the call (or, for the
 * photon work an update runs beside rendering, on that update's worker thread while the call lasts). */
typedef void (*lmgi_log_fn)(void *user, lmgi_log_level level, const char *message);

/* Zero-initialised means the defaults. */
typedef struct {
    lmgi_log_fn log;          /* NULL: messages go to stderr as "lmgi: warning: ..." */
    void *log_user;
    lmgi_log_level log_level; /* the most detailed level passed on (0: LMGI_LOG_WARN) */
    const char *gl_backend;   /* "auto", "egl" or "osmesa" (NULL: the LMGI_GL environment variable, else
                               * auto: EGL when it gives a hardware renderer, else OSMesa) */
    void *share_context;      /* the host's GL context to share textures with (lmgi_get_lightmap_texture):
                               * an EGLContext of desktop OpenGL (EGL_OPENGL_API, any version) with
                               * share_display its EGLDisplay, or an OSMesaContext with share_display NULL.
                               * lmgi's context is made on that display in its share group (the backend is
                               * the host's kind; another named in gl_backend is refused). NULL: none */
    void *share_display;
} lmgi_context_desc;

/* Creates the GL context (OpenGL 4.5 core, no window). NULL desc: the defaults; NULL out:
 * LMGI_ERR_INVALID; no GL 4.5: LMGI_ERR_BACKEND naming what was tried. */
LMGI_API lmgi_status lmgi_context_create(const lmgi_context_desc *desc, lmgi_context **out, lmgi_error *err);
/* Every updater made from it must be freed first. NULL: nothing. */
LMGI_API void lmgi_context_free(lmgi_context *ctx);
/* "4.5 (Core Profile) Mesa 22.3.6 / llvmpipe (...) (OSMesa; ...)"; "" for NULL. */
LMGI_API const char *lmgi_context_gl_description(const lmgi_context *ctx);

/* ------------------------------------------------------------------------------------------------------
 * Updater: keeps a scene's lightmaps up to date as it changes (docs/architecture.md, "The frame loop").
 * Creating one traces every photon, fills every AIM and gathers every texel (seconds on big atlases; the
 * desc's progress callback follows it), so the first update already shows converged light. Each
 * lmgi_update then plays animations to its time, re-traces the photons that changed, refreshes the AIMs
 * of the surfaces whose photons changed most, and regathers IIM texels within a budget.
 *
 * The scene is borrowed and must outlive the updater (lmgi_free refuses, with a message, a scene that has
 * one); a scene has at most one updater, since updates move its nodes. Node edits made while an updater
 * exists reach it at its next update. Thread-safety: as its context's (one thread at a time). */
typedef struct lmgi_updater lmgi_updater;

typedef enum { LMGI_EMITTERS_AUTO = 0, LMGI_EMITTERS_CLOSED_FORM, LMGI_EMITTERS_DRAWN } lmgi_emitter_light;
/* Progress of long work: fraction 0 to 1 and the stage under way ("photons", "gather", "done"). */
typedef void (*lmgi_progress_fn)(void *user, float fraction, const char *stage);
typedef enum {
    LMGI_GATHER_DEFAULT = 0, /* the hemicube, or rays for a scene of over LMGI_RAYS_ABOVE_TRIANGLES where the GL
                              * rasterizes in software, under a sky that is not uniform, and where emissive
                              * triangles alone light the scene with aim.direct on auto (docs/gather.md,
                              * "Rays"); lmgi_check chooses as lmgi_updater_create does */
    LMGI_GATHER_VIEWPORTS,   /* hemicubes, one draw per texel */
    LMGI_GATHER_INSTANCED,   /* hemicubes, one instanced draw per pass */
    LMGI_GATHER_LAYERED,     /* hemicubes, into a layered target */
    LMGI_GATHER_RAYS         /* no hemicube: Embree rays over each texel's hemisphere on every core */
} lmgi_gather_scheme;
#define LMGI_RAYS_ABOVE_TRIANGLES 20000

enum { LMGI_EFFECT_SHADOWS = 1, LMGI_EFFECT_INDIRECT = 2, LMGI_EFFECT_REFLECTIONS = 4, LMGI_EFFECT_CAUSTICS = 8 };
/* How frames get their indirect light (docs/gather.md, docs/tiled.md): LMGI_INDIRECT_LIGHTMAP, the
 * paper's AIMs, hemicube gather and IIM (the lightmaps); the others gather the photon hits themselves at
 * every visible pixel on the GPU (Mara et al. 2013; no AIM or IIM, so the lightmaps stay 0 and environment
 * maps show direct light only): TILED per screen tile from shared memory (the fast one), HASHGRID per
 * pixel from a hash grid of cells, BRUTEFORCE every photon against every pixel (the ground truth the
 * others equal, for small frames). */
typedef enum {
    LMGI_INDIRECT_LIGHTMAP = 0,
    LMGI_INDIRECT_BRUTEFORCE,
    LMGI_INDIRECT_TILED,
    LMGI_INDIRECT_HASHGRID
} lmgi_indirect_path;
/* Where the approximate illumination maps (docs/aim.md) get direct light. DEFAULT: EMITTERS with the rays
 * gather where a scene is lit by emissive triangles alone, in closed form (no punctual light, no sky; the
 * gather scheme on auto is then rays: docs/gather.md, "Near and far hits"), else SUNS. SUNS: directional
 * lights' computed per texel by shadow rays, photons bringing the rest (a sun's photons are spread over the
 * whole scene, a large level's ground included, so its direct light is the first to starve); PHOTONS: photon
 * first hits bring it all (the paper's form: blurred across shadow edges by the photon estimate's radius);
 * EMITTERS: emissive triangles' light computed per texel (closed form, sampled shadows) where the gather's
 * closed form suits the scene, photons bringing the rest (sharp contact shadows; the rays gather takes it
 * at its near hits); ALL: emissive triangles' and every punctual light's. */
typedef enum {
    LMGI_AIM_DIRECT_DEFAULT = 0,
    LMGI_AIM_DIRECT_SUNS,
    LMGI_AIM_DIRECT_EMITTERS,
    LMGI_AIM_DIRECT_ALL,
    LMGI_AIM_DIRECT_PHOTONS
} lmgi_aim_direct;

/* The updater's tuning knobs, stage by stage: one struct per stage, made from the knob table
 * (lmgi_knobs.h, which gives each knob's range, default, meaning of LMGI_OFF and help). 0 is always the
 * default; LMGI_OFF says "off" (none, all at once, no filter: the knob's line says which). */
typedef struct { LMGI_PHOTON_KNOBS(LMGI_KNOB_MEMBER) } lmgi_photon_knobs;   /* docs/photons.md */
typedef struct { LMGI_AIM_KNOBS(LMGI_KNOB_MEMBER) } lmgi_aim_knobs;         /* docs/aim.md */
typedef struct { LMGI_GATHER_KNOBS(LMGI_KNOB_MEMBER) } lmgi_gather_knobs;   /* docs/gather.md */
typedef struct { LMGI_CAUSTIC_KNOBS(LMGI_KNOB_MEMBER) } lmgi_caustic_knobs; /* docs/caustics.md */
typedef struct { LMGI_TILED_KNOBS(LMGI_KNOB_MEMBER) } lmgi_tiled_knobs;     /* docs/tiled.md */
/* The frame each lmgi_update composites (what `lmgi run` writes): its size (0 x 0: none; lmgi_render
 * draws on demand), the file's camera for it (0: its first; -1, or 0 when it has none: one framing the
 * scene), and its knobs. */
typedef struct {
    int width, height;
    int camera;
    LMGI_FRAME_KNOBS(LMGI_KNOB_MEMBER)
} lmgi_frame_knobs;

/* Zero-initialised means the defaults (the same as `lmgi run`'s; docs/ says what each costs and buys). */
typedef struct {
    lmgi_photon_knobs photons;
    lmgi_aim_knobs aim;
    lmgi_gather_knobs gather;
    lmgi_caustic_knobs caustics;
    lmgi_frame_knobs frame;
    lmgi_tiled_knobs tiled;        /* the per-pixel photon gathers (indirect TILED, HASHGRID, BRUTEFORCE) */
    lmgi_indirect_path indirect;   /* (0: LMGI_INDIRECT_LIGHTMAP) */
    /* effects this updater leaves out whatever the scene calls for (0: none), LMGI_EFFECT_* bits:
     * SHADOWS no shadow maps (lights reach everything), INDIRECT no photon, AIM or gather work at all
     * (the lightmaps stay 0; the frame shows direct light, emission, caustics and reflections), REFLECTIONS
     * no environment maps (as frame.reflection_size LMGI_OFF), CAUSTICS no caustic photons and no caustic
     * pass. Per node: lmgi_set_node_effects */
    unsigned effects_off;
    int in_order;              /* 1: the photon work before the gather on the calling thread (the paper's
                                * order); 0: on a second thread beside rendering, one update behind */
    /* the first full solution made by lmgi_updater_create: its gather's progress (NULL: none), and a flag
     * that, set non-zero (from any thread), stops it between gather passes: LMGI_ERR_CANCELLED */
    lmgi_progress_fn progress;
    void *progress_user;
    const volatile int *cancel;
    /* the first full solution's checkpoint (docs/levels.md, "Long bakes"): a file (NULL: none) that its
     * gather writes what it has finished to, between passes at most every checkpoint_seconds (0: 10) and
     * when cancelled, so that a killed or cancelled bake keeps its work; resume non-zero: the gather starts
     * from that file and ends with the same bits as a bake that never stopped. A resume without the file,
     * or from one of another scene or other settings, is LMGI_ERR_INVALID naming it; nothing is written
     * over it then. The caller removes the file when it no longer wants it. */
    const char *checkpoint;
    double checkpoint_seconds;
    int resume;
    /* a bake spread over processes or machines (docs/levels.md, "A bake in shards"): shards > 0 (at most
     * 4096) makes the first full solution gather only share `shard` (0 to shards - 1) of its texels, into
     * the checkpoint file (needed), which holds that share when the call returns: a part. The updater's
     * lightmap is then incomplete: keep the part and free it. parts (part_count files, each a part of
     * every share made by the same scene and settings) instead make the first full solution from their
     * texels put together: the same bits as one process's. A part of another scene or other settings, two
     * parts with the same texels, a share no part holds, an unfinished part, shard out of range, shards
     * without a checkpoint, or parts with shards or resume: LMGI_ERR_INVALID naming it. */
    int shard, shards;
    const char *const *parts;
    int part_count;
    /* a bake by processes that work together (an MPI bake, docs/farm.md): every process has the same scene
     * and desc but its own shard (0 to shards - 1, shards > 1), and these calls connect them.
     * photon_exchange (NULL: each traces every photon) shares the photon trace: photon k of a full trace is
     * traced by process k mod shards alone, and the paths are exchanged so that every process stores them
     * all, the one-process photon map to the bit. It is collective (every process calls it as often) and
     * called twice per batch of photons: with all NULL, to fill sizes[0 .. shards) with every process's
     * byte count (this one's is `size`), then to fill `all` (their sum) with every process's bytes back to
     * back in process order. Return 0 on failure (the call then fails with LMGI_ERR_BACKEND).
     * claim_pass (NULL: every shards-th pass from shard, as above) hands out the first gather's passes as
     * the processes finish them, so that each gathers what its speed allows: called between passes with
     * the number of passes, it returns the next pass this process gathers (0 to passes - 1, each pass to
     * one process only) or -1 when none is left. The part then lists the passes it took; parts are put
     * together as above, refused when two hold one pass or a pass is in none. */
    int (*photon_exchange)(void *user, const void *mine, size_t size, size_t *sizes, void *all);
    int (*claim_pass)(void *user, int passes);
    void *share_user;
} lmgi_updater_desc;

/* The desc's defaults resolved: every knob's default (lmgi_knobs.h) where it has one of its own, 0 where
 * the scene chooses it (lmgi_get_updater_info gives what an updater chose). NULL d: nothing. */
LMGI_API void lmgi_updater_defaults(lmgi_updater_desc *d);

/* What one lmgi_update did and what it cost (milliseconds). With the photon work on a second thread
 * (in_order 0) its counts are those of the work that ran during this update. */
typedef struct {
    int frame;                 /* updates before this one */
    float time;                /* animation time, seconds */
    uint32_t photons_retraced, groups_invalidated, groups_retraced;
    int aim_surfaces_refreshed; /* for the photons that changed, and at once for a light, emission or colour
                                 * edit (those are in ms_aim too, not ms_animate) */
    uint32_t texels_gathered;  /* IIM texels regathered */
    uint32_t texels_estimated; /* texels waiting to be regathered whose estimate from a few rays (the change of
                                * what they see since their gather) this update brought up to date and shows
                                * (docs/gather.md, "Rays for the texels that wait"); gather.texels_per_frame x
                                * 16 at most without a time budget, what the budget gives them with one;
                                * their time in ms_estimates */
    uint32_t texels_based;     /* texels whose estimate's base (what their few rays see as gathered) was taken
                                * since the last update: those gathered, and every texel once, at the setup
                                * in a scene with a dynamic node or an animation, else before its first edit,
                                * counted here (docs/gather.md, "Rays for the texels that wait") */
    int texels_budget;         /* the texels this update was allowed (budget_ms > 0: from the measured cost) */
    int surfaces_changed;      /* surfaces whose displayed lightmap changed (lmgi_surface_version moved) */
    uint32_t caustic_photons_retraced; /* caustic photons traced (a moved light or mirror/glass node: all its) */
    int caustic_tiles, caustic_tiles_lit; /* screen tiles (each queried when a photon projects into it), and
                                           * those found holding caustic photons */
    uint64_t caustic_pixels_filtered; /* pixels the caustic filter ran on (the lit tiles grown by k) */
    uint32_t caustic_photons_landed, caustic_photons_thin; /* caustic photons that landed, and of those the ones
                                * the lightmaps carry as thin light (docs/caustics.md, "Thin light in the
                                * lightmaps"); the rest are the screen pass's */
    int cube_faces_rendered;   /* environment map faces rendered */
    int planar_maps_rendered;  /* flat reflectors' pictures of the view mirrored in their plane, drawn when
                                * the view or what they show changed (docs/direct.md, "Flat reflectors";
                                * their time is in ms_direct) */
    int photon_gathers;        /* per-pixel photon gathers run (indirect TILED, HASHGRID, BRUTEFORCE): 0 when
                                * the photons, the view and the scene were as for the last one (its picture
                                * is shown again; the gather's time is in ms_gather) */
    uint64_t photon_entries;   /* the tile or hash-cell list entries of those gathers */
    uint32_t photon_pages_uploaded; /* pages of 1,024 photon records sent to the GPU (only those that changed) */
    double ms_animate, ms_trace, ms_aim, ms_caustic_trace; /* the photon work's parts */
    double ms_photons;         /* what the update spent on or waiting for the photon work */
    double ms_gather, ms_blend, ms_direct, ms_caustics, ms_reflections, ms_composite, ms_total;
    int shadow_maps_rendered;  /* punctual lights' shadow maps re-rendered */
    int shadow_maps_stale;     /* stale ones left for the next updates (desc.frame.shadow_maps_per_update) */
    /* the stage that took the update's longest time: "photons" (invalid groups re-traced), "AIM", "caustic
     * photons", "reflections" (environment map faces), "gather" (the texels gathered), "light scale" (a
     * light edit's texel factors), "estimates" (the waiting texels' ray estimates) or "frame" (the
     * picture's own passes), and why, in words: what it did, what still waits, and what the budget planned
     * for it */
    const char *busiest_stage;
    char why[160];
    int lights_scaled;         /* lights changed in power alone (colour, intensity, switched off) and emitters
                                * in their emission: their photons' hits scaled instead of re-traced, and their
                                * light shown in the lightmaps at once, refined by the regathers after
                                * (docs/tradeoff.md, "Light edits at once") */
    int aim_surfaces_at_once;  /* of aim_surfaces_refreshed, those refreshed at once for this update's light,
                                * emission or colour edits, or a placement's catch-up (groups_at_once): as many
                                * as the edits reach, outside the AIM budget that bounds the others (issue 32,
                                * item 4) */
    double ms_light_scale;     /* of ms_photons or ms_gather: a light, emission or colour edit's texel factors,
                                * their first guess at the edit, then their refinement a few surfaces an update
                                * within the budget (docs/tradeoff.md, "Light edits at once") */
    uint32_t light_scale_rays; /* the rays of one of their two gathers this update cast */
    int lights_lit;            /* lights added or switched on from dark, whatever the budget: their photons
                                * traced in this update, not over the updates after, and their light shown in
                                * the lightmaps at once as a first guess that the regathers after refine
                                * (docs/tradeoff.md, "Lights added or switched on") */
    uint32_t groups_at_once;   /* of groups_retraced, those re-traced at once for a node or light this
                                * update's edits placed or reshaped after an update without edits, or that
                                * edits in a row placed, in the first update without edits after them (a drag
                                * released); without a time budget; the AIMs they changed are in
                                * aim_surfaces_at_once: the edits' own work, beyond photons.group_budget
                                * (docs/photons.md, "Caught up in one update") */
    int placements_caught_up;  /* 1: this update caught up with the nodes and lights edits placed (its
                                * groups_at_once, its AIMs at once, the lightmap texels they changed most
                                * gathered and shown at once), whether or not a group was left to re-trace:
                                * after a still update, or the first update without edits after edits in a
                                * row (a drag released); never under a time budget */
    double ms_estimates;       /* of ms_gather: the waiting texels' estimates (texels_estimated), a stage the
                                * time budget plans on its own (docs/api.md, "The time budget") */
} lmgi_update_stats;

/* NULL ctx, scene, out: LMGI_ERR_INVALID (NULL desc: the defaults); a value out of range (negative
 * sizes, groups not 2^a 3^b, ...): LMGI_ERR_INVALID naming it; a scene without triangles, or one that
 * already has an updater: LMGI_ERR_INVALID. */
LMGI_API lmgi_status lmgi_updater_create(lmgi_context *ctx, lmgi_scene *scene, const lmgi_updater_desc *desc,
                                lmgi_updater **out, lmgi_error *err);
LMGI_API void lmgi_updater_free(lmgi_updater *u); /* NULL: nothing */

/* The settings an updater resolved (the desc's zeros and per-scene choices made) and its setup's cost. */
typedef struct {
    /* every knob as the updater runs it: the desc's values with each 0 made its default or the scene's
     * choice (LMGI_OFF stays LMGI_OFF); tiled.radius is 0 before the first frame of a per-pixel gather;
     * photons.per_group, when the count chose it, is the largest group's photons (the round robin re-checks
     * every stored path in per_group / retrace_per_group updates) */
    lmgi_photon_knobs photons;
    lmgi_aim_knobs aim;
    lmgi_gather_knobs gather;
    lmgi_caustic_knobs caustics;
    lmgi_frame_knobs frame;
    lmgi_tiled_knobs tiled;
    const char *gather_scheme;  /* "viewports", "instanced", "layered" or "rays" */
    uint32_t emissive_triangles;
    int emitters_closed_form;   /* 1: their light in closed form with gather.emitter_rays shadow rays, 0: drawn */
    uint32_t stored_photons;    /* stored photon paths over all lights */
    double ms_setup_trace, ms_setup_aim, ms_setup_gather; /* the full trace, every AIM, the full gather */
    const char *indirect;       /* "lightmap", "tiled", "hashgrid" or "bruteforce" */
    int portals_found;          /* rectangles found for suns and the sky to aim their photons through: openings, and
                                 * places outside whose light gets in by them (photons.find_portals; 0: none) */
} lmgi_updater_info;
/* NULL u: info zeroed; NULL info: nothing. */
LMGI_API void lmgi_get_updater_info(const lmgi_updater *u, lmgi_updater_info *info);

/* Baking: the lightmaps brought to the converged state of the scene as it is now, for an editor. An
 * updater's creation is the first bake (every photon, AIM and texel); lmgi_bake after edits re-traces
 * every photon (a path the edits did not change changes nothing), refreshes the AIMs of the surfaces
 * whose photons changed and regathers every texel of the surfaces whose light changed, then shows them
 * at once, and reports how much that was. The quality is the updater's desc (photons, N, R, ...).
 * The bake works on the updater (not the scene) because the updater holds the solution it refines. */
typedef struct {
    lmgi_progress_fn progress;  /* NULL: none */
    void *progress_user;
    const volatile int *cancel; /* set non-zero (from any thread) to stop within about 100 ms (between
                                 * gather passes): LMGI_ERR_CANCELLED, the lightmaps as before the bake
                                 * and what it did not finish left to the next bake or update */
    float time;                 /* animation time to bake at (seconds) */
    int fresh_plan;             /* 1: the bake gives a fresh updater's lightmap of the scene as it is now,
                                 * to the bit: where lights changed in power or number since the updater's
                                 * creation the photons are planned again as a fresh updater plans them
                                 * (at the cost of every photon path and texel), and a path that moved by
                                 * float noise is stored again; 0 (default): the shares of creation are
                                 * kept, and an edit in one room re-traces and regathers nothing of
                                 * another's (docs/api.md, "Baking") */
} lmgi_bake_desc;
typedef struct {
    uint32_t photons_traced, photons_changed; /* re-traced, and of those the paths the edits changed */
    int aim_surfaces_refreshed;
    uint32_t texels_gathered;   /* texels regathered (the atlas has lmgi_info.texels) */
    int surfaces_seeing;        /* of the surfaces regathered, those only because they see a refreshed AIM */
    int surfaces_changed;       /* surfaces whose lightmap changed */
    double ms_photons, ms_gather, ms_total;
} lmgi_bake_report;
/* NULL u or a non-finite time: LMGI_ERR_INVALID; NULL desc: the defaults; report may be NULL. */
LMGI_API lmgi_status lmgi_bake(lmgi_updater *u, const lmgi_bake_desc *desc, lmgi_bake_report *report,
                               lmgi_error *err);

/* One frame's work at animation time `time` (seconds; animations clamp to their range). budget_ms > 0:
 * one budget for every stage: the invalid photon groups re-traced, the AIM refreshes' hits, the caustic
 * photons, the environment map faces and the texels regathered are chosen from each stage's measured cost
 * in the last updates so that the update takes about budget_ms (never less than one unit of a stage that
 * has work waiting); 0: the desc's fixed counts (gather.texels_per_frame, photons.group_budget, ...). stats may be
 * NULL. NULL u, a time or budget that is not finite, or a negative budget: LMGI_ERR_INVALID. A frame
 * that came out with a NaN or infinity: LMGI_ERR_BACKEND naming the first stage that has them (the AIMs,
 * the IIM lightmap, the caustics, else the direct light, reflections or composite). */
LMGI_API lmgi_status lmgi_update(lmgi_updater *u, float time, float budget_ms, lmgi_update_stats *stats, lmgi_error *err);

/* The frame the last lmgi_update composited (frame.width x frame.height x 3 linear floats, top row
 * first; valid until the next update or the free), NULL before the first update or without a frame. */
LMGI_API const float *lmgi_frame(const lmgi_updater *u, int *width, int *height);

/* A camera (column-major matrices, GL conventions: view space looks down -z, proj maps to clip space),
 * in the file's world (see "Coordinates" above). */
typedef struct {
    float view[16], proj[16];
} lmgi_camera;
/* The scene's camera `index` (-1: the file's first, else one framing the scene) for a width x height
 * picture. NULL scene or cam: LMGI_ERR_INVALID; index out of range: LMGI_ERR_INVALID. */
LMGI_API lmgi_status lmgi_scene_camera(const lmgi_scene *scene, int index, int width, int height, lmgi_camera *cam,
                              lmgi_error *err);
/* Composites the current lighting (direct, shadows, reflections, indirect from the IIM) from `cam` into
 * rgb (width * height * 3 linear floats, top row first). NULL argument, sizes outside 1..16384 or a view
 * matrix that is not invertible: LMGI_ERR_INVALID. */
LMGI_API lmgi_status lmgi_render(lmgi_updater *u, const lmgi_camera *cam, int width, int height, float *rgb,
                        lmgi_error *err);

/* The lightmaps, atlas-sized (lmgi_info's atlas_width x atlas_height) RGBA floats, row 0 at v = 0:
 *   LMGI_LIGHTMAP_IIM       irradiance E (rgb) as displayed, a = 1 on valid texels, 0 on gutters and on
 *                           texels inside or under geometry (those filled from their neighbours and the
 *                           gutters dilated, so bilinear filtering stays smooth);
 *   LMGI_LIGHTMAP_AIM       the approximate illumination map (photon estimate of radiance leaving each
 *                           texel, rgb; gutters dilated), a as above;
 *   LMGI_LIGHTMAP_ERROR     how far the displayed IIM may still be from the lighting as it is now,
 *                           relative to the texel's irradiance (r = g = b): what a refresh under way or
 *                           a blend has still to bring in, and, where the surface's photons changed since
 *                           its last refresh, that change relative to their energy (an upper bound;
 *                           docs/api.md, "The error atlas"). 0 everywhere once the lightmap has caught
 *                           up: an editor shows what is not yet final, a game can wait for it. a as above.
 *   LMGI_LIGHTMAP_ACCURACY  the lightmaps' estimate of their own accuracy (needs desc.aim.error_estimate): r the
 *                           IIM texel's relative standard error from the photon noise of the AIMs its
 *                           hemicube sees, g the AIM texel's own, b the share of its hemicube on back faces
 *                           (light it cannot know); a as above. Noise, not bias: docs/gather.md, "Error
 *                           estimate", says what it ranks and what it misses. Costs 64 rays a texel a call.
 * A diffuse surface's indirect radiance is albedo / pi * E (docs/materials.md). */
typedef enum { LMGI_LIGHTMAP_IIM = 0, LMGI_LIGHTMAP_AIM, LMGI_LIGHTMAP_ERROR, LMGI_LIGHTMAP_ACCURACY } lmgi_lightmap;
/* The caustics of the last picture the updater drew, an update's own frame or lmgi_render's
 * (docs/caustics.md): the caustic irradiance E at each pixel, the screen-space pass's filter plus the thin
 * light the lightmaps carry (caustics.thin), width x height x 3 linear floats, top row first (the picture
 * added kd / pi x E there); 0 where no caustic photon's light reached, and everywhere in a scene without
 * caustics. *width and *height (each may be NULL) get
 * the picture's size, 0 x 0 before any; rgb must hold `floats` >= 3 x width x height. NULL u or rgb, too
 * small, or no picture yet: LMGI_ERR_INVALID (the size still given). */
LMGI_API lmgi_status lmgi_get_caustics(lmgi_updater *u, float *rgb, size_t floats, int *width, int *height,
                                       lmgi_error *err);
/* rgba must hold `floats` >= 4 * atlas_width * atlas_height floats. NULL u or rgba, too small, or an
 * unknown kind: LMGI_ERR_INVALID. */
LMGI_API lmgi_status lmgi_get_lightmap(lmgi_updater *u, lmgi_lightmap kind, float *rgba, size_t floats, lmgi_error *err);

/* Export for engines (docs/api.md, "Exporting to engines"): the scene as lmgi lit it, written to
 * DIR/NAME.gltf (+ NAME.bin, NAME_texN.png for its textures) with TEXCOORD_1 on every triangle set to its
 * lightmap UVs, and the lightmap itself beside it: NAME_lightmap.exr (the displayed IIM as
 * lmgi_get_lightmap gives it: irradiance, alpha = valid; linear float or half), NAME_lightmap.png (a
 * tone-mapped preview) and NAME_lightmap_rgbd.png (RGBD, the texture every material with lightmap texels
 * samples through TEXCOORD_1 by the vendor extension LMGI_lightmap, which says how to decode it: docs/api.md,
 * "The lightmap in engines"). Every node is a root placed by its world matrix at the time of the export (the
 * baked pose; animations are not written); each node with lightmap texels names the lightmap in its
 * extras ({"lightmap": {"uri": "NAME_lightmap.exr", "texCoord": 1}}, beside {"lmgi": {...}}, its
 * settings), and the document's extras say what the lightmap holds. The copy loads back into lmgi with
 * lmgi_options.use_file_uv1 (`--use-uv1`) and lights the same. A level of several pages (lmgi_info.pages)
 * gets those three images for each page P, NAME_lightmap_pageP.exr, .png and _rgbd.png; TEXCOORD_1 over
 * the triangle's page; a primitive per node, material and page; and a material on several pages written
 * once per page, each copy's LMGI_lightmap naming its page's image. */
typedef struct {
    const char *name;   /* the files' base name (NULL: "scene"): letters, digits, - _ . */
    int half;           /* the EXR in 16-bit half floats */
    int force;          /* write into a directory that holds files lmgi did not write (lmgi_output_open) */
    lmgi_output *output; /* write into this open output's new result (dir then unused, may be NULL); NULL:
                          * open dir as the command "export", commit at the end */
} lmgi_export_desc;
/* NULL u, NULL dir without desc->output, a name that is not plain: LMGI_ERR_INVALID; the scene's own
 * file in the way, a directory lmgi may not write into (lmgi_output_open), a failed write: LMGI_ERR_IO
 * naming the file, and nothing of the export left. NULL desc: the defaults. Thread-safety: as the
 * updater's. */
LMGI_API lmgi_status lmgi_export_gltf(lmgi_updater *u, const char *dir, const lmgi_export_desc *desc,
                                      lmgi_error *err);

LMGI_API int lmgi_surface_count(const lmgi_scene *scene); /* 0 for NULL */
/* The atlas rectangle holding a surface's texels: rect = {x, y, width, height}; returns 0 (rect zeroed)
 * for NULL or an id out of range. A surface's charts may share the rectangle with other surfaces. */
LMGI_API int lmgi_surface_rect(const lmgi_scene *scene, int surface, int rect[4]);
/* The page holding a surface's texels: its node's page where the node's charts fit one page (nearly
 * always), else the surface's own. -1 for NULL, an id out of range, a surface without texels, and a
 * surface larger than a page, whose charts lie on several (lmgi_triangle_lightmap_page then says which). */
LMGI_API int lmgi_surface_page(const lmgi_scene *scene, int surface);
/* How many updates changed what surface's lightmap shows (1 after the updater's first gather): upload a
 * surface's rectangle again only when this moved. 0 for NULL or an id out of range. */
LMGI_API uint32_t lmgi_surface_version(const lmgi_updater *u, int surface);
/* The rectangle an engine uploads again when the surface's version moved: its texels' rectangle grown
 * by the texels around it that bilinear filtering reads (gutters dilated from it: max(gutter, 2)
 * texels), clipped to the atlas. Returns 0 (rect zeroed) as lmgi_surface_rect does. */
LMGI_API int lmgi_surface_lightmap_rect(const lmgi_scene *scene, int surface, int rect[4]);
/* lmgi_get_lightmap's values in the atlas rectangle rect = {x, y, width, height} alone, bit for bit:
 * rgba holds width x height RGBA floats, row 0 at rect's y (glTexSubImage2D at x, y). The IIM is read
 * back and its invalid texels filled only around the rectangle (its surfaces' rectangles), the AIM's
 * gutters dilated there alone; the error and accuracy estimates are made whole and cut. NULL u, rect or
 * rgba, a rectangle not inside the atlas, rgba too small (floats < 4 x width x height) or an unknown
 * kind: LMGI_ERR_INVALID; a value that is not finite: LMGI_ERR_BACKEND. docs/api.md, "Lightmaps to an
 * engine", has the upload loop and its cost against the whole read. Thread-safety: as the updater's. */
LMGI_API lmgi_status lmgi_get_lightmap_rect(lmgi_updater *u, lmgi_lightmap kind, const int rect[4], float *rgba,
                                            size_t floats, lmgi_error *err);
/* One page of the lightmap: lmgi_get_lightmap_rect over lmgi_page_rect(page), so its values are the whole
 * read's in that rectangle, bit for bit; rgba holds page_width x page_height RGBA floats, row 0 at v = 0
 * of the page's UVs (lmgi_triangle_lightmap_page). A page out of range: LMGI_ERR_INVALID naming it; the
 * rest as lmgi_get_lightmap_rect. */
LMGI_API lmgi_status lmgi_get_lightmap_page(lmgi_updater *u, lmgi_lightmap kind, int page, float *rgba,
                                            size_t floats, lmgi_error *err);
/* The displayed IIM lightmap as an OpenGL texture (docs/api.md, "The lightmap as a GL texture"): a
 * GL_TEXTURE_2D name of lmgi's context, atlas-sized, GL_RGBA32F, one level, bilinear, clamped to the edge,
 * holding what lmgi_get_lightmap(LMGI_LIGHTMAP_IIM) gives, bit for bit (row 0 at t = 0: sample it at the
 * lightmap's UVs as they are). Each call brings it up to date: the first uploads the whole atlas, later ones
 * only the rectangles (lmgi_surface_lightmap_rect) of the surfaces whose lmgi_surface_version moved since,
 * and it returns once the upload is finished (glFinish), so a context sharing with lmgi's may sample it at
 * once. The name is the same for the updater's life; lmgi deletes it in lmgi_updater_free; the host must
 * not change or delete it. A host sees it only in a context that shares with lmgi's
 * (lmgi_context_desc.share_context). NULL u or texture: LMGI_ERR_INVALID; a lightmap with a NaN: as
 * lmgi_get_lightmap. *texture is 0 on any error. */
LMGI_API lmgi_status lmgi_get_lightmap_texture(lmgi_updater *u, unsigned *texture, lmgi_error *err);

/* LMGI_VERSION as the library was compiled: a program that loads liblmgi.so at run time compares it with
 * the LMGI_VERSION it was compiled against (a library older than the header may lack what the program
 * calls; docs/api.md, "Versions"). */
LMGI_API int lmgi_version(void);
LMGI_API const char *lmgi_status_name(lmgi_status s);
/* What lmgi prints on stderr: 0 errors only, 1 also warnings (default), 2 also progress, 3 debug. */
LMGI_API void lmgi_set_verbosity(int level);

#ifdef __cplusplus
}
#endif

#endif
