/* Packing the photon hits into 20-byte records (photon_records.h). */
#include "photon_records.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"

#define MANTISSA_BITS 13
#define MANTISSA_MAX ((1u << MANTISSA_BITS) - 1u)

static uint32_t octahedron_byte(float v) { return (uint32_t)lrintf((fminf(fmaxf(v, -1.0f), 1.0f) * 0.5f + 0.5f) * 255.0f); }

/* The unit vector d onto the octahedron, unfolded into the square [-1, 1]^2, 8 bits a coordinate. */
static uint32_t encode_direction(const float d[3])
{
    float s = fabsf(d[0]) + fabsf(d[1]) + fabsf(d[2]);
    if (!(s > 0.0f))
        return octahedron_byte(0.0f) << 8 | octahedron_byte(0.0f);
    float x = d[0] / s, y = d[1] / s;
    if (d[2] < 0.0f) {
        float fx = (1.0f - fabsf(y)) * (x >= 0.0f ? 1.0f : -1.0f), fy = (1.0f - fabsf(x)) * (y >= 0.0f ? 1.0f : -1.0f);
        x = fx, y = fy;
    }
    return octahedron_byte(x) << 8 | octahedron_byte(y);
}

static void decode_direction(uint32_t bits, float d[3])
{
    float x = (float)(bits >> 8 & 255u) / 255.0f * 2.0f - 1.0f, y = (float)(bits & 255u) / 255.0f * 2.0f - 1.0f;
    float z = 1.0f - fabsf(x) - fabsf(y);
    if (z < 0.0f) {
        float fx = (1.0f - fabsf(y)) * (x >= 0.0f ? 1.0f : -1.0f), fy = (1.0f - fabsf(x)) * (y >= 0.0f ? 1.0f : -1.0f);
        x = fx, y = fy;
    }
    float n = sqrtf(x * x + y * y + z * z);
    d[0] = x / n, d[1] = y / n, d[2] = z / n;
}

void lm_hit_side_normal(const lm_scene *s, const lm_hit *h, float n[3])
{
    lm_vec3 from = lm_scale(lm_v3_load(h->dir), -1.0f), ng = from;
    if (s && h->tri < s->tri_count) {
        float p[3][3];
        for (int k = 0; k < 3; k++)
            lm_scene_vertex_world(s, s->tris[3 * (size_t)h->tri + (size_t)k], p[k]);
        lm_vec3 a = lm_v3_load(p[0]);
        lm_vec3 x = lm_cross(lm_sub(lm_v3_load(p[1]), a), lm_sub(lm_v3_load(p[2]), a));
        float len = sqrtf(lm_dot(x, x));
        if (len > 0.0f && isfinite(len))
            ng = lm_scale(x, lm_dot(x, from) < 0.0f ? -1.0f / len : 1.0f / len);
    }
    lm_v3_store(n, ng);
}

void lm_photon_record_encode(const lm_hit *h, const float side[3], lm_photon_record *r)
{
    memset(r, 0, sizeof *r);
    if (!h || h->surface < 0 || !lm_hit_in_iim(h))
        return;
    float m = fmaxf(h->flux[0], fmaxf(h->flux[1], h->flux[2]));
    if (!(m > 0.0f) || !isfinite(m))
        return;
    int e;
    frexpf(m, &e); /* m = f 2^e, f in [0.5, 1) */
    if (e < -127)
        return;
    if (e > 127)
        e = 127;
    uint32_t q[3];
    for (int c = 0; c < 3; c++) {
        float v = ldexpf(fmaxf(h->flux[c], 0.0f), MANTISSA_BITS - e);
        q[c] = v >= (float)MANTISSA_MAX ? MANTISSA_MAX : (uint32_t)lrintf(v);
    }
    memcpy(r->w, h->pos, 3 * sizeof(float));
    r->w[3] = (uint32_t)(e + 128) << 24 | q[0] << 11 | q[1] >> 2;
    r->w[4] = (q[1] & 3u) << 30 | q[2] << 17 | encode_direction(side);
}

int lm_photon_record_decode(const lm_photon_record *r, float pos[3], float side[3], float flux[3])
{
    memset(pos, 0, 3 * sizeof *pos);
    memset(side, 0, 3 * sizeof *side);
    memset(flux, 0, 3 * sizeof *flux);
    if (!r->w[3])
        return 0;
    memcpy(pos, r->w, 3 * sizeof(float));
    int e = (int)(r->w[3] >> 24) - 128;
    uint32_t q[3] = {r->w[3] >> 11 & MANTISSA_MAX, (r->w[3] & 0x7FFu) << 2 | r->w[4] >> 30, r->w[4] >> 17 & MANTISSA_MAX};
    for (int c = 0; c < 3; c++)
        flux[c] = ldexpf((float)q[c], e - MANTISSA_BITS);
    decode_direction(r->w[4] & 0xFFFFu, side);
    return 1;
}

/* Room for n records and their page marks. */
static int reserve(lm_photon_records *r, uint32_t n)
{
    uint32_t pages = (n + LM_RECORD_PAGE - 1) / LM_RECORD_PAGE;
    if (n > r->capacity || !r->rec) {
        lm_photon_record *rec = realloc(r->rec, (size_t)(n ? n : 1) * sizeof *rec);
        if (!rec)
            return 0;
        r->rec = rec;
        r->capacity = n ? n : 1;
    }
    uint8_t *dirty = realloc(r->dirty, pages ? pages : 1);
    if (!dirty)
        return 0;
    r->dirty = dirty;
    return 1;
}

lm_status lm_photon_records_update(lm_photon_records *r, const lm_photon_store *ps, const lm_scene *s,
                                   lm_error *err)
{
    if (r->rec && r->store_version == ps->version) {
        r->dirty_pages = 0;
        if (r->dirty)
            memset(r->dirty, 0, r->pages);
        return LM_OK;
    }
    uint32_t n = ps->used;
    if (!reserve(r, n))
        return lm_fail(err, LM_ERR_NOMEM, "no memory for %u photon records", n);
    int resized = n != r->count;
    r->count = n;
    r->pages = (n + LM_RECORD_PAGE - 1) / LM_RECORD_PAGE;
    memset(r->dirty, resized, r->pages);
    r->live = 0;
    r->top_exponent = -1000;
    for (uint32_t i = 0; i < n; i++) {
        lm_photon_record x;
        float side[3] = {0.0f, 0.0f, 0.0f};
        if (ps->hits[i].surface >= 0)
            lm_hit_side_normal(s, &ps->hits[i], side);
        lm_photon_record_encode(&ps->hits[i], side, &x);
        r->live += x.w[3] != 0;
        if (x.w[3] && (int)(x.w[3] >> 24) - 128 > r->top_exponent)
            r->top_exponent = (int)(x.w[3] >> 24) - 128;
        if (resized || memcmp(&x, &r->rec[i], sizeof x)) {
            r->rec[i] = x;
            r->dirty[i / LM_RECORD_PAGE] = 1;
        }
    }
    r->dirty_pages = 0;
    for (uint32_t p = 0; p < r->pages; p++)
        r->dirty_pages += r->dirty[p];
    r->store_version = ps->version;
    return LM_OK;
}

void lm_photon_records_free(lm_photon_records *r)
{
    free(r->rec);
    free(r->dirty);
    memset(r, 0, sizeof *r);
}
