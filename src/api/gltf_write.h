/* glTF 2.0 written in memory, for the two places the API makes glTF: lmgi_load_desc (an application's
 * arrays as a .glb for the loader) and lmgi_export_gltf (a .gltf and its .bin for engines).
 *
 * A document is a JSON text the caller writes its objects into (`json`, leading commas: start with
 * "{\"asset\":...}" and every later key with ','), and one binary buffer that lm_gltf_accessor appends
 * to, 4-byte aligned, each array its own buffer view and accessor. lm_gltf_finish appends the buffer, the
 * views and the accessors; the caller closes the object with '}' and takes lm_gltf_text and lm_gltf_bin.
 * Numbers are written with 9 significant digits (floats round-trip). Out of memory: the streams stop
 * growing and lm_gltf_text returns NULL. Not thread-safe (one document per thread). */
#ifndef LM_GLTF_WRITE_H
#define LM_GLTF_WRITE_H

#include <stdint.h>
#include <stdio.h>

typedef struct {
    FILE *json;             /* the document's text: the caller's objects go here */
    int views, accessors;   /* written so far */
    size_t bin_len;         /* bytes in the binary buffer so far */
    /* the streams behind them (open_memstream) */
    FILE *views_f, *accessors_f, *bin_f;
    char *json_text, *views_text, *accessors_text, *bin_data;
    size_t json_size, views_size, accessors_size, bin_size;
} lm_gltf_doc;

/* Opens the streams; 0 when out of memory (then lm_gltf_close is still safe). */
int lm_gltf_open(lm_gltf_doc *d);
void lm_gltf_close(lm_gltf_doc *d);

/* An accessor over a new view holding `count` elements: `comps` floats each (2: VEC2, 3: VEC3; with
 * bounds, the min and max glTF requires of POSITION) or, comps 0, uint32 indices. Returns its index. */
int lm_gltf_accessor(lm_gltf_doc *d, const void *data, uint32_t count, int comps, int bounds);

/* A JSON string (quotes, backslashes and control characters escaped), and an array of floats. */
void lm_gltf_string(FILE *f, const char *s);
void lm_gltf_floats(FILE *f, const float *v, int n);
/* ,"emissiveFactor":[...] for an emitted radiance e: the factor is at most 1 per channel, so e is split
 * into factor x strength. Returns the strength for KHR_materials_emissive_strength (above 1), or 0 when
 * the factor says it all. */
float lm_gltf_emissive(FILE *f, const float e[3]);
/* A KHR_lights_punctual light object (name NULL: none; type 0 point, 1 spot, 2 directional; range <= 0:
 * infinite, none written; cones for spots). */
void lm_gltf_light(FILE *f, const char *name, int type, const float color[3], float intensity, float range,
                   float inner_cone, float outer_cone);

/* Appends ,"buffers":[{"uri":bin_uri (NULL: none, a GLB's own),"byteLength":...}],"bufferViews":[...],
 * "accessors":[...] to the JSON. */
void lm_gltf_finish(lm_gltf_doc *d, const char *bin_uri);
/* The JSON text and the binary buffer once finished and closed with '}' (flushes); NULL when a stream
 * ran out of memory. Valid until lm_gltf_close. */
const char *lm_gltf_text(lm_gltf_doc *d, size_t *len);
const void *lm_gltf_bin(lm_gltf_doc *d, size_t *len);

#endif
