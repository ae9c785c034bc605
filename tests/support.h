/* Helpers shared by the tests: where the shared and generated scenes are, and skipping when absent. */
#ifndef LM_TEST_SUPPORT_H
#define LM_TEST_SUPPORT_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

/* Path of a file under ../shared/scenes (or $LMGI_SHARED/scenes); NULL if it does not exist.
 * The returned string is static storage, valid until the next call. */
const char *lmt_shared_scene(const char *relative);
/* Path of a file under the project's scenes/ (generated scenes); NULL if missing. */
const char *lmt_project_scene(const char *relative);
/* Runs only the tests whose names match $LMT_FILTER (cmocka's wildcards), when it is set: one case of a
 * long binary while working on it, e.g. LMT_FILTER=test_command_help. Call before running the group. */
void lmt_filter_from_env(void);
/* A fresh empty temporary directory for the calling test (static storage). */
const char *lmt_tmpdir(void);
/* The folder this program keeps its references in (lmgi_reference_desc.cache_dir, lm_ref_settings.cache_dir):
 * made at the first call and the same for every later one, removed at exit. A test reuses a reference
 * solved earlier in the same run, never one an earlier run left in build/reference-cache. */
const char *lmt_reference_cache(void);
/* The whole file in a malloc'd buffer with `extra` spare bytes after it (for mutations); *size its
 * length. Fails the test when it cannot be read. */
unsigned char *lmt_read_file(const char *path, size_t *size, size_t extra);
/* xorshift32: the next number of the fixed sequence *state (non-zero) steps through. */
uint32_t lmt_xorshift(uint32_t *state);
/* Writes n bytes to path; fails the test when it cannot. */
void lmt_write_file(const char *path, const void *data, size_t n);
/* Base64 of n bytes into out, which holds 4 * ceil(n / 3) + 1 chars (NUL-terminated). */
void lmt_base64(const void *data, size_t n, char *out);
/* Processes of a shared bake played by threads: an allgather over a barrier (lmgi_updater_desc's
 * photon_exchange, lm_photon_split's exchange). Initialise with lmt_hub_init for n threads (at most 8). */
typedef struct {
    pthread_barrier_t barrier;
    int n;
    const void *mine[8];
    size_t size[8];
    int calls[8];                /* exchange calls each thread made */
} lmt_hub;
void lmt_hub_init(lmt_hub *h, int n);
void lmt_hub_free(lmt_hub *h);
/* Thread `id`'s part of the collective exchange: with all NULL, every thread's size into sizes; else
 * every thread's bytes back to back into all. Returns 1. */
int lmt_hub_exchange(lmt_hub *h, int id, const void *mine, size_t size, size_t *sizes, void *all);
/* Runs `SHELL_PREFIX BUILD/lmgi ARGS 2>&1` (BUILD: $LMGI_BUILD, else build) with stdout and stderr together
 * into output (size bytes, NUL-terminated); asserts it exited rather than crashed and returns its exit
 * status. */
int lmt_lmgi(const char *shell_prefix, const char *args, char *output, size_t size);
/* Runs a shell command (its stdout into output, the rest read and dropped); returns its exit status (the
 * test fails if it did not exit, e.g. crashed). */
int lmt_run(const char *cmd, char *output, size_t size);
/* The node packages' folder, absolute (make test installs them into build/npm, or $LMGI_NPM), or NULL with
 * *why saying what is missing (node, or the package). */
const char *lmt_node_modules(const char *package, const char **why);
/* The Khronos glTF validator (tests/engines/validate.mjs) over a .gltf and the files it names: 0 errors, or
 * the test fails with its report, which is printed either way. */
void lmt_gltf_validate(const char *node_modules, const char *gltf);

/* Use in a cmocka test: skips (and says so) when the scene is not there. */
/* LMT_UNDER_ASAN: 1 in a test built with AddressSanitizer (make test-asan), else 0. */
#if defined(__SANITIZE_ADDRESS__)
#define LMT_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LMT_UNDER_ASAN 1
#endif
#endif
#ifndef LMT_UNDER_ASAN
#define LMT_UNDER_ASAN 0
#endif

#define LMT_REQUIRE_SCENE(var, path_expr)                                                     \
    const char *var = (path_expr);                                                              \
    do {                                                                                        \
        if (!var) {                                                                             \
            print_message("skipped: scene not found (%s)\n", #path_expr);                       \
            skip();                                                                             \
        }                                                                                       \
    } while (0)


/* The internal pipeline for one scene file: scene, surfaces, atlas, BVH and emitters. */
#include "../src/charts/charts.h"
#include "../src/trace/lights.h"
#include "../src/trace/rt_scene.h"
#include "../src/update/world.h"

typedef struct {
    lm_scene *s;
    lm_surfaces su;
    lm_atlas atlas;
    lm_rt *rt;
    lm_emitters em;
    lm_world w;    /* s, su, atlas and rt for the runtime */
} lmt_pipeline;

/* Loads `path` with default options but the given texel size (0 = default); fails the test on error. */
void lmt_pipeline_load(lmt_pipeline *p, const char *path, float texel_size);
void lmt_pipeline_free(lmt_pipeline *p);

/* Reference texels for a loaded pipeline at a relative standard error target, uncached and quiet
 * (a test must not depend on a cache a previous run left); fails the test on error. */
#include "../src/reference/reference.h"
void lmt_reference_texels(const lmt_pipeline *p, float target_error, lm_ref_result *out);

/* cmocka group fixtures for tests that render: one GL context, current for the whole group. */
int lmt_gl_setup(void **state);
int lmt_gl_teardown(void **state);

/* A 20 x 20 plane (y = 0, facing up, default 0.8 grey material) under a point light of intensity 10 at
 * height 2, written to a fresh temporary directory; returns its path (static storage). */
const char *lmt_plane_scene(void);
/* The same plane under one light at (0, 2, 0) given as KHR_lights_punctual JSON (its node turns nothing:
 * a spot shines down -Z). */
const char *lmt_plane_scene_with(const char *light);


/* Material and light JSON for lmt_write_scene's materials text: a grey diffuse material, a mirror of albedo
 * r, clear glass (ior 1.5), and the extensions' declarations with a list of KHR_lights_punctual lights
 * (each a JSON object). */
#define LMT_LIGHTS(json) \
    "\"extensionsUsed\": [\"KHR_lights_punctual\", \"KHR_materials_transmission\", \"KHR_materials_ior\"], " \
    "\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [" json "]}}"
#define LMT_DIFFUSE(g) "{\"pbrMetallicRoughness\": {\"baseColorFactor\": [" #g ", " #g ", " #g ", 1], \"metallicFactor\": 0}}"
#define LMT_MIRROR(r) "{\"pbrMetallicRoughness\": {\"baseColorFactor\": [" #r ", " #r ", " #r ", 1], \"metallicFactor\": 1, " \
                      "\"roughnessFactor\": 0}}"
#define LMT_GLASS "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0}, \"extensions\": {\"KHR_materials_transmission\": " \
                  "{\"transmissionFactor\": 1}, \"KHR_materials_ior\": {\"ior\": 1.5}}}"

/* The caustic tests' mirror scene: an 8 x 8 m diffuse floor (y = 0, albedo 0.8), a vertical 0.5 m square
 * mirror (albedo 0.9) at x = 1 facing -x (y in [0.75, 1.25], z in [-0.25, 0.25]), a point light of 10 cd
 * at (0, 2, 0); `cube_extras`: a 0.2 m diffuse cube at (-2, 0.2, -2) with these node extras (NULL: no
 * cube; it is named "cube"); `mirror_extras` on the mirror's node; last, a camera 4 m above (-0.15, 0, 0) looking straight down
 * (60 degrees). Written to lmt_tmpdir()/name; returns its path. */
const char *lmt_mirror_scene(const char *name, const char *mirror_extras, const char *cube_extras);
/* The image of that light in that mirror: the irradiance F I cos / d^2 from the virtual light (2, 2, 0) at
 * floor point (x, 0, z), F the mirror's reflectance where that light meets it, and whether the line to it
 * passes through the mirror (*inside). */
double lmt_mirror_image(double x, double z, int *inside);
/* A metal's Fresnel reflectance (Schlick's, F0 the albedo) at 1 - cos. */
double lmt_mirror_fresnel(double albedo, double one_minus_cos);

#endif


/* A tiny mesh for hand-written test scenes: positions (3 floats each) and u16 triangle indices. */
typedef struct {
    int vertex_count, index_count;
    float pos[64 * 3];
    uint16_t idx[64 * 3];
} lmt_mesh;

void lmt_mesh_quad(lmt_mesh *m, const float corner[3], const float edge_u[3], const float edge_v[3]);
/* Axis-aligned cube of half-size h centred at the origin, 6 faces, outward winding. */
void lmt_mesh_cube(lmt_mesh *m, float h);
/* The same cube seen from inside: winding turned so every face points inwards (a closed room). */
void lmt_mesh_cube_inward(lmt_mesh *m, float h);
/* A spherical cap around +y of half-angle alpha (radians) on the sphere of radius r centred at (0, cy, 0):
 * its top, two rings of 16 vertices, 48 triangles facing out. glTF gives it flat normals; a test that
 * wants the sphere's sets them after loading. */
void lmt_mesh_cap(lmt_mesh *m, double alpha, double r, double cy);

/* Writes a .gltf at `path` with one buffer (base64 data URI) holding the meshes, and one mesh per
 * entry. `nodes_json` is the JSON array of nodes (mesh i = meshes[i]); `extra_json` is inserted at the
 * top level (e.g. "\"animations\": [...]," — may reference accessors from `extra_accessors`, which are
 * appended as raw float data after the meshes: each entry is a float array with count and type).
 * Returns 0 on success. */
typedef struct {
    const float *data;
    int count;          /* elements */
    const char *type;   /* "SCALAR", "VEC3", "VEC4" */
} lmt_accessor;
int lmt_write_gltf(const char *path, const lmt_mesh *meshes, int mesh_count, const char *nodes_json,
                   const lmt_accessor *extra, int extra_count, const char *extra_json);
/* Writes meshes[0, count) to lmt_tmpdir()/name with mesh i using material i (materials: the JSON text of
 * the "materials" array; nodes: of the "nodes" array); returns the path (static storage). */
const char *lmt_write_scene(const char *name, const lmt_mesh *meshes, int count, const char *nodes,
                            const char *materials);
/* Gives every primitive of a file lmt_write_gltf wrote material 0 (it writes none), rewriting its text. */
void lmt_use_material_0(const char *path);
