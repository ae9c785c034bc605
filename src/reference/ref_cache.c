/* Cache keys and files for the reference solver (ref_cache.h). */
#include "ref_cache.h"

#include "../core/hash.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../core/image.h"
#include "../core/log.h"
#include "../scene/sky.h"

#define LM_REF_MAGIC "LMGIREF1"
#define LM_REF_VERSION 4u /* 2: the split by light path (caustic, lost, pixel parts); 3: paths cut; 4: errors pooled */
#define LM_FNV_OFFSET LM_HASH_SEED

/* ---- FNV-1a ---- */

static void fnv(uint64_t *h, const void *data, size_t n) { *h = lm_hash_bytes(*h, data, n); }

static void fnv_u32(uint64_t *h, uint32_t v) { fnv(h, &v, sizeof v); }
static void fnv_f(uint64_t *h, float v) { fnv(h, &v, sizeof v); }

static void hash_material(uint64_t *h, const lm_material *m)
{
    fnv(h, m->base_color, sizeof m->base_color);
    fnv_u32(h, (uint32_t)m->base_color_tex);
    fnv_u32(h, (uint32_t)m->base_color_uv);
    fnv(h, m->uv_offset, sizeof m->uv_offset);
    fnv(h, m->uv_scale, sizeof m->uv_scale);
    fnv_f(h, m->uv_rotation);
    fnv_f(h, m->metallic);
    fnv_f(h, m->roughness);
    fnv(h, m->emissive, sizeof m->emissive);
    fnv_f(h, m->transmission);
    fnv_f(h, m->ior);
    fnv_u32(h, (uint32_t)m->double_sided);
    fnv_u32(h, (uint32_t)m->split_sides);
    fnv_u32(h, (uint32_t)m->cls);
}

static void hash_light(uint64_t *h, const lm_light *l)
{
    fnv_u32(h, (uint32_t)l->type);
    fnv(h, l->color, sizeof l->color);
    fnv_f(h, l->off || l->removed ? 0.0f : l->intensity);
    fnv_f(h, l->range);
    fnv_f(h, l->inner_cone);
    fnv_f(h, l->outer_cone);
    fnv_u32(h, (uint32_t)l->node);
    if (l->node < 0) { /* an added light: its own place */
        fnv(h, l->pos, sizeof l->pos);
        fnv(h, l->dir, sizeof l->dir);
    }
}

static void hash_scene(uint64_t *h, const lm_scene *s)
{
    *h = lm_sky_hash(*h, s);
    size_t nv = s->vertex_count;
    fnv_u32(h, s->vertex_count);
    fnv(h, s->positions, nv * 3 * sizeof(float));
    fnv(h, s->normals, nv * 3 * sizeof(float));
    fnv(h, s->uv0, nv * 2 * sizeof(float));
    if (s->uv1)
        fnv(h, s->uv1, nv * 2 * sizeof(float));
    fnv(h, s->vertex_node, nv * sizeof(uint32_t));
    fnv_u32(h, s->tri_count);
    fnv(h, s->tris, (size_t)s->tri_count * 3 * sizeof(uint32_t));
    fnv(h, s->tri_material, (size_t)s->tri_count * sizeof(int));
    fnv(h, s->tri_node, (size_t)s->tri_count * sizeof(uint32_t));
    for (int i = 0; i < s->node_count; i++)
        fnv(h, s->nodes[i].world, sizeof s->nodes[i].world);
    for (int i = 0; i < s->material_count; i++)
        hash_material(h, &s->materials[i]);
    for (int i = 0; i < s->texture_count; i++) {
        const lm_texture *t = &s->textures[i];
        fnv_u32(h, (uint32_t)t->width);
        fnv_u32(h, (uint32_t)t->height);
        if (t->rgba)
            fnv(h, t->rgba, (size_t)t->width * (size_t)t->height * 4 * sizeof(float));
    }
    for (int i = 0; i < s->light_count; i++)
        hash_light(h, &s->lights[i]);
    fnv(h, s->bounds_min, sizeof s->bounds_min);
    fnv(h, s->bounds_max, sizeof s->bounds_max);
}

static void hash_settings(uint64_t *h, const lm_ref_settings *set)
{
    fnv_f(h, set->target_error);
    fnv_u32(h, (uint32_t)set->samples);
    fnv_u32(h, (uint32_t)set->min_samples);
    fnv_u32(h, (uint32_t)set->max_samples);
    fnv_u32(h, set->seed);
    fnv_u32(h, (uint32_t)set->max_depth);
    fnv_u32(h, (uint32_t)set->rr_depth);
    fnv_u32(h, set->caustic_photons);
}

uint64_t lm_ref_key_texels(const lm_scene *s, const lm_atlas *a, const lm_ref_settings *set)
{
    uint64_t h = LM_FNV_OFFSET;
    fnv_u32(&h, LM_REF_VERSION);
    fnv_u32(&h, LM_REF_KIND_TEXELS);
    hash_scene(&h, s);
    fnv_u32(&h, (uint32_t)a->width);
    fnv_u32(&h, (uint32_t)a->height);
    fnv_f(&h, a->texel_size);
    fnv_u32(&h, a->texel_count);
    for (uint32_t i = 0; i < a->texel_count; i++) { /* field by field: no padding bytes hashed */
        const lm_texel *t = &a->texels[i];
        fnv(&h, t->pos, sizeof t->pos);
        fnv(&h, t->bary, sizeof t->bary);
        fnv(&h, t->normal, sizeof t->normal);
        fnv_u32(&h, (uint32_t)t->x);
        fnv_u32(&h, (uint32_t)t->y);
        fnv_u32(&h, t->tri);
    }
    for (uint32_t i = 0; i < a->footprint_count; i++) { /* none: the key as before footprints */
        const lm_texel *t = &a->footprints[i];
        fnv(&h, t->pos, sizeof t->pos);
        fnv(&h, t->normal, sizeof t->normal);
        fnv_u32(&h, t->tri);
    }
    for (uint32_t i = 0; a->footprint_count && i <= a->texel_count; i++)
        fnv_u32(&h, a->footprint_first[i]);
    hash_settings(&h, set);
    return h;
}

uint64_t lm_ref_key_pixels(const lm_scene *s, const lm_view *cam, const lm_ref_settings *set)
{
    uint64_t h = LM_FNV_OFFSET;
    fnv_u32(&h, LM_REF_VERSION);
    fnv_u32(&h, LM_REF_KIND_PIXELS);
    hash_scene(&h, s);
    fnv(&h, cam->eye, sizeof cam->eye);
    fnv(&h, cam->forward, sizeof cam->forward);
    fnv(&h, cam->up, sizeof cam->up);
    fnv_f(&h, cam->yfov);
    fnv_u32(&h, (uint32_t)cam->width);
    fnv_u32(&h, (uint32_t)cam->height);
    fnv_f(&h, cam->znear);
    hash_settings(&h, set);
    return h;
}

void lm_ref_cache_path(char *buf, size_t size, const lm_ref_settings *set, uint32_t kind, uint64_t key)
{
    const char *dir = set->cache_dir;
    if (!dir || !dir[0])
        dir = getenv("LMGI_CACHE");
    if (!dir || !dir[0])
        dir = "build/reference-cache";
    snprintf(buf, size, "%s/%s-%016llx.lmref", dir, kind == LM_REF_KIND_TEXELS ? "texels" : "pixels",
             (unsigned long long)key);
}

/* ---- file layout ---- */

typedef struct {
    uint32_t version, kind;
    uint64_t key;
    uint32_t count;
    int32_t width, height;
    uint32_t has_texel_arrays, converged;
    uint64_t total_samples;
    double mean_rel_se, max_rel_se, seconds;
    uint64_t caustic_photons;
    double caustic_seconds;
    uint64_t paths_cut;
} file_header;

/* Writes or reads the header fields one by one (no struct padding in the file). */
typedef struct {
    unsigned char *p;
    size_t len, cap, pos;
    int bad;
} buffer;

static void put(buffer *b, const void *d, size_t n)
{
    if (b->bad)
        return;
    if (b->len + n > b->cap) {
        size_t cap = (b->cap ? 2 * b->cap : 4096) + n;
        unsigned char *q = realloc(b->p, cap);
        if (!q) {
            b->bad = 1;
            return;
        }
        b->p = q, b->cap = cap;
    }
    memcpy(b->p + b->len, d, n);
    b->len += n;
}

static void get(buffer *b, void *d, size_t n)
{
    if (b->bad || b->pos + n > b->len) {
        b->bad = 1;
        memset(d, 0, n);
        return;
    }
    memcpy(d, b->p + b->pos, n);
    b->pos += n;
}

#define XFER_FIELDS(op, b, h)                                                                                   \
    do {                                                                                                        \
        op(b, &(h)->version, 4), op(b, &(h)->kind, 4), op(b, &(h)->key, 8), op(b, &(h)->count, 4);              \
        op(b, &(h)->width, 4), op(b, &(h)->height, 4), op(b, &(h)->has_texel_arrays, 4);                        \
        op(b, &(h)->converged, 4), op(b, &(h)->total_samples, 8), op(b, &(h)->mean_rel_se, 8);                  \
        op(b, &(h)->max_rel_se, 8), op(b, &(h)->seconds, 8), op(b, &(h)->caustic_photons, 8);                   \
        op(b, &(h)->caustic_seconds, 8), op(b, &(h)->paths_cut, 8);                                             \
    } while (0)

static void put_arrays(buffer *b, const lm_ref_result *r, int texels)
{
    lm_ref_result view = *r; /* the list points at a result's fields, which it may fill: read through a copy */
    float **arrays[LM_REF_MAX_ARRAYS];
    int n = lm_ref_result_arrays(&view, texels, arrays);
    for (int i = 0; i < n; i++)
        put(b, *arrays[i], (size_t)r->count * 3 * sizeof(float));
    put(b, r->samples, (size_t)r->count * sizeof(uint32_t));
    put(b, r->rel_se, (size_t)r->count * sizeof(float));
}

void lm_ref_cache_store(const char *path, uint32_t kind, const lm_ref_result *r)
{
    char dir[1024], tmp[1100];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    lm_error err;
    if (slash) {
        *slash = '\0';
        if (lm_mkdir_p(dir, &err) != LM_OK) {
            lm_warn("reference cache: %s", err.msg);
            return;
        }
    }
    file_header h = {LM_REF_VERSION, kind, r->key, r->count, r->width, r->height, r->iim != NULL, r->converged,
                     r->total_samples, r->mean_rel_se, r->max_rel_se, r->seconds, r->caustic_photons,
                     r->caustic_seconds, r->paths_cut};
    buffer b = {0};
    put(&b, LM_REF_MAGIC, 8);
    XFER_FIELDS(put, &b, &h);
    put_arrays(&b, r, r->iim != NULL);
    uint64_t sum = LM_FNV_OFFSET;
    if (!b.bad)
        fnv(&sum, b.p, b.len);
    put(&b, &sum, sizeof sum);
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
    FILE *f = b.bad ? NULL : fopen(tmp, "wbx"); /* created: never through a link planted there */
    int ok = f && fwrite(b.p, 1, b.len, f) == b.len;
    ok = (f && fclose(f) == 0) && ok;
    if (ok && rename(tmp, path) != 0)
        ok = 0;
    if (!ok) {
        remove(tmp);
        lm_warn("reference cache: cannot write %s", path);
    }
    free(b.p);
}

static int read_all(const char *path, buffer *b)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    long n = -1;
    if (fseek(f, 0, SEEK_END) == 0)
        n = ftell(f);
    if (n < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return -1;
    }
    b->p = malloc(n > 0 ? (size_t)n : 1);
    b->len = b->p ? (size_t)n : 0;
    int ok = b->p && fread(b->p, 1, b->len, f) == b->len;
    fclose(f);
    return ok ? 1 : -1;
}

static int parse(buffer *b, uint32_t kind, uint64_t key, uint32_t count, int width, int height, lm_ref_result *out,
                 const char **why)
{
    char magic[8];
    file_header h;
    uint64_t sum = LM_FNV_OFFSET, stored;
    if (b->len < 8 + sizeof stored)
        return *why = "truncated", 0;
    fnv(&sum, b->p, b->len - sizeof stored);
    memcpy(&stored, b->p + b->len - sizeof stored, sizeof stored);
    b->len -= sizeof stored;
    get(b, magic, 8);
    XFER_FIELDS(get, b, &h);
    if (b->bad || memcmp(magic, LM_REF_MAGIC, 8) || h.version != LM_REF_VERSION)
        return *why = "not a reference cache file of this version", 0;
    if (sum != stored)
        return *why = "checksum mismatch (damaged)", 0;
    if (h.kind != kind || h.key != key || h.count != count || h.width != width || h.height != height ||
        h.has_texel_arrays != (kind == LM_REF_KIND_TEXELS))
        return *why = "key or sizes do not match", 0;
    memset(out, 0, sizeof *out);
    out->count = count, out->width = width, out->height = height, out->key = key;
    if (!lm_ref_result_alloc(out, count, (int)h.has_texel_arrays))
        return *why = "out of memory", 0;
    float **arrays[LM_REF_MAX_ARRAYS];
    int n = lm_ref_result_arrays(out, (int)h.has_texel_arrays, arrays);
    for (int i = 0; i < n; i++)
        get(b, *arrays[i], (size_t)count * 3 * sizeof(float));
    get(b, out->samples, (size_t)count * sizeof(uint32_t));
    get(b, out->rel_se, (size_t)count * sizeof(float));
    if (b->bad || b->pos != b->len)
        return *why = "wrong length", 0;
    out->converged = h.converged, out->total_samples = h.total_samples;
    out->mean_rel_se = h.mean_rel_se, out->max_rel_se = h.max_rel_se, out->seconds = h.seconds;
    out->caustic_photons = h.caustic_photons, out->caustic_seconds = h.caustic_seconds;
    out->paths_cut = h.paths_cut;
    out->from_cache = 1;
    return 1;
}

int lm_ref_cache_load(const char *path, uint32_t kind, uint64_t key, uint32_t count, int width, int height,
                      lm_ref_result *out)
{
    buffer b = {0};
    memset(out, 0, sizeof *out);
    int rc = read_all(path, &b);
    const char *why = "unreadable";
    int ok = rc > 0 && parse(&b, kind, key, count, width, height, out, &why);
    if (rc != 0 && !ok) {
        lm_warn("reference cache: ignoring %s: %s; recomputing", path, why);
        lm_ref_result_free(out);
    }
    free(b.p);
    return ok;
}
