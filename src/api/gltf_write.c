#include "gltf_write.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int lm_gltf_open(lm_gltf_doc *d)
{
    memset(d, 0, sizeof *d);
    d->json = open_memstream(&d->json_text, &d->json_size);
    d->views_f = open_memstream(&d->views_text, &d->views_size);
    d->accessors_f = open_memstream(&d->accessors_text, &d->accessors_size);
    d->bin_f = open_memstream(&d->bin_data, &d->bin_size);
    return d->json && d->views_f && d->accessors_f && d->bin_f;
}

void lm_gltf_close(lm_gltf_doc *d)
{
    FILE *f[4] = {d->json, d->views_f, d->accessors_f, d->bin_f};
    for (int k = 0; k < 4; k++)
        if (f[k])
            fclose(f[k]);
    free(d->json_text), free(d->views_text), free(d->accessors_text), free(d->bin_data);
    memset(d, 0, sizeof *d);
}

void lm_gltf_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

void lm_gltf_floats(FILE *f, const float *v, int n)
{
    fputc('[', f);
    for (int i = 0; i < n; i++)
        fprintf(f, "%s%.9g", i ? "," : "", (double)v[i]);
    fputc(']', f);
}

float lm_gltf_emissive(FILE *f, const float e[3])
{
    float peak = fmaxf(e[0], fmaxf(e[1], e[2])), scale = fmaxf(peak, 1.0f);
    float factor[3] = {e[0] / scale, e[1] / scale, e[2] / scale};
    fprintf(f, ",\"emissiveFactor\":");
    lm_gltf_floats(f, factor, 3);
    return peak > 1.0f ? peak : 0.0f;
}

void lm_gltf_light(FILE *f, const char *name, int type, const float color[3], float intensity, float range,
                   float inner_cone, float outer_cone)
{
    static const char *const types[3] = {"point", "spot", "directional"};
    fputc('{', f);
    if (name) {
        fprintf(f, "\"name\":");
        lm_gltf_string(f, name);
        fputc(',', f);
    }
    fprintf(f, "\"type\":\"%s\",\"color\":", types[type]);
    lm_gltf_floats(f, color, 3);
    fprintf(f, ",\"intensity\":%.9g", (double)intensity);
    if (range > 0.0f)
        fprintf(f, ",\"range\":%.9g", (double)range);
    if (type == 1)
        fprintf(f, ",\"spot\":{\"innerConeAngle\":%.9g,\"outerConeAngle\":%.9g}", (double)inner_cone,
                (double)outer_cone);
    fputc('}', f);
}

int lm_gltf_accessor(lm_gltf_doc *d, const void *data, uint32_t count, int comps, int bounds)
{
    static const char *const types[] = {"SCALAR", "SCALAR", "VEC2", "VEC3", "VEC4"};
    size_t bytes = (size_t)count * (comps ? (size_t)comps * sizeof(float) : sizeof(uint32_t));
    for (; d->bin_len % 4; d->bin_len++)
        fputc(0, d->bin_f);
    fprintf(d->views_f, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":%d}", d->views ? "," : "",
            d->bin_len, bytes, comps ? 34962 : 34963);
    fwrite(data, 1, bytes, d->bin_f);
    d->bin_len += bytes;
    fprintf(d->accessors_f, "%s{\"bufferView\":%d,\"componentType\":%d,\"count\":%u,\"type\":\"%s\"",
            d->accessors ? "," : "", d->views++, comps ? 5126 : 5125, count, types[comps]);
    if (bounds && comps == 3) {
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        const float *p = data;
        for (uint32_t i = 0; i < count; i++)
            for (int k = 0; k < 3; k++)
                lo[k] = fminf(lo[k], p[3 * i + k]), hi[k] = fmaxf(hi[k], p[3 * i + k]);
        fprintf(d->accessors_f, ",\"min\":");
        lm_gltf_floats(d->accessors_f, lo, 3);
        fprintf(d->accessors_f, ",\"max\":");
        lm_gltf_floats(d->accessors_f, hi, 3);
    }
    fputc('}', d->accessors_f);
    return d->accessors++;
}

void lm_gltf_finish(lm_gltf_doc *d, const char *bin_uri)
{
    fflush(d->views_f);
    fflush(d->accessors_f);
    fprintf(d->json, ",\"buffers\":[{");
    if (bin_uri) {
        fprintf(d->json, "\"uri\":");
        lm_gltf_string(d->json, bin_uri);
        fputc(',', d->json);
    }
    fprintf(d->json, "\"byteLength\":%zu}],\"bufferViews\":[%s],\"accessors\":[%s]", d->bin_len,
            d->views_text ? d->views_text : "", d->accessors_text ? d->accessors_text : "");
}

const char *lm_gltf_text(lm_gltf_doc *d, size_t *len)
{
    if (fflush(d->json) != 0 || ferror(d->json) || ferror(d->views_f) || ferror(d->accessors_f))
        return NULL;
    *len = d->json_size;
    return d->json_text;
}

const void *lm_gltf_bin(lm_gltf_doc *d, size_t *len)
{
    if (fflush(d->bin_f) != 0 || ferror(d->bin_f))
        return NULL;
    *len = d->bin_size;
    return d->bin_data;
}
