/* The scene model: what a glTF file becomes inside lmgi.
 *
 * Geometry is flattened per node: every node that references a mesh gets its own copy of that mesh's
 * triangle primitives (a lightmap needs unique texels per instance anyway). Vertex positions and normals
 * are kept in the node's local (object) space; a node's world matrix places them. Static and dynamic
 * nodes are stored alike; `dynamic` says whether the node may move (lmgi extras, or animated).
 *
 * Units are the file's own (glTF metres, but lmgi never assumes a scale). Colours are linear RGB. */
#ifndef LM_SCENE_H
#define LM_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "../core/error.h"
#include "../core/vecmath.h"

#define LM_NAME_MAX 64

/* Material classes for light transport (docs/materials.md gives the rule; lm_material_classify applies it). */
typedef enum {
    LM_MAT_DIFFUSE = 0,
    LM_MAT_GLOSSY,
    LM_MAT_MIRROR,
    LM_MAT_GLASS,
    LM_MAT_EMITTER,
    LM_MAT_CLASS_COUNT
} lm_material_class;

typedef struct {
    int width, height;
    float *rgba; /* linear RGBA, row 0 at the top (v = 0), width*height*4 floats */
} lm_texture;

typedef struct {
    char name[LM_NAME_MAX];
    float base_color[4];   /* linear RGBA factor */
    int base_color_tex;    /* index into lm_scene.textures, -1 if none */
    int base_color_uv;     /* which TEXCOORD set the texture uses (0 or 1) */
    float uv_offset[2], uv_scale[2], uv_rotation; /* KHR_texture_transform of the base colour texture */
    float metallic, roughness;
    float emissive[3];     /* emissiveFactor x KHR_materials_emissive_strength: emitted radiance */
    int emissive_tex;      /* -1 if none */
    int missing_textures;  /* textures the file names for it that could not be found or decoded (it uses
                            * its factors instead; lmgi info says so) */
    float transmission;    /* KHR_materials_transmission factor */
    float ior;             /* KHR_materials_ior (1.5 when absent) */
    int double_sided;      /* both sides lit alike by one triangle: after loading, only mirror and glass;
                            * other double-sided materials have their sides split (split_sides) */
    int split_sides;       /* double-sided in the file, not specular: each of its triangles has a twin
                            * facing the other way (lm_scene.tri_twin), and both are single-sided */
    lm_material_class cls;
    int lightmapped;       /* its triangles got lightmap texels at load (it was not mirror or glass then):
                            * what an edit of its class may rely on */
} lm_material;

typedef enum { LM_LIGHT_POINT = 0, LM_LIGHT_SPOT, LM_LIGHT_DIRECTIONAL } lm_light_type;

typedef enum { LM_SKY_UNIFORM = 0, LM_SKY_GRADIENT, LM_SKY_IMAGE } lm_sky_kind;

typedef struct {
    char name[LM_NAME_MAX];
    lm_light_type type;
    float color[3];
    float intensity;       /* candela (point/spot) or lux (directional), as in the file */
    float range;           /* 0 = infinite */
    float inner_cone, outer_cone; /* spot only, radians */
    int node;              /* node that places it; light shines down the node's local -Z. -1 for a light
                            * added after load (added): pos and dir place it */
    float pos[3], dir[3];  /* an added light's world position and unit direction (unused otherwise) */
    int off;               /* switched off by an edit: emits nothing, keeps its colour and intensity */
    int added;             /* added by an edit after load: its emitter follows the area emitters, so that
                            * the photon ids of the lights before it do not move (lights.c) */
    int removed;           /* removed by an edit: emits nothing and is never on again; its id stays taken
                            * (ids are not reused, so a caller's handle to another light stays good) */
} lm_light;

typedef struct {
    char name[LM_NAME_MAX];
    int perspective;       /* 1 perspective, 0 orthographic */
    float yfov, aspect;    /* aspect 0 = use the image's */
    float znear, zfar;     /* zfar 0 = infinite */
    float xmag, ymag;      /* orthographic */
    int node;
} lm_camera;

/* Portal triangles a scene may have: each photon of the sun and the sky tests them all. */
#define LM_MAX_PORTAL_TRIS 256

/* Per-node lmgi settings from glTF node extras {"lmgi": {...}}. Switches are -1 (unset: inherit from
 * the parent, else on), 0 (off) or 1 (on). */
typedef struct {
    int dynamic;           /* extras "dynamic": true */
    int caustics;          /* extras "caustics" */
    int indirect;          /* extras "indirect" */
    int shadows;           /* extras "shadows" (or "casts_shadows") */
    int reflections;       /* extras "reflections": a mirror or glossy node gets an environment map */
    int portal;            /* extras "portal": its mesh marks an opening (a window) that the sun's and the
                            * sky's photons are aimed through, and is no geometry (not inherited) */
    int has_reflection_box; /* extras "reflection_box": its environment map is looked up box-projected */
    float reflection_box[6]; /* that box, world space: min x, y, z, max x, y, z (not inherited) */
} lm_node_settings;

typedef struct {
    char name[LM_NAME_MAX];
    int parent;            /* -1 for roots */
    float translation[3], rotation[4], scale[3]; /* local TRS (rotation x, y, z, w) */
    float matrix[16];      /* local matrix when the node gave one (has_matrix), else derived from TRS */
    int has_matrix;
    float world[16];       /* world matrix, kept current by lm_scene_update_world */
    int mesh;              /* glTF mesh index, -1 if none */
    int camera, light;     /* -1 if none */
    int dynamic;           /* may move: extras dynamic, or targeted by an animation */
    lm_node_settings settings; /* resolved: inherited switches already applied (never -1 after load) */
    uint32_t first_tri, tri_count; /* this node's triangles in lm_scene.tris: the file's first, then the
                                    * twins of those with split sides (front_tri_count of them are the file's) */
    uint32_t front_tri_count;
    int mirrored;          /* its world matrix mirrors (negative determinant) at load: the loader reversed
                            * its triangles' winding, as glTF asks, so that every later stage finds the
                            * front where the file meant it. Edits keep the sign (lm_rt_set_node_transform) */
    int edited;            /* placed by an edit (lm_scene_set_node_world): its animation channels no longer
                            * drive it, so that playing time does not undo what a user did */
} lm_node;

typedef enum { LM_INTERP_LINEAR = 0, LM_INTERP_STEP, LM_INTERP_CUBIC } lm_interp;
typedef enum { LM_PATH_TRANSLATION = 0, LM_PATH_ROTATION, LM_PATH_SCALE } lm_anim_path;

typedef struct {
    int node;
    lm_anim_path path;
    lm_interp interp;
    int key_count;
    float *times;          /* key_count, ascending */
    float *values;         /* key_count * comps, or key_count * 3 * comps for cubic (in-tangent, value, out-tangent) */
    int comps;             /* 3 or 4 */
} lm_anim_channel;

typedef struct {
    char name[LM_NAME_MAX];
    int channel_count;
    lm_anim_channel *channels;
    float duration;        /* last key time over all channels */
} lm_animation;

typedef struct {
    char path[1024];       /* the file it came from */

    int node_count;
    lm_node *nodes;
    int material_count;
    lm_material *materials;
    uint32_t material_version; /* counts material edits: what copied materials (the GPU's) compare with */
    uint32_t pass_version;   /* counts edits that change which passes a node takes part in and how (static
                              * or dynamic, a material's class, a node's effect switches): what the render
                              * passes built on them (the direct pass's casters, the reflection maps)
                              * compare with */
    int texture_count;
    lm_texture *textures;
    int light_count;
    lm_light *lights;
    int camera_count;
    lm_camera *cameras;
    int animation_count;
    lm_animation *animations;

    /* Vertices, in their node's local space. uv1 is NULL when no primitive had TEXCOORD_1; when some
     * had it, vertices of the others get (0, 0). */
    uint32_t vertex_count;
    float *positions;      /* 3 per vertex */
    float *normals;        /* 3 per vertex (generated from faces when the file has none) */
    float *uv0;            /* 2 per vertex (0,0 when absent) */
    float *uv1;            /* 2 per vertex or NULL */
    uint32_t *vertex_node; /* node index per vertex */

    /* Triangles. Each node's triangles are contiguous (lm_node.first_tri). */
    uint32_t tri_count;
    uint32_t *tris;        /* 3 vertex indices per triangle */
    int *tri_material;     /* material index per triangle (a default material is appended when needed) */
    uint32_t *tri_node;    /* node index per triangle */
    /* Two sides (DESIGN.md "Surfaces have two sides"): per triangle, the triangle on the same corners wound
     * the other way, with its own vertices (normals negated) and the same material, or -1. A file's
     * triangle comes before its twin. NULL when no material was split. Each side is then an ordinary
     * single-sided triangle: its own surface, chart, photons, AIM and IIM, lit only from its front. */
    int32_t *tri_twin;
    uint32_t file_tri_count; /* triangles in the file (tri_count less the twins) */

    /* The sky: the environment around the scene, radiance by direction in linear RGB (docs/levels.md,
     * "Sky"; sky.h). It lights through photons (lm_emitters' SKY emitter), the gather (what a texel's
     * hemisphere sees of it), the frame's background and reflections, and the reference (rays that leave
     * the scene). sky: the uniform sky's radiance, the gradient's at the zenith, the image's scale.
     * has_sky: the scene has one, even if it is dark now (set once: the emitter then stays, so a sky
     * dimmed to 0 and back is an edit like a light's). */
    float sky[3];
    int has_sky;
    lm_sky_kind sky_kind;
    float sky_horizon[3];  /* LM_SKY_GRADIENT: the radiance at and below the horizon */
    int sky_width, sky_height; /* LM_SKY_IMAGE: an equirectangular image, row 0 at the zenith, the middle
                                * column towards -z, +x three quarters across (sky.h) */
    float *sky_image;      /* sky_width x sky_height x 3 floats, times sky[]; then, in the same block, the
                            * running sums lm_sky_sample draws directions by (scene/sky.c) */
    float sky_image_mean[3]; /* its mean over the sphere (solid-angle weighted), made as it is loaded */

    /* Portals (docs/levels.md, "Portals"): the triangles of the nodes tagged extras.lmgi.portal, world
     * space, 9 floats each (at most LM_MAX_PORTAL_TRIS), not in tris: openings that the sun's and the
     * sky's photons are aimed through (trace/lights.c). A portal's front (counter-clockwise) faces the
     * outside, where the light comes from. */
    float *portal_tris;
    uint32_t portal_tri_count;

    int mesh_count;        /* number of glTF meshes (for reporting) */
    float bounds_min[3], bounds_max[3]; /* world-space bounds at load time (all nodes) */
    /* lm_scene_update_bounds' cache: per node the world min and max of its triangles' corners and the world
     * matrix they were made with (LM_NODE_BOUNDS floats), valid for the triangles of bounds_tris (NULL: none
     * made yet); freed with the scene */
    float *node_bounds;
    const uint32_t *bounds_tris;
    float origin[3];       /* where lmgi's world origin lies in the file's world: a scene that sits farther
                            * from the file's origin than 256 times its size is rebased at load (its root nodes
                            * moved by -origin) so that float rays, matrices and depths keep their digits;
                            * the public API adds it back (positions out) and takes it off (positions in) */
} lm_scene;

typedef struct {
    int strict;            /* degenerate triangles and non-finite data become errors, not warnings */
    const void *data;      /* non-NULL: the .gltf or .glb's bytes in memory (`path` then only names it in
                            * messages, and the scene may not name external files: data: URIs or the GLB's
                            * own buffer only) */
    size_t size;
    int untrusted;         /* files the scene names must lie inside its folder (after "..", percent-encoding
                            * and symbolic links): another is refused, naming it; trusted (0), one outside is
                            * read with a warning that says so */
} lm_load_options;

/* Loads a .gltf or .glb file. On failure returns the status, fills err with a message that names the
 * file and the problem, and leaves *out NULL. Implemented in gltf_loader.cpp. */
lm_status lm_scene_load_gltf(const char *path, const lm_load_options *opt, lm_scene **out, lm_error *err);
void lm_scene_free(lm_scene *s);

/* Gives every triangle of a double-sided, non-specular material a twin facing the other way and makes
 * the material single-sided (split_sides): called once by the loader, after the nodes are finished. */
lm_status lm_scene_split_sides(lm_scene *s, lm_error *err);
/* A node's triangles as the file has them (its first ones; the rest are their twins). */
static inline uint32_t lm_node_file_tris(const lm_scene *s, const lm_node *n)
{
    return s->tri_twin ? n->front_tri_count : n->tri_count;
}
/* 1 for a node with triangles of its own that may move: the BVH instances it apart, the photons' round
 * robin watches it, lmgi info counts it among the dynamic. */
static inline int lm_node_moves(const lm_node *n) { return n->dynamic && n->tri_count > 0; }
/* 1 when some node may move (lm_node_moves): else the photons' round robin has nothing to find (lmgi
 * info's "photon updates: off"). O(nodes); lmgi_set_node_dynamic can change it between updates. */
static inline int lm_scene_any_node_moves(const lm_scene *s)
{
    for (int n = 0; n < s->node_count; n++)
        if (lm_node_moves(&s->nodes[n]))
            return 1;
    return 0;
}
/* 1 when triangle t is the twin (the back side) of a file's triangle. */
static inline int lm_tri_is_back(const lm_scene *s, uint32_t t)
{
    return s->tri_twin && s->tri_twin[t] >= 0 && (uint32_t)s->tri_twin[t] < t;
}

/* Recomputes every node's world matrix from local transforms (parents before children), O(nodes). */
void lm_scene_update_world(lm_scene *s);
/* Node indices with every parent before its children, O(nodes) whatever the depth (caller frees); NULL
 * when out of memory. *cycle: -1, or a node on a cycle of the parent links (the order is then partial). */
int *lm_scene_parents_first(const lm_scene *s, int *cycle);
/* Sets the local TRS of every node that animation `anim` targets to its value at time t (seconds;
 * clamped to the animation's range), then updates world matrices. anim < 0 evaluates all animations. */
void lm_scene_eval_animation(lm_scene *s, int anim, float t);
/* An edit: places `node` at `world` (its local matrix becomes the parent's inverse times world, so its
 * children follow) and marks it edited, so animations leave it alone until lm_scene_release_node. Returns
 * 0, changing nothing, when the parent's world matrix has no inverse. */
int lm_scene_set_node_world(lm_scene *s, int node, const float world[16]);
/* 1 when `node` is `ancestor` or lies under it. */
int lm_node_under(const lm_scene *s, int node, int ancestor);
/* 1 when an animation channel drives `node` or a node under it. */
int lm_node_animated_under(const lm_scene *s, int node);
/* Makes `node` and every node under it dynamic (1) or static (0), where they are now, and counts the
 * switch in pass_version. The caller checks that it may (no animated node goes static, no node under a
 * dynamic parent) and rebuilds what is built on the split (lm_rt_rebuild). */
void lm_scene_set_dynamic(lm_scene *s, int node, int dynamic);
/* Hands an edited node back to its animations (from the next lm_scene_eval_animation on). */
void lm_scene_release_node(lm_scene *s, int node);
/* The value (not a tangent) of key k of a channel: comps floats. */
float *lm_anim_key_value(const lm_anim_channel *c, int k);
/* Duration of the longest animation (0 if none). */
float lm_scene_animation_duration(const lm_scene *s);

/* The largest |coordinate| a vertex may have in world space after loading (a load error beyond it):
 * rays must stay far inside Embree's limit of about 1.8e18, and texel sizes and scene sizes finite. */
#define LM_MAX_COORDINATE 1e15f
/* An animation's translation and scale keys at most (the loader's rule): with them a node's vertices stay
 * within LM_MAX_COORDINATE for any local coordinate under 5e8. */
#define LM_MAX_ANIM_TRANSLATION 5e14f
#define LM_MAX_ANIM_SCALE 1e6f
/* The largest light colour x intensity or material emission (a load error beyond it): a photon's power is
 * that times 4 pi or an area, summed over bounces and texels in float; 1e38 overflowed to infinity and
 * asked for 77 billion photons. The brightest real light (the sun, about 1e5 lux) is far below. */
#define LM_MAX_EMISSION 1e20
/* KHR_texture_transform's offset and scale at most: a million repeats of a texture is past any real use,
 * and 3e38 made every lookup infinite (an 81% NaN frame). */
#define LM_MAX_UV_TRANSFORM 1e6f

/* World-space position of a vertex / normal under the current node matrices. */
void lm_scene_vertex_world(const lm_scene *s, uint32_t v, float out[3]);
void lm_scene_normal_world(const lm_scene *s, uint32_t v, float out[3]);
/* Geometric (face) normal, unit and as wound (zero for a degenerate triangle), and area of a triangle in
 * world space. */
lm_vec3 lm_scene_tri_normal_world(const lm_scene *s, uint32_t t);
float lm_scene_tri_area_world(const lm_scene *s, uint32_t t);
/* Length of the world bounds' diagonal: the scene's size, used for relative tolerances. */
float lm_scene_size(const lm_scene *s);
/* How far a shadow ray leaves a surface: 1e-5 of the scene's size (of 1 for an empty or unbounded one). */
float lm_scene_ray_lift(const lm_scene *s);
/* A hash (core/hash.h) of every node's world matrix: what changes when anything moves. */
uint64_t lm_scene_world_hash(const lm_scene *s);
/* Recomputes bounds_min/max from the current world matrices. With the cache (lm_scene_keep_bounds) only
 * the corners of the triangles of the nodes whose matrix changed since the last call are transformed again,
 * the other nodes' bounds kept: an update of the still shared room spent 2 ms here transforming every
 * corner. The same bounds, to the bit, as transforming them all, which it does without the cache. */
void lm_scene_update_bounds(lm_scene *s);
/* Makes (again) lm_scene_update_bounds' cache, LM_NODE_BOUNDS floats a node (none without memory: every
 * corner each time); the scene's node count must not change after. */
#define LM_NODE_BOUNDS 22
void lm_scene_keep_bounds(lm_scene *s);
/* Every node's box of its own triangles' corners in its local space, 6 floats a node into out (min x, y, z,
 * max x, y, z; min > max for a node without triangles). O(triangles). */
void lm_scene_node_local_boxes(const lm_scene *s, float *out);

/* Mirror and glass: light leaves them in one direction; they store no photon and get no lightmap texels. */
static inline int lm_material_is_specular(lm_material_class c) { return c == LM_MAT_MIRROR || c == LM_MAT_GLASS; }
/* Mirror, glossy and glass: the classes whose reflections of the scene the frame draws (gpu/frame/reflections.h). */
static inline int lm_material_reflects(lm_material_class c) { return lm_material_is_specular(c) || c == LM_MAT_GLOSSY; }
/* Applies the material class rule to m's parameters (sets m->cls and returns it). */
lm_material_class lm_material_classify(lm_material *m);
const char *lm_material_class_name(lm_material_class c);
/* Albedo at texture coordinate (u, v) of the base colour texture (with its transform), times the factor. */
void lm_material_albedo(const lm_scene *s, const lm_material *m, float u, float v, float out[3]);
/* The two lobes of m's class for a given albedo (docs/materials.md, bsdf.c): kd the diffuse
 * reflectance (the whole albedo for diffuse and emitters; albedo (1 - metallic)(1 - max ks) for glossy;
 * 0 for mirror and glass) and ks the glossy lobe's (mix(0.04, albedo, metallic) for glossy, else 0).
 * kd is what a lightmap's irradiance turns into view-independent radiance, kd / pi x E. */
void lm_material_lobes(const lm_material *m, const float albedo[3], float kd[3], float ks[3]);

const char *lm_light_type_name(lm_light_type t);
/* Where a light is now (lmgi's world) and the unit direction it shines: its node's origin and -Z under
 * the node's world matrix, or an added light's own pos and dir. */
void lm_light_place(const lm_scene *s, const lm_light *l, float pos[3], float dir[3]);
/* The one rule for a light's parameters, at load and at every edit, so a light that loads can always be
 * set again with its own values: colour in [0, 1000] (glTF: [0, 1]; brighter colours kept for engines
 * that write them), intensity and range in [0, 1e15] (range 0: unbounded), colour x intensity at most
 * LM_MAX_EMISSION (which the two bounds already keep: a guard), and for a spot 0 <= inner <= outer <= pi/2 with outer > 0 (inner = outer, as Blender
 * writes a hard-edged spot, is a hard edge). LM_ERR_INVALID naming `what` and the parameter. */
/* Whether every node (its place: a light's or camera's) and vertex under `node` (-1: the whole scene)
 * lies within LM_MAX_COORDINATE, where the node is now; LM_ERR_INVALID naming the first that does not.
 * O(nodes x depth + vertices), one test a vertex. */
lm_status lm_scene_check_extent(const lm_scene *s, int node, lm_error *err);
lm_status lm_light_check(const char *what, const float color[3], float intensity, float range, int spot,
                         float inner_cone, float outer_cone, lm_error *err);

#endif
