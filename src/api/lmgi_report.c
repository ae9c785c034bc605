/* What the public API reports about a loaded scene: counts, effects, and the charts pictures. */
#include <lmgi_tools.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../charts/atlas_image.h"
#include "../core/image.h"
#include "../scene/scene_view.h"
#include "../gpu/gl/gl_context.h"
#include "../gpu/frame/surface_view.h"
#include "lmgi_scene.h"

void lmgi_get_info(const lmgi_scene *sc, lmgi_info *in)
{
    if (!in)
        return;
    memset(in, 0, sizeof *in);
    if (!sc)
        return;
    lm_scene_commit(sc, NULL); /* the edits staged so far in what it counts (a failure: counted as it was) */
    const lm_scene *s = sc->scene;
    in->triangles = s->tri_twin ? s->file_tri_count : s->tri_count;
    in->back_triangles = s->tri_count - in->triangles;
    in->vertices = s->vertex_count;
    in->nodes = s->node_count;
    for (int n = 0; n < s->node_count; n++)
        in->dynamic_nodes += s->nodes[n].dynamic;
    in->meshes = s->mesh_count;
    in->materials = s->material_count;
    for (int m = 0; m < s->material_count; m++)
        in->materials_by_class[s->materials[m].cls]++;
    in->textures = s->texture_count;
    for (int l = 0; l < s->light_count; l++)
        if (!s->lights[l].removed)
            in->lights++, in->lights_by_type[s->lights[l].type]++;
    in->cameras = s->camera_count;
    in->animations = s->animation_count;
    for (int a = 0; a < s->animation_count; a++)
        in->animation_seconds = fmaxf(in->animation_seconds, s->animations[a].duration);
    in->surfaces = sc->surfaces.surface_count;
    in->charts = sc->atlas.chart_count;
    in->degenerate_triangles = sc->surfaces.degenerate_tris;
    in->nonmanifold_edges = sc->surfaces.nonmanifold_edges;
    in->atlas_width = sc->atlas.width;
    in->atlas_height = sc->atlas.height;
    in->pages = sc->atlas.page_count;
    in->page_width = sc->atlas.page_width;
    in->page_height = sc->atlas.page_height;
    in->texels = sc->atlas.texel_count;
    in->texel_size = sc->atlas.texel_size;
    in->utilization = sc->atlas.page_utilization;
    for (int k = 0; k < 3; k++) /* in the file's coordinates */
        in->bounds_min[k] = s->bounds_min[k] + s->origin[k], in->bounds_max[k] = s->bounds_max[k] + s->origin[k];
    in->timings = sc->timings;
}

int lmgi_effect_count(const lmgi_scene *sc)
{
    return sc ? LM_EFFECT_COUNT : 0;
}

void lmgi_get_effect(const lmgi_scene *sc, int i, lmgi_effect *out)
{
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    if (!sc || i < 0 || i >= LM_EFFECT_COUNT)
        return;
    lm_scene_commit(sc, NULL); /* the effects that the edits staged so far call for */
    out->name = lm_effect_name((lm_effect_id)i);
    out->on = sc->effects.on[i];
    snprintf(out->reason, sizeof out->reason, "%s", sc->effects.reason[i]);
}

/* A level's thousands of materials, lights and moving nodes would fill pages: each list shows its first
 * LIST_MAX entries in the order that matters (for materials, the classes that switch effects on first)
 * and says how many more there are; the totals above each list count them all. */
#define LIST_MAX 12

static void print_more(FILE *f, int more, const char *what)
{
    if (more > 0)
        fprintf(f, "  ... and %d more %s\n", more, what);
}

static void print_materials(const lm_scene *s, const lmgi_info *in, FILE *f)
{
    static const lm_material_class order[] = {LM_MAT_EMITTER, LM_MAT_GLASS, LM_MAT_MIRROR, LM_MAT_GLOSSY,
                                              LM_MAT_DIFFUSE};
    fprintf(f, "materials   %d:", in->materials);
    for (int c = 0; c < LM_MAT_CLASS_COUNT; c++)
        if (in->materials_by_class[c])
            fprintf(f, " %d %s", in->materials_by_class[c], lm_material_class_name((lm_material_class)c));
    int missing = 0;
    for (int m = 0; m < s->material_count; m++)
        missing += s->materials[m].missing_textures > 0;
    if (missing)
        fprintf(f, "; %d with a texture missing or undecodable (their factors alone are used)", missing);
    fputc('\n', f);
    int shown = 0;
    for (size_t k = 0; k < sizeof order / sizeof order[0]; k++)
        for (int m = 0; m < s->material_count && shown < LIST_MAX; m++) {
            const lm_material *mat = &s->materials[m];
            if (mat->cls != order[k])
                continue;
            fprintf(f, "  %-28s %-8s base (%.2f %.2f %.2f)%s%s\n", mat->name, lm_material_class_name(mat->cls),
                    (double)mat->base_color[0], (double)mat->base_color[1], (double)mat->base_color[2],
                    mat->base_color_tex >= 0 ? " + texture" : "",
                    mat->missing_textures ? " (a texture is missing or undecodable: its factor alone is used)" : "");
            shown++;
        }
    print_more(f, s->material_count - shown, "materials");
}

static void print_nodes(const lm_scene *s, const lmgi_info *in, FILE *f)
{
    fprintf(f, "nodes       %d (%d static, %d dynamic)\n", in->nodes, in->nodes - in->dynamic_nodes,
            in->dynamic_nodes);
    int shown = 0;
    for (int n = 0; n < s->node_count && shown < LIST_MAX; n++)
        if (s->nodes[n].dynamic) {
            fprintf(f, "  dynamic: '%s' (%u triangles)\n", s->nodes[n].name, s->nodes[n].tri_count);
            shown++;
        }
    print_more(f, in->dynamic_nodes - shown, "dynamic nodes");
}

static void print_lights(const lm_scene *s, const lmgi_info *in, FILE *f)
{
    fprintf(f, "lights      %d (%d point, %d spot, %d directional)\n", in->lights, in->lights_by_type[0],
            in->lights_by_type[1], in->lights_by_type[2]);
    int shown = 0;
    for (int l = 0; l < s->light_count && shown < LIST_MAX; l++) {
        const lm_light *li = &s->lights[l];
        if (li->removed)
            continue;
        fprintf(f, "  %-12s '%s' intensity %g colour (%.2f %.2f %.2f)", lm_light_type_name(li->type), li->name,
                (double)li->intensity, (double)li->color[0], (double)li->color[1], (double)li->color[2]);
        if (li->range > 0.0f && li->type != LM_LIGHT_DIRECTIONAL)
            fprintf(f, " range %g", (double)li->range);
        fputc('\n', f);
        shown++;
    }
    print_more(f, in->lights - shown, "lights");
}

void lmgi_print_info(const lmgi_scene *sc, FILE *f)
{
    if (!sc || !f)
        return;
    lm_scene_commit(sc, NULL);
    const lm_scene *s = sc->scene;
    lmgi_info in;
    lmgi_get_info(sc, &in);
    fprintf(f, "scene       %s\n", s->path);
    fprintf(f, "triangles   %u (%u vertices, %d meshes)", in.triangles, in.vertices, in.meshes);
    if (in.back_triangles)
        fprintf(f, ", and %u back sides of double-sided surfaces", in.back_triangles);
    fputc('\n', f);
    if (in.triangles == 0)
        fprintf(f, "bounds      none: the scene is empty (no triangles)\n");
    else
        fprintf(f, "bounds      (%.4g %.4g %.4g) .. (%.4g %.4g %.4g)\n", (double)in.bounds_min[0],
                (double)in.bounds_min[1], (double)in.bounds_min[2], (double)in.bounds_max[0],
                (double)in.bounds_max[1], (double)in.bounds_max[2]);
    print_nodes(s, &in, f);
    print_materials(s, &in, f);
    print_lights(s, &in, f);
    if (s->has_sky && s->sky_kind == LM_SKY_GRADIENT)
        fprintf(f, "sky         gradient, radiance (%.4g %.4g %.4g) at the zenith, (%.4g %.4g %.4g) at the horizon\n",
                (double)s->sky[0], (double)s->sky[1], (double)s->sky[2], (double)s->sky_horizon[0],
                (double)s->sky_horizon[1], (double)s->sky_horizon[2]);
    else if (s->has_sky && s->sky_kind == LM_SKY_IMAGE)
        fprintf(f, "sky         HDR image, %d x %d, scale %.4g\n", s->sky_width, s->sky_height, (double)s->sky[0]);
    else if (s->has_sky)
        fprintf(f, "sky         uniform radiance (%.4g %.4g %.4g)\n", (double)s->sky[0], (double)s->sky[1],
                (double)s->sky[2]);
    fprintf(f, "cameras     %d, animations %d", in.cameras, in.animations);
    if (in.animations)
        fprintf(f, " (%.3g s)", (double)in.animation_seconds);
    fprintf(f, ", textures %d\n", in.textures);
    fprintf(f, "surfaces    %d (%u degenerate triangles dropped, %u non-manifold edges)\n", in.surfaces,
            in.degenerate_triangles, in.nonmanifold_edges);
    fprintf(f, "charts      %d\n", in.charts);
    if (in.pages > 1)
        fprintf(f, "atlas       %d pages of %d x %d (side by side in a %d x %d atlas), texel %.4g units, %u texels, "
                "utilization %.1f%% of the pages\n", in.pages, in.page_width, in.page_height, in.atlas_width,
                in.atlas_height, (double)in.texel_size, in.texels, 100.0 * (double)in.utilization);
    else
        fprintf(f, "atlas       %d x %d, texel %.4g units, %u texels, utilization %.1f%%\n", in.atlas_width,
                in.atlas_height, (double)in.texel_size, in.texels, 100.0 * (double)in.utilization);
    if (sc->atlas.bent_surfaces > 0)
        fprintf(f, "            finer texels on %d surfaces whose shading normals bend (--bend; docs/charts.md)\n",
                sc->atlas.bent_surfaces);
    if (sc->atlas.open_surfaces > 0)
        fprintf(f, "            coarser texels on %d surfaces that see mostly open sky (--open-need; docs/charts.md)\n",
                sc->atlas.open_surfaces);
    uint32_t pieces = 0;
    for (uint32_t i = 0; sc->atlas.footprint_first && i < sc->atlas.texel_count; i++)
        pieces += sc->atlas.footprint_first[i + 1] > sc->atlas.footprint_first[i];
    if (pieces > 0)
        fprintf(f, "            %u texels stand for curved pieces and are gathered at %u points spread over them "
                "(docs/charts.md, \"Footprints\")\n", pieces, sc->atlas.footprint_count);
    fprintf(f, "effects\n");
    for (int i = 0; i < LM_EFFECT_COUNT; i++)
        fprintf(f, "  %s: %s — %s\n", lm_effect_name((lm_effect_id)i), sc->effects.on[i] ? "on" : "off",
                sc->effects.reason[i]);
    fprintf(f, "time        load %.3f s, surfaces %.3f s, atlas %.3f s, BVH %.3f s, total %.3f s\n", in.timings.load,
            in.timings.surfaces, in.timings.atlas, in.timings.bvh, in.timings.total);
}

static lm_status draw_surface_view(const lmgi_scene *sc, const char *path, int w, int h, lm_error *e)
{
    uint8_t *img = malloc((size_t)w * h * 4);
    if (!img)
        return lm_fail(e, LM_ERR_NOMEM, "no memory for a %dx%d picture", w, h);
    lm_view view;
    lm_view_for_scene(sc->scene, -1, w, h, &view);
    lm_status st = lm_render_surface_ids(sc->scene, &sc->surfaces, &view, w, h, img, e);
    if (st == LM_OK)
        st = lm_write_png(path, w, h, img, e);
    free(img);
    return st;
}

/* On a GL context of its own, the host's given back after (gl_context.h, the guest scope). */
static lm_status write_surface_view(const lmgi_scene *sc, const char *path, int w, int h, lm_error *e)
{
    lm_gl_context *gl = NULL;
    lm_gl_guest_enter();
    lm_status st = lm_gl_context_create(&gl, e);
    if (st == LM_OK)
        st = draw_surface_view(sc, path, w, h, e);
    lm_gl_context_destroy(gl);
    lm_gl_guest_leave();
    return st;
}

lmgi_status lmgi_write_charts(const lmgi_scene *sc, const char *dir, int width, int height, lmgi_error *err)
{
    lm_error e;
    lm_error_clear(&e);
    if (!sc || !dir) {
        lm_fail(&e, LM_ERR_INVALID, "lmgi_write_charts: %s is NULL", sc ? "the directory" : "the scene");
        return lm_export_error(err, &e);
    }
    if (width <= 0 || height <= 0) {
        width = 1024;
        height = 768;
    }
    char path[4096];
    lm_status st = lm_mkdir_p(dir, &e);
    if (st == LM_OK) {
        uint8_t *img = lm_atlas_chart_image(&sc->atlas);
        snprintf(path, sizeof path, "%s/atlas.png", dir);
        st = img ? lm_write_png(path, sc->atlas.width, sc->atlas.height, img, &e)
                 : lm_fail(&e, LM_ERR_NOMEM, "no memory for the atlas picture");
        free(img);
    }
    if (st == LM_OK) {
        snprintf(path, sizeof path, "%s/surfaces.png", dir);
        st = write_surface_view(sc, path, width, height, &e);
    }
    return st == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}
