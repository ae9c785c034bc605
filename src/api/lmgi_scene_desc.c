/* lmgi_load_desc: an application's own level (vertex and index arrays, materials, lights) handed over
 * without a file. The arrays are written into a .glb in memory and loaded by the glTF loader, so a scene
 * from arrays is checked, classified and split into sides exactly as a file is, with the same messages
 * (the glTF is written by gltf_write.h, as lmgi_export_gltf's is). */
#include <lmgi.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_write.h"
#include "lmgi_scene.h"

static int finite_all(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* What glTF and the loader cannot say as clearly: counts, indices and references. */
static lmgi_status check(const lmgi_scene_desc *d, lmgi_error *err)
{
    if (d->mesh_count < 1 || !d->meshes)
        return lm_api_refuse(err, "lmgi_load_desc: no meshes");
    if (d->material_count < 0 || (d->material_count > 0 && !d->materials) || d->light_count < 0 ||
        (d->light_count > 0 && !d->lights))
        return lm_api_refuse(err, "lmgi_load_desc: material or light count without the array");
    for (int i = 0; i < d->mesh_count; i++) {
        const lmgi_mesh_desc *m = &d->meshes[i];
        if (!m->positions || !m->indices || m->vertex_count == 0 || m->triangle_count == 0)
            return lm_api_refuse(err, "mesh %d: needs positions, indices and at least one triangle", i);
        for (size_t k = 0; k < 3 * (size_t)m->triangle_count; k++)
            if (m->indices[k] >= m->vertex_count)
                return lm_api_refuse(err, "mesh %d: index %zu is %u, but the mesh has %u vertices", i, k,
                                     m->indices[k], m->vertex_count);
        if (m->material < 0 || m->material >= d->material_count)
            return lm_api_refuse(err, "mesh %d: material %d, but the scene has %d", i, m->material,
                                 d->material_count);
        if (!finite_all(m->transform, 16))
            return lm_api_refuse(err, "mesh %d: its transform has NaN or infinite entries", i);
    }
    for (int i = 0; i < d->light_count; i++) {
        const lmgi_light_desc *l = &d->lights[i];
        if (!finite_all(l->position, 3) || !finite_all(l->direction, 3) || !finite_all(l->color, 3) ||
            !(l->intensity >= 0.0f) || !isfinite(l->intensity))
            return lm_api_refuse(err, "light %d: position, direction, colour and intensity must be finite (intensity "
                                 ">= 0)", i);
        if (l->type < LMGI_LIGHT_POINT || l->type > LMGI_LIGHT_DIRECTIONAL)
            return lm_api_refuse(err, "light %d: type %d is not a light type", i, (int)l->type);
    }
    return LMGI_OK;
}

static int is_zero(const float *v, int n)
{
    for (int i = 0; i < n; i++)
        if (v[i] != 0.0f)
            return 0;
    return 1;
}

/* The rotation taking glTF's light direction (-Z) to d. */
static void light_rotation(const float d_in[3], float q[4])
{
    float len = sqrtf(d_in[0] * d_in[0] + d_in[1] * d_in[1] + d_in[2] * d_in[2]);
    float d[3] = {0, 0, -1};
    if (len > 0.0f)
        d[0] = d_in[0] / len, d[1] = d_in[1] / len, d[2] = d_in[2] / len;
    float dot = -d[2]; /* (0, 0, -1) . d */
    if (dot < -0.999999f) { /* straight up +Z: half a turn about x */
        q[0] = 1, q[1] = 0, q[2] = 0, q[3] = 0;
        return;
    }
    /* axis (0, 0, -1) x d, angle from w = 1 + dot, normalised */
    float x = d[1], y = -d[0], z = 0.0f, w = 1.0f + dot;
    float n = sqrtf(x * x + y * y + z * z + w * w);
    q[0] = x / n, q[1] = y / n, q[2] = z / n, q[3] = w / n;
}

static void write_meshes(const lmgi_scene_desc *d, lm_gltf_doc *doc)
{
    FILE *f = doc->json;
    fprintf(f, ",\"meshes\":[");
    for (int i = 0; i < d->mesh_count; i++) {
        const lmgi_mesh_desc *m = &d->meshes[i];
        fprintf(f, "%s{\"name\":", i ? "," : ""); /* the node's name: the loader's warnings name the mesh */
        lm_gltf_string(f, m->name ? m->name : "mesh");
        fprintf(f, ",\"primitives\":[{\"attributes\":{\"POSITION\":%d",
                lm_gltf_accessor(doc, m->positions, m->vertex_count, 3, 1));
        if (m->normals)
            fprintf(f, ",\"NORMAL\":%d", lm_gltf_accessor(doc, m->normals, m->vertex_count, 3, 0));
        if (m->uvs)
            fprintf(f, ",\"TEXCOORD_0\":%d", lm_gltf_accessor(doc, m->uvs, m->vertex_count, 2, 0));
        fprintf(f, "},\"indices\":%d,\"material\":%d,\"mode\":4}]}",
                lm_gltf_accessor(doc, m->indices, 3 * m->triangle_count, 0, 0), m->material);
    }
    fputc(']', f);
}

static void write_materials(const lmgi_scene_desc *d, FILE *f, int *uses_mat_ext)
{
    fprintf(f, ",\"materials\":[");
    for (int i = 0; i < d->material_count; i++) {
        const lmgi_material_desc *m = &d->materials[i];
        float base[4] = {1, 1, 1, 1};
        if (!is_zero(m->base_color, 4))
            memcpy(base, m->base_color, sizeof base);
        fprintf(f, "%s{\"name\":", i ? "," : "");
        lm_gltf_string(f, m->name ? m->name : "material");
        fprintf(f, ",\"pbrMetallicRoughness\":{\"baseColorFactor\":");
        lm_gltf_floats(f, base, 4);
        fprintf(f, ",\"metallicFactor\":%.9g,\"roughnessFactor\":%.9g}", (double)m->metallic,
                (double)(m->roughness > 0.0f ? m->roughness : 1.0f));
        float strength = lm_gltf_emissive(f, m->emissive);
        fprintf(f, ",\"doubleSided\":%s", m->double_sided ? "true" : "false");
        if (strength > 0.0f || m->transmission > 0.0f || m->ior > 0.0f) {
            *uses_mat_ext = 1;
            fprintf(f, ",\"extensions\":{");
            const char *sep = "";
            if (strength > 0.0f)
                fprintf(f, "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":%.9g}", (double)strength), sep = ",";
            if (m->transmission > 0.0f)
                fprintf(f, "%s\"KHR_materials_transmission\":{\"transmissionFactor\":%.9g}", sep,
                        (double)m->transmission), sep = ",";
            if (m->ior > 0.0f)
                fprintf(f, "%s\"KHR_materials_ior\":{\"ior\":%.9g}", sep, (double)m->ior);
            fputc('}', f);
        }
        fputc('}', f);
    }
    fputc(']', f);
}

static void write_nodes(const lmgi_scene_desc *d, FILE *f)
{
    fprintf(f, ",\"scene\":0,\"scenes\":[{\"nodes\":[");
    for (int i = 0; i < d->mesh_count + d->light_count; i++)
        fprintf(f, "%s%d", i ? "," : "", i);
    fprintf(f, "]}],\"nodes\":[");
    for (int i = 0; i < d->mesh_count; i++) {
        const lmgi_mesh_desc *m = &d->meshes[i];
        fprintf(f, "%s{\"name\":", i ? "," : "");
        lm_gltf_string(f, m->name ? m->name : "mesh");
        fprintf(f, ",\"mesh\":%d", i);
        if (!is_zero(m->transform, 16))
            fprintf(f, ",\"matrix\":"), lm_gltf_floats(f, m->transform, 16);
        if (m->dynamic)
            fprintf(f, ",\"extras\":{\"lmgi\":{\"dynamic\":true}}");
        fputc('}', f);
    }
    for (int i = 0; i < d->light_count; i++) {
        const lmgi_light_desc *l = &d->lights[i];
        float q[4];
        light_rotation(l->direction, q);
        fprintf(f, ",{\"name\":");
        lm_gltf_string(f, l->name ? l->name : "light");
        fprintf(f, ",\"translation\":");
        lm_gltf_floats(f, l->position, 3);
        fprintf(f, ",\"rotation\":");
        lm_gltf_floats(f, q, 4);
        fprintf(f, ",\"extensions\":{\"KHR_lights_punctual\":{\"light\":%d}}}", i);
    }
    fputc(']', f);
    if (d->light_count > 0) {
        fprintf(f, ",\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[");
        for (int i = 0; i < d->light_count; i++) {
            const lmgi_light_desc *l = &d->lights[i];
            float color[3] = {1, 1, 1};
            if (!is_zero(l->color, 3))
                memcpy(color, l->color, sizeof color);
            fprintf(f, "%s", i ? "," : "");
            lm_gltf_light(f, l->name, l->type, color, l->intensity, l->range, l->inner_cone,
                          l->outer_cone > 0.0f ? l->outer_cone : 0.785398163f);
        }
        fprintf(f, "]}}");
    }
}

/* The .glb: 12-byte header, the JSON chunk padded with spaces, the BIN chunk padded with zeros. */
static unsigned char *glb(const char *json, size_t json_len, const void *bin, size_t bin_len, size_t *size)
{
    size_t jlen = (json_len + 3) & ~(size_t)3, blen = (bin_len + 3) & ~(size_t)3;
    *size = 12 + 8 + jlen + 8 + blen;
    unsigned char *out = calloc(1, *size);
    if (!out)
        return NULL;
    uint32_t head[5] = {0x46546C67u, 2, (uint32_t)*size, (uint32_t)jlen, 0x4E4F534Au};
    memcpy(out, head, sizeof head);
    memcpy(out + 20, json, json_len);
    memset(out + 20 + json_len, ' ', jlen - json_len);
    uint32_t bhead[2] = {(uint32_t)blen, 0x004E4942u};
    memcpy(out + 20 + jlen, bhead, sizeof bhead);
    memcpy(out + 28 + jlen, bin, bin_len);
    return out;
}

lmgi_status lmgi_load_desc(const lmgi_scene_desc *d, const lmgi_options *o, lmgi_scene **out, lmgi_error *err)
{
    if (out)
        *out = NULL;
    if (!d || !out)
        return lm_api_refuse(err, "lmgi_load_desc: %s is NULL", d ? "out" : "the desc");
    lmgi_status st = check(d, err);
    if (st != LMGI_OK)
        return st;
    lm_gltf_doc doc;
    unsigned char *file = NULL;
    size_t size = 0, json_len = 0, bin_len = 0;
    if (lm_gltf_open(&doc)) {
        int mat_ext = 0;
        fprintf(doc.json, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"lmgi_load_desc\"}");
        write_meshes(d, &doc);
        write_materials(d, doc.json, &mat_ext);
        write_nodes(d, doc.json);
        if (d->light_count > 0 || mat_ext)
            fprintf(doc.json, ",\"extensionsUsed\":[%s%s%s]", d->light_count > 0 ? "\"KHR_lights_punctual\"" : "",
                    d->light_count > 0 && mat_ext ? "," : "",
                    mat_ext ? "\"KHR_materials_emissive_strength\",\"KHR_materials_transmission\",\"KHR_materials_ior\"" : "");
        lm_gltf_finish(&doc, NULL);
        fputc('}', doc.json);
        const char *json = lm_gltf_text(&doc, &json_len);
        const void *bin = lm_gltf_bin(&doc, &bin_len);
        file = json && bin ? glb(json, json_len, bin, bin_len, &size) : NULL;
    }
    lm_gltf_close(&doc);
    st = file ? lmgi_load_memory(file, size, d->name ? d->name : "(scene desc)", o, out, err)
              : lm_export_error(err, &(lm_error){LM_ERR_NOMEM, "lmgi_load_desc: no memory for the scene"});
    free(file);
    return st;
}
