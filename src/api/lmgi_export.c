/* The public API's glTF export (lmgi_export_gltf): the scene as lmgi lit it, with the lightmap's UVs as
 * TEXCOORD_1 and the lightmap beside it (docs/api.md, "Exporting to engines").
 *
 * Every node becomes a root node placed by its world matrix (the file's world: lmgi's origin added back),
 * so what an engine draws is where lmgi baked it. Each node's triangles are written with their own three
 * vertices per triangle (the lightmap's charts cut the mesh wherever they like; sharing vertices would
 * need their UVs to agree), one primitive per material. Twins of double-sided surfaces are written as
 * the single-sided triangles they are in lmgi, each with its own lightmap texels, so their material is
 * single-sided in the copy. A mirrored node's triangles get the file's winding back: glTF readers reverse
 * it again for the negative determinant, as lmgi's loader did. A level of several lightmap pages gets an
 * image per page, a primitive per node, material and page, and a copy of a material for each further
 * page it lies on (export_pages.h). */
#include <lmgi_tools.h>

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/image.h"
#include "../core/vecmath.h"
#include "export_pages.h"
#include "gltf_write.h"
#include "lmgi_context.h"
#include "lmgi_scene.h"
#include "lmgi_updater.h"

typedef struct {
    const lm_scene *s;
    const lm_atlas *atlas;
    const char *name;
    lm_gltf_doc doc;
    const lm_export_pages *ep; /* which page each primitive and material samples */
    const float *lightmap;  /* the displayed IIM, atlas-sized RGBA */
    float rgbd_scale;       /* the RGBD image's values times this are E */
    int lightmap_texture;   /* its glTF texture (page p's: + p), -1 when no triangle has texels */
    const uint8_t *material_lit; /* per material: 1 if any of its triangles has texels (mirrors, glass: 0) */
} writer;

/* Which uv set a material's textures read: 0, or 2 where the file's base colour texture used TEXCOORD_1
 * (TEXCOORD_1 now holds the lightmap's). */
static int texture_uv(const lm_material *m) { return m->base_color_uv == 1 ? 2 : 0; }

/* Whether triangle t is of `material` and exported on `page`. */
static int in_primitive(const writer *w, uint32_t t, int material, int page)
{
    return w->s->tri_material[t] == material && lm_export_tri_page(w->ep, w->s, w->atlas, t) == page;
}

/* The vertices of node nd's triangles of `material` on `page`, three per triangle, TEXCOORD_1 over the
 * page, written as one primitive (the node's first when `first`). */
static lm_status write_primitive(writer *w, const lm_node *nd, int material, int page, int first, lm_error *err)
{
    const lm_scene *s = w->s;
    uint32_t n = 0;
    for (uint32_t t = nd->first_tri; t < nd->first_tri + nd->tri_count; t++)
        n += in_primitive(w, t, material, page);
    float *pos = malloc((size_t)n * 3 * 3 * sizeof(float)), *nrm = malloc((size_t)n * 3 * 3 * sizeof(float));
    float *uv0 = malloc((size_t)n * 3 * 2 * sizeof(float)), *uvl = malloc((size_t)n * 3 * 2 * sizeof(float));
    int file_uv1 = texture_uv(&s->materials[material]) == 2;
    float *uvf = file_uv1 ? malloc((size_t)n * 3 * 2 * sizeof(float)) : NULL;
    uint32_t *idx = malloc((size_t)n * 3 * sizeof(uint32_t));
    if (!pos || !nrm || !uv0 || !uvl || (file_uv1 && !uvf) || !idx) {
        free(pos), free(nrm), free(uv0), free(uvl), free(uvf), free(idx);
        return lm_fail(err, LM_ERR_NOMEM, "export: no memory for node '%s'", nd->name);
    }
    static const int file_order[3] = {0, 2, 1}, same[3] = {0, 1, 2};
    const int *order = nd->mirrored ? file_order : same;
    uint32_t v = 0;
    for (uint32_t t = nd->first_tri; t < nd->first_tri + nd->tri_count; t++) {
        if (!in_primitive(w, t, material, page))
            continue;
        for (int c = 0; c < 3; c++, v++) {
            int k = order[c];
            uint32_t sv = s->tris[3 * t + k];
            memcpy(pos + 3 * v, s->positions + 3 * (size_t)sv, 3 * sizeof(float));
            memcpy(nrm + 3 * v, s->normals + 3 * (size_t)sv, 3 * sizeof(float));
            memcpy(uv0 + 2 * v, s->uv0 + 2 * (size_t)sv, 2 * sizeof(float));
            if (uvf)
                memcpy(uvf + 2 * v, s->uv1 + 2 * (size_t)sv, 2 * sizeof(float));
            const float *l = w->atlas->corner_uv + 6 * (size_t)t + 2 * k; /* NaN: no surface (mirror, glass) */
            uvl[2 * v] = uvl[2 * v + 1] = 0.0f;
            if (isfinite(l[0]) && isfinite(l[1]))
                lm_atlas_page_uv(w->atlas, page, l, uvl + 2 * v);
            idx[v] = v;
        }
    }
    int a_pos = lm_gltf_accessor(&w->doc, pos, 3 * n, 3, 1);
    int a_nrm = lm_gltf_accessor(&w->doc, nrm, 3 * n, 3, 0);
    int a_uv0 = lm_gltf_accessor(&w->doc, uv0, 3 * n, 2, 0);
    int a_uvl = lm_gltf_accessor(&w->doc, uvl, 3 * n, 2, 0);
    int a_uvf = uvf ? lm_gltf_accessor(&w->doc, uvf, 3 * n, 2, 0) : -1;
    int a_idx = lm_gltf_accessor(&w->doc, idx, 3 * n, 0, 0);
    fprintf(w->doc.json, "%s{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d,\"TEXCOORD_0\":%d,\"TEXCOORD_1\":%d",
            first ? "" : ",", a_pos, a_nrm, a_uv0, a_uvl);
    if (a_uvf >= 0)
        fprintf(w->doc.json, ",\"TEXCOORD_2\":%d", a_uvf);
    fprintf(w->doc.json, "},\"indices\":%d,\"material\":%d}", a_idx, w->ep->index[(size_t)material * w->ep->pages + page]);
    free(pos), free(nrm), free(uv0), free(uvl), free(uvf), free(idx);
    return LM_OK;
}

static int int_order(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* The node's primitives, by material then page, each (material, page) it uses once. */
static lm_status write_primitives(writer *w, const lm_node *nd, lm_error *err)
{
    int pages = w->ep->pages, *key = malloc(((size_t)nd->tri_count + 1) * sizeof *key);
    if (!key)
        return lm_fail(err, LM_ERR_NOMEM, "export: no memory for node '%s'", nd->name);
    for (uint32_t i = 0; i < nd->tri_count; i++) {
        uint32_t t = nd->first_tri + i;
        key[i] = w->s->tri_material[t] * pages + lm_export_tri_page(w->ep, w->s, w->atlas, t);
    }
    qsort(key, nd->tri_count, sizeof *key, int_order);
    lm_status st = LM_OK;
    for (uint32_t i = 0; i < nd->tri_count && st == LM_OK; i++)
        if (!i || key[i] != key[i - 1])
            st = write_primitive(w, nd, key[i] / pages, key[i] % pages, !i, err);
    free(key);
    return st;
}

/* Meshes: one per node with triangles (mesh_of[node], else -1), a primitive per material and page. */
static lm_status write_meshes(writer *w, int *mesh_of, lm_error *err)
{
    const lm_scene *s = w->s;
    int meshes = 0;
    lm_status st = LM_OK;
    fprintf(w->doc.json, ",\"meshes\":[");
    for (int i = 0; i < s->node_count && st == LM_OK; i++) {
        const lm_node *nd = &s->nodes[i];
        mesh_of[i] = -1;
        if (!nd->tri_count)
            continue;
        mesh_of[i] = meshes++;
        fprintf(w->doc.json, "%s{\"name\":", mesh_of[i] ? "," : "");
        lm_gltf_string(w->doc.json, nd->name);
        fprintf(w->doc.json, ",\"primitives\":[");
        st = write_primitives(w, nd, err);
        fprintf(w->doc.json, "]}");
    }
    fputc(']', w->doc.json);
    return st;
}

/* The node's lightmap in its extras, where any of its triangles has texels (mirror and glass have none):
 * the file, and with several pages its first page and, where it lies on more, all of them. */
static void write_node_lightmap(const writer *w, const lm_node *nd)
{
    int first = -1, last = -1;
    for (uint32_t t = nd->first_tri; t < nd->first_tri + nd->tri_count; t++) {
        int p = lm_atlas_tri_page(w->atlas, t);
        first = p >= 0 && (first < 0 || p < first) ? p : first;
        last = p > last ? p : last;
    }
    if (first < 0)
        return;
    char file[260];
    lm_export_lightmap_file(file, sizeof file, w->name, w->ep, first, ".exr");
    fprintf(w->doc.json, ",\"lightmap\":{\"uri\":\"%s\"", file);
    if (w->ep->pages > 1)
        fprintf(w->doc.json, ",\"page\":%d", first);
    if (last > first) { /* a node larger than a page: every page it lies on */
        fprintf(w->doc.json, ",\"pages\":[%d", first);
        for (int p = first + 1; p <= last; p++) {
            uint32_t t = nd->first_tri;
            while (t < nd->first_tri + nd->tri_count && lm_atlas_tri_page(w->atlas, t) != p)
                t++;
            if (t < nd->first_tri + nd->tri_count)
                fprintf(w->doc.json, ",%d", p);
        }
        fputc(']', w->doc.json);
    }
    fprintf(w->doc.json, ",\"texCoord\":1}");
}

/* A node for each light added by an edit, at its position with its local -z along its direction. */
static void write_added_lights(writer *w)
{
    const lm_scene *s = w->s;
    for (int l = 0; l < s->light_count; l++) {
        const lm_light *li = &s->lights[l];
        if (li->node >= 0 || li->removed)
            continue;
        lm_vec3 z = lm_scale(lm_normalize(lm_v3_load(li->dir)), -1.0f);
        lm_vec3 up = fabsf(z.y) < 0.9f ? lm_v3(0, 1, 0) : lm_v3(1, 0, 0);
        lm_vec3 x = lm_normalize(lm_cross(up, z)), y = lm_cross(z, x);
        float m[16] = {x.x, x.y, x.z, 0, y.x, y.y, y.z, 0, z.x, z.y, z.z, 0, 0, 0, 0, 1};
        for (int k = 0; k < 3; k++)
            m[12 + k] = li->pos[k] + s->origin[k];
        fprintf(w->doc.json, ",{\"name\":");
        lm_gltf_string(w->doc.json, li->name);
        fprintf(w->doc.json, ",\"matrix\":");
        lm_gltf_floats(w->doc.json, m, 16);
        fprintf(w->doc.json, ",\"extensions\":{\"KHR_lights_punctual\":{\"light\":%d}}}", l);
    }
}

static void write_nodes(writer *w, const int *mesh_of)
{
    const lm_scene *s = w->s;
    int added = 0; /* lights added by edits: a node each, after the scene's */
    for (int l = 0; l < s->light_count; l++)
        added += s->lights[l].node < 0 && !s->lights[l].removed;
    fprintf(w->doc.json, ",\"scene\":0,\"scenes\":[{\"nodes\":[");
    for (int i = 0; i < s->node_count + added; i++)
        fprintf(w->doc.json, "%s%d", i ? "," : "", i);
    fprintf(w->doc.json, "]}],\"nodes\":[");
    for (int i = 0; i < s->node_count; i++) {
        const lm_node *nd = &s->nodes[i];
        float m[16];
        memcpy(m, nd->world, sizeof m);
        for (int k = 0; k < 3; k++) /* the file's world: lmgi's origin added back */
            m[12 + k] += s->origin[k] * m[15];
        fprintf(w->doc.json, "%s{\"name\":", i ? "," : "");
        lm_gltf_string(w->doc.json, nd->name);
        fprintf(w->doc.json, ",\"matrix\":");
        lm_gltf_floats(w->doc.json, m, 16);
        if (mesh_of[i] >= 0)
            fprintf(w->doc.json, ",\"mesh\":%d", mesh_of[i]);
        if (nd->camera >= 0)
            fprintf(w->doc.json, ",\"camera\":%d", nd->camera);
        if (nd->light >= 0 && !s->lights[nd->light].removed)
            fprintf(w->doc.json, ",\"extensions\":{\"KHR_lights_punctual\":{\"light\":%d}}", nd->light);
        /* lmgi's own node settings (as resolved: a reload needs no inheritance), then the lightmap */
        const lm_node_settings *ns = &nd->settings;
        fprintf(w->doc.json, ",\"extras\":{\"lmgi\":{\"dynamic\":%s,\"caustics\":%s,\"indirect\":%s,\"shadows\":%s,"
                "\"reflections\":%s}", nd->dynamic ? "true" : "false", ns->caustics ? "true" : "false",
                ns->indirect ? "true" : "false", ns->shadows ? "true" : "false", ns->reflections ? "true" : "false");
        if (ns->has_reflection_box) { /* in the file's world, as it was read */
            fprintf(w->doc.json, ",\"reflection_box\":[");
            for (int k = 0; k < 6; k++)
                fprintf(w->doc.json, "%s%.9g", k ? "," : "", (double)(ns->reflection_box[k] + s->origin[k % 3]));
            fputc(']', w->doc.json);
        }
        write_node_lightmap(w, nd);
        fprintf(w->doc.json, "}}");
    }
    write_added_lights(w);
    fputc(']', w->doc.json);
}

/* Textures: each of the scene's decoded images as NAME_texN.png (8-bit sRGB) with the default sampler, then
 * the lightmap's RGBD image (one a page) with its own: bilinear without mipmaps (a mip would blend charts
 * with their neighbours), clamped at the atlas's edges. */
static lm_status write_textures(writer *w, const char *dir, lm_error *err)
{
    const lm_scene *s = w->s;
    if (!s->texture_count && w->lightmap_texture < 0)
        return LM_OK;
    lm_status st = LM_OK;
    fprintf(w->doc.json, ",\"samplers\":[{},{\"magFilter\":9729,\"minFilter\":9729,\"wrapS\":33071,"
                         "\"wrapT\":33071}],\"images\":[");
    for (int i = 0; i < s->texture_count; i++) {
        fprintf(w->doc.json, "%s{\"uri\":\"%s_tex%d.png\"}", i ? "," : "", w->name, i); /* name checked to be plain */
        const lm_texture *t = &s->textures[i];
        size_t n = (size_t)t->width * (size_t)t->height;
        uint8_t *px = st == LM_OK ? malloc(n * 4) : NULL;
        if (st == LM_OK && !px)
            st = lm_fail(err, LM_ERR_NOMEM, "export: no memory for texture %d", i);
        for (size_t p = 0; px && p < n; p++)
            for (int c = 0; c < 4; c++) {
                float v = t->rgba[4 * p + c];
                v = c < 3 ? lm_linear_to_srgb(v) : v;
                px[4 * p + c] = (uint8_t)lroundf(255.0f * fminf(1.0f, fmaxf(0.0f, v)));
            }
        if (px) {
            char path[4200];
            snprintf(path, sizeof path, "%s/%s_tex%d.png", dir, w->name, i);
            st = lm_write_png(path, t->width, t->height, px, err);
        }
        free(px);
    }
    for (int p = 0; w->lightmap_texture >= 0 && p < w->ep->pages; p++) {
        char file[260];
        lm_export_lightmap_file(file, sizeof file, w->name, w->ep, p, "_rgbd.png");
        fprintf(w->doc.json, "%s{\"uri\":\"%s\"}", s->texture_count || p ? "," : "", file);
    }
    fprintf(w->doc.json, "],\"textures\":[");
    for (int i = 0; i < s->texture_count; i++)
        fprintf(w->doc.json, "%s{\"source\":%d,\"sampler\":0}", i ? "," : "", i);
    for (int p = 0; w->lightmap_texture >= 0 && p < w->ep->pages; p++)
        fprintf(w->doc.json, "%s{\"source\":%d,\"sampler\":1}", s->texture_count || p ? "," : "",
                w->lightmap_texture + p);
    fputc(']', w->doc.json);
    return st;
}

static void write_texture_ref(FILE *f, const lm_material *m, int texture)
{
    fprintf(f, "{\"index\":%d,\"texCoord\":%d", texture, texture_uv(m));
    if (m->uv_offset[0] != 0.0f || m->uv_offset[1] != 0.0f || m->uv_scale[0] != 1.0f || m->uv_scale[1] != 1.0f ||
        m->uv_rotation != 0.0f)
        fprintf(f, ",\"extensions\":{\"KHR_texture_transform\":{\"offset\":[%.9g,%.9g],\"scale\":[%.9g,%.9g],"
                   "\"rotation\":%.9g}}", (double)m->uv_offset[0], (double)m->uv_offset[1], (double)m->uv_scale[0],
                (double)m->uv_scale[1], (double)m->uv_rotation);
    fputc('}', f);
}

/* Material i as it samples the lightmap's page `page` (the comma before it unless `first`). */
static void write_material(writer *w, int i, int page, int first)
{
    const lm_material *m = &w->s->materials[i];
    fprintf(w->doc.json, "%s{\"name\":", first ? "" : ",");
    lm_gltf_string(w->doc.json, m->name);
    fprintf(w->doc.json, ",\"pbrMetallicRoughness\":{\"baseColorFactor\":");
    lm_gltf_floats(w->doc.json, m->base_color, 4);
    fprintf(w->doc.json, ",\"metallicFactor\":%.9g,\"roughnessFactor\":%.9g", (double)m->metallic, (double)m->roughness);
    if (m->base_color_tex >= 0) {
        fprintf(w->doc.json, ",\"baseColorTexture\":");
        write_texture_ref(w->doc.json, m, m->base_color_tex);
    }
    fputc('}', w->doc.json);
    float strength = lm_gltf_emissive(w->doc.json, m->emissive);
    if (m->emissive_tex >= 0) {
        fprintf(w->doc.json, ",\"emissiveTexture\":");
        write_texture_ref(w->doc.json, m, m->emissive_tex);
    }
    /* split sides are two single-sided triangles here, each with its own lightmap texels */
    fprintf(w->doc.json, ",\"doubleSided\":%s,\"extensions\":{\"KHR_materials_ior\":{\"ior\":%.9g}",
            m->double_sided ? "true" : "false", (double)m->ior);
    if (strength > 0.0f)
        fprintf(w->doc.json, ",\"KHR_materials_emissive_strength\":{\"emissiveStrength\":%.9g}", (double)strength);
    if (m->transmission > 0.0f)
        fprintf(w->doc.json, ",\"KHR_materials_transmission\":{\"transmissionFactor\":%.9g}", (double)m->transmission);
    if (w->lightmap_texture >= 0 && w->material_lit[i]) /* docs/api.md, "The lightmap in engines" */
        fprintf(w->doc.json, ",\"LMGI_lightmap\":{\"lightmapTexture\":{\"index\":%d,\"texCoord\":1},"
                "\"encoding\":\"RGBD\",\"gamma\":%.9g,\"scale\":%.9g}", w->lightmap_texture + page,
                (double)LM_RGBD_GAMMA, (double)w->rgbd_scale);
    fprintf(w->doc.json, "}}");
}

/* The scene's materials, each on its first page, then the copies for the further pages (export_pages.h). */
static void write_materials(writer *w)
{
    fprintf(w->doc.json, ",\"materials\":[");
    for (int i = 0; i < w->s->material_count; i++)
        write_material(w, i, w->ep->first_page[i], !i);
    for (int c = 0; c < w->ep->copies; c++)
        write_material(w, w->ep->copy[2 * c], w->ep->copy[2 * c + 1], 0);
    fputc(']', w->doc.json);
}

static void write_lights_and_cameras(writer *w)
{
    const lm_scene *s = w->s;
    if (s->light_count) {
        fprintf(w->doc.json, ",\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[");
        for (int i = 0; i < s->light_count; i++) {
            const lm_light *l = &s->lights[i];
            fprintf(w->doc.json, "%s", i ? "," : "");
            lm_gltf_light(w->doc.json, l->name, (int)l->type, l->color, l->off ? 0.0f : l->intensity, /* as baked */
                          l->range, l->inner_cone, l->outer_cone);
        }
        fprintf(w->doc.json, "]}}");
    }
    if (!s->camera_count)
        return;
    fprintf(w->doc.json, ",\"cameras\":[");
    for (int i = 0; i < s->camera_count; i++) {
        const lm_camera *c = &s->cameras[i];
        fprintf(w->doc.json, "%s{\"name\":", i ? "," : "");
        lm_gltf_string(w->doc.json, c->name);
        if (c->perspective) {
            fprintf(w->doc.json, ",\"type\":\"perspective\",\"perspective\":{\"yfov\":%.9g,\"znear\":%.9g", (double)c->yfov,
                    (double)c->znear);
            if (c->aspect > 0.0f)
                fprintf(w->doc.json, ",\"aspectRatio\":%.9g", (double)c->aspect);
        } else {
            fprintf(w->doc.json, ",\"type\":\"orthographic\",\"orthographic\":{\"xmag\":%.9g,\"ymag\":%.9g,\"znear\":%.9g",
                    (double)c->xmag, (double)c->ymag, (double)c->znear);
        }
        if (c->zfar > 0.0f || !c->perspective)
            fprintf(w->doc.json, ",\"zfar\":%.9g", (double)(c->zfar > 0.0f ? c->zfar : 1e6f));
        fprintf(w->doc.json, "}}");
    }
    fputc(']', w->doc.json);
}

static int float_order(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The RGBD image's scale: the 99th percentile of the valid texels' brightest channel maps to 1, so 99% of
 * them are stored with d = 1 (a loader that premultiplies alpha, as a browser's image decoder does, loses
 * nothing there) and only the brightest 1% use d < 1; never so small that the brightest clamps at RGBD's
 * 255. 1 for a black lightmap. */
static float rgbd_scale(const float *rgba, size_t pixels)
{
    float *bright = malloc(pixels * sizeof *bright), top = 0.0f;
    size_t n = 0;
    for (size_t p = 0; p < pixels; p++) {
        float m = fmaxf(rgba[4 * p], fmaxf(rgba[4 * p + 1], rgba[4 * p + 2]));
        top = fmaxf(top, m);
        if (bright && rgba[4 * p + 3] >= 0.5f)
            bright[n++] = m;
    }
    float p99 = 0.0f;
    if (n) {
        qsort(bright, n, sizeof *bright, float_order);
        p99 = bright[(size_t)(0.99 * (double)(n - 1))];
    }
    free(bright);
    float scale = fmaxf(p99, top / LM_RGBD_RANGE);
    return scale > 0.0f ? scale : 1.0f;
}

/* One page of the lightmap: the displayed IIM (irradiance, alpha = valid) as EXR, a tone-mapped PNG
 * preview, and the RGBD PNG the glTF's materials sample; rgba the page's texels. */
static lmgi_status write_page(const writer *w, const char *dir, int half, int page, const float *rgba, int pw,
                              int ph, lmgi_error *err)
{
    char path[4200], file[260];
    lmgi_image_desc d = {LMGI_TONEMAP_NEUTRAL, 0.0f, half};
    lm_export_lightmap_file(file, sizeof file, w->name, w->ep, page, ".exr");
    snprintf(path, sizeof path, "%s/%s", dir, file);
    lmgi_status st = lmgi_write_image(path, pw, ph, 4, rgba, &d, err);
    lm_export_lightmap_file(file, sizeof file, w->name, w->ep, page, ".png");
    snprintf(path, sizeof path, "%s/%s", dir, file);
    if (st == LMGI_OK)
        st = lmgi_write_image(path, pw, ph, 4, rgba, &d, err);
    if (st != LMGI_OK || w->lightmap_texture < 0)
        return st;
    uint8_t *rgbd = malloc(4 * (size_t)pw * (size_t)ph);
    if (!rgbd)
        return lm_api_refuse(err, "lmgi_export_gltf: no memory for the %d x %d RGBD lightmap", pw, ph);
    lm_encode_rgbd(rgba, (size_t)pw * (size_t)ph, w->rgbd_scale, rgbd);
    lm_export_lightmap_file(file, sizeof file, w->name, w->ep, page, "_rgbd.png");
    snprintf(path, sizeof path, "%s/%s", dir, file);
    lm_error e;
    st = lm_write_png(path, pw, ph, rgbd, &e) == LM_OK ? LMGI_OK : lm_export_error(err, &e);
    free(rgbd);
    return st;
}

/* The lightmap's pages, each cut from the atlas (one page: the atlas as it is). */
static lmgi_status write_lightmap(const writer *w, const char *dir, int half, lmgi_error *err)
{
    const lm_atlas *a = w->atlas;
    if (w->ep->pages == 1)
        return write_page(w, dir, half, 0, w->lightmap, a->width, a->height, err);
    float *page = malloc(4 * sizeof *page * (size_t)a->page_width * a->page_height);
    lmgi_status st = page ? LMGI_OK : lm_api_refuse(err, "lmgi_export_gltf: no memory for a %d x %d lightmap page",
                                                    a->page_width, a->page_height);
    for (int p = 0; st == LMGI_OK && p < w->ep->pages; p++) {
        int r[4];
        lm_atlas_page_rect(a, p, r);
        for (int y = 0; y < r[3]; y++)
            memcpy(page + 4 * (size_t)y * r[2], w->lightmap + 4 * ((size_t)(r[1] + y) * a->width + r[0]),
                   4 * sizeof *page * (size_t)r[2]);
        st = write_page(w, dir, half, p, page, r[2], r[3], err);
    }
    free(page);
    return st;
}

/* The extensions the document uses (KHR_materials_ior always: every material states its IOR). */
static void write_extensions_used(writer *w)
{
    const lm_scene *s = w->s;
    int strength = 0, transmission = 0, transform = 0;
    for (int i = 0; i < s->material_count; i++) {
        const lm_material *m = &s->materials[i];
        strength |= fmaxf(m->emissive[0], fmaxf(m->emissive[1], m->emissive[2])) > 1.0f;
        transmission |= m->transmission > 0.0f;
        transform |= (m->base_color_tex >= 0 || m->emissive_tex >= 0) &&
                     (m->uv_offset[0] != 0.0f || m->uv_offset[1] != 0.0f || m->uv_scale[0] != 1.0f ||
                      m->uv_scale[1] != 1.0f || m->uv_rotation != 0.0f);
    }
    fprintf(w->doc.json, ",\"extensionsUsed\":[\"KHR_materials_ior\"%s%s%s%s%s]",
            s->light_count ? ",\"KHR_lights_punctual\"" : "", strength ? ",\"KHR_materials_emissive_strength\"" : "",
            transmission ? ",\"KHR_materials_transmission\"" : "", transform ? ",\"KHR_texture_transform\"" : "",
            w->lightmap_texture >= 0 ? ",\"LMGI_lightmap\"" : "");
}

/* The sky into the document's extras as the loader reads it back (docs/levels.md, "Sky"); an image sky's
 * image beside the document as NAME_sky.exr. */
static lm_status write_sky(writer *w, const char *dir, lm_error *err)
{
    const lm_scene *s = w->s;
    if (!s->has_sky)
        return LM_OK;
    if (s->sky_kind == LM_SKY_GRADIENT) {
        fprintf(w->doc.json, ",\"sky\":{\"zenith\":[%.9g,%.9g,%.9g],\"horizon\":[%.9g,%.9g,%.9g]}", (double)s->sky[0],
                (double)s->sky[1], (double)s->sky[2], (double)s->sky_horizon[0], (double)s->sky_horizon[1],
                (double)s->sky_horizon[2]);
        return LM_OK;
    }
    if (s->sky_kind == LM_SKY_IMAGE && s->sky_image) { /* one scale for all channels: the API's */
        char path[4200];
        snprintf(path, sizeof path, "%s/%s_sky.exr", dir, w->name);
        fprintf(w->doc.json, ",\"sky\":{\"image\":\"%s_sky.exr\",\"scale\":%.9g}", w->name, (double)s->sky[0]);
        return lm_write_exr(path, s->sky_width, s->sky_height, 3, s->sky_image, err);
    }
    fprintf(w->doc.json, ",\"sky\":[%.9g,%.9g,%.9g]", (double)s->sky[0], (double)s->sky[1], (double)s->sky[2]);
    return LM_OK;
}

/* The lightmap's files in the document's extras: "lightmap", "preview", "rgbd", or with several pages a list
 * of them, one a page ("pages"). */
static void write_lightmap_files(writer *w)
{
    static const char *const key[3] = {"lightmap", "preview", "rgbd"}, *const what[3] = {".exr", ".png", "_rgbd.png"};
    if (w->ep->pages > 1)
        fprintf(w->doc.json, "\"pages\":[");
    for (int p = 0; p < w->ep->pages; p++) {
        fprintf(w->doc.json, "%s", w->ep->pages == 1 ? "" : p ? ",{" : "{");
        for (int k = 0; k < 3; k++) {
            char file[260];
            lm_export_lightmap_file(file, sizeof file, w->name, w->ep, p, what[k]);
            fprintf(w->doc.json, "%s\"%s\":\"%s\"", k ? "," : "", key[k], file);
        }
        fprintf(w->doc.json, "%s", w->ep->pages == 1 ? "" : "}");
    }
    if (w->ep->pages > 1)
        fputc(']', w->doc.json);
}

/* Everything but the images into w's document. */
static lm_status write_document(writer *w, const char *dir, lm_error *err)
{
    const lm_scene *s = w->s;
    int *mesh_of = malloc(sizeof *mesh_of * (size_t)(s->node_count ? s->node_count : 1));
    if (!mesh_of)
        return lm_fail(err, LM_ERR_NOMEM, "export: no memory");
    fprintf(w->doc.json, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"lmgi\"}");
    write_extensions_used(w);
    lm_status st = write_meshes(w, mesh_of, err);
    if (st == LM_OK) {
        write_nodes(w, mesh_of);
        write_materials(w);
        write_lights_and_cameras(w);
        st = write_textures(w, dir, err);
    }
    free(mesh_of);
    if (st != LM_OK)
        return st;
    char bin_uri[260];
    snprintf(bin_uri, sizeof bin_uri, "%s.bin", w->name);
    lm_gltf_finish(&w->doc, bin_uri);
    fprintf(w->doc.json, ",\"extras\":{\"lmgi\":{");
    write_lightmap_files(w);
    fprintf(w->doc.json, ",\"texCoord\":1,\"size\":[%d,%d],\"holds\":\"irradiance E of indirect light, emissive "
                     "surfaces and the sky (not the punctual lights' direct light); diffuse radiance = baseColor / pi x "
                     "E; alpha 1 on valid texels\"", w->atlas->page_width, w->atlas->page_height);
    st = write_sky(w, dir, err);
    fputs("}}}", w->doc.json);
    return st;
}

/* The export's file name: letters, digits, '-', '_' and '.', so it is a plain relative URI. */
static int plain_name(const char *name)
{
    if (!name[0] || strlen(name) > 200 || name[0] == '.')
        return 0;
    for (const char *c = name; *c; c++)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '-' ||
              *c == '_' || *c == '.'))
            return 0;
    return 1;
}

static lmgi_status export_owned(lmgi_updater *u, const char *dir, const lmgi_export_desc *desc, lmgi_error *err)
{
    static const char fn[] = "lmgi_export_gltf";
    if (!u || (!dir && !(desc && desc->output)))
        return lm_api_refuse(err, "%s: %s is NULL", fn, u ? "dir" : "updater");
    lmgi_export_desc d;
    memset(&d, 0, sizeof d);
    if (desc)
        d = *desc;
    const char *name = d.name ? d.name : "scene";
    if (!plain_name(name))
        return lm_api_refuse(err, "%s: name '%s' must be 1 to 200 of a-z A-Z 0-9 - _ . and not start with '.'", fn,
                             name);
    const lmgi_scene *sc = lm_updater_scene(u);
    lmgi_output *own = NULL; /* the export's own output, when the caller gave none */
    if (!d.output) {
        const char *const inputs[] = {sc->scene->path, NULL};
        lmgi_status st = lmgi_output_open(dir, "export", d.force, inputs, &own, err);
        if (st != LMGI_OK)
            return st;
    }
    lmgi_output *out = d.output ? d.output : own;
    char path[4200];
    for (int k = 0; k < 2; k++) { /* the scene's own file or a user's in the way: refused before the work */
        char file[260];
        snprintf(file, sizeof file, "%s.%s", name, k ? "bin" : "gltf");
        lmgi_status st = lmgi_output_file(out, file, path, sizeof path, err);
        if (st != LMGI_OK) {
            lmgi_output_abort(own);
            return st;
        }
    }
    dir = lmgi_output_folder(out);
    lm_export_pages ep;
    lm_error e;
    if (lm_export_pages_make(sc->scene, &sc->atlas, &ep, &e) != LM_OK) {
        lmgi_output_abort(own);
        return lm_export_error(err, &e);
    }
    writer w = {.s = sc->scene, .atlas = &sc->atlas, .name = name, .ep = &ep, .lightmap_texture = -1};
    size_t pixels = (size_t)w.atlas->width * (size_t)w.atlas->height;
    float *lightmap = malloc(4 * pixels * sizeof *lightmap);
    uint8_t *lit = calloc((size_t)w.s->material_count + 1, 1);
    lmgi_status st = lightmap && lit ? lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, lightmap, 4 * pixels, err)
                                     : lm_api_refuse(err, "%s: no memory for the %d x %d lightmap", fn,
                                                     w.atlas->width, w.atlas->height);
    if (st != LMGI_OK) {
        free(lightmap);
        free(lit);
        lm_export_pages_free(&ep);
        lmgi_output_abort(own);
        return st;
    }
    for (uint32_t t = 0; t < w.s->tri_count; t++) /* one pass, not one per material */
        lit[w.s->tri_material[t]] |= w.atlas->tri_chart[t] >= 0;
    w.material_lit = lit;
    w.lightmap = lightmap;
    w.rgbd_scale = rgbd_scale(lightmap, pixels);
    if (w.atlas->texel_count)
        w.lightmap_texture = w.s->texture_count;
    lm_status ls = lm_gltf_open(&w.doc) ? LM_OK : lm_fail(&e, LM_ERR_NOMEM, "export: no memory");
    if (ls == LM_OK)
        ls = write_document(&w, dir, &e);
    size_t json_len = 0, bin_len = 0;
    const char *json = ls == LM_OK ? lm_gltf_text(&w.doc, &json_len) : NULL;
    const void *bin = ls == LM_OK ? lm_gltf_bin(&w.doc, &bin_len) : NULL;
    if (ls == LM_OK && (!json || !bin))
        ls = lm_fail(&e, LM_ERR_NOMEM, "export: no memory for the document");
    if (ls == LM_OK) {
        snprintf(path, sizeof path, "%s/%s.bin", dir, name);
        ls = lm_write_file(path, bin, bin_len, &e);
    }
    if (ls == LM_OK) {
        snprintf(path, sizeof path, "%s/%s.gltf", dir, name);
        ls = lm_write_file(path, json, json_len, &e);
    }
    lm_gltf_close(&w.doc);
    st = ls == LM_OK ? write_lightmap(&w, dir, d.half, err) : lm_export_error(err, &e);
    free(lightmap);
    free(lit);
    lm_export_pages_free(&ep);
    if (own && st == LMGI_OK)
        return lmgi_output_commit(own, err);
    lmgi_output_abort(own);
    return st;
}

lmgi_status lmgi_export_gltf(lmgi_updater *u, const char *dir, const lmgi_export_desc *desc, lmgi_error *err)
{
    if (!u)
        return export_owned(u, dir, desc, err); /* refused there, naming it */
    lmgi_status st = lm_api_claim(lm_updater_context(u), "lmgi_export_gltf", err);
    if (st != LMGI_OK)
        return st;
    st = lm_scene_commit(lm_updater_scene(u), err); /* the scene with every edit made so far */
    if (st == LMGI_OK)
        st = export_owned(u, dir, desc, err);
    lm_api_release(lm_updater_context(u));
    return st;
}
