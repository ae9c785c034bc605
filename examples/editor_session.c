/* A level editor's session, through include/lmgi.h
 * (and include/lmgi_tools.h for its pictures and output directory).
 *
 * Loads a scene and bakes it with a progress bar (the updater's creation is the first bake), then does
 * what an artist does: recolours a wall, moves a light, adds a lamp below it, and re-bakes after each
 * edit; each re-bake redoes only what the edit reached and says how much. Writes the lightmap after each bake, a picture from
 * the scene's camera at the end, and exports the edited level for an engine: OUT_DIR/level.gltf with
 * the lightmap's UVs as TEXCOORD_1 and level_lightmap.exr beside it.
 *
 *   editor_session SCENE OUT_DIR [--material NAME] [--light NODE] [--texels N]
 *
 * --material names the material to recolour (default: the first diffuse one), --light the node of the
 * light to move (default: the first light's), --texels the lightmap's texel count (default 65536). */
#include <lmgi_tools.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A progress bar on stderr; the line ends when the work reaches 100%. */
static void show(void *user, float fraction, const char *stage)
{
    static float last = 1.0f;
    if (fraction >= 1.0f && last >= 1.0f) /* a second report of the end */
        return;
    const char *what = user;
    int filled = (int)(30.0f * fraction);
    fprintf(stderr, "\r%-10s [%.*s%*s] %3d%% %-8s", what, filled, "##############################", 30 - filled, "",
            (int)(100.0f * fraction), stage);
    if (fraction >= 1.0f)
        fputc('\n', stderr);
    last = fraction;
}

static int fail(const char *what, const lmgi_error *e)
{
    fprintf(stderr, "editor_session: %s: %s\n", what, e->message);
    return 1;
}

static int save(lmgi_scene *sc, lmgi_updater *u, lmgi_output *out, const char *name)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *rgba = malloc(n * sizeof *rgba);
    char path[4200];
    lmgi_error e;
    int rc = 0;
    if (!rgba)
        rc = 1;
    else if (lmgi_output_file(out, name, path, sizeof path, &e) != LMGI_OK ||
             lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, rgba, n, &e) != LMGI_OK ||
             lmgi_write_image(path, in.atlas_width, in.atlas_height, 4, rgba, NULL, &e))
        rc = fail(name, &e);
    free(rgba);
    return rc;
}

static int rebake(lmgi_updater *u, const char *what)
{
    lmgi_bake_desc d = {.progress = show, .progress_user = (void *)what};
    lmgi_bake_report r;
    lmgi_error e;
    if (lmgi_bake(u, &d, &r, &e) != LMGI_OK)
        return fail("bake", &e);
    printf("%-10s %u of %u photon paths changed, %d AIM surfaces refreshed, %u texels regathered (%d surfaces), "
           "%.0f ms\n", what, r.photons_changed, r.photons_traced, r.aim_surfaces_refreshed, r.texels_gathered,
           r.surfaces_changed, r.ms_total);
    return 0;
}

static int find_material(const lmgi_scene *sc, const char *name)
{
    for (int m = 0; m < lmgi_material_count(sc); m++) {
        lmgi_material mat;
        if (lmgi_get_material(sc, m, &mat, NULL) != LMGI_OK)
            continue;
        if (name ? !strcmp(lmgi_material_name(sc, m), name) : mat.cls == LMGI_MATERIAL_DIFFUSE)
            return m;
    }
    return -1;
}

static int find_light(const lmgi_scene *sc, const char *node)
{
    for (int l = 0; l < lmgi_light_count(sc); l++) {
        lmgi_light li;
        if (lmgi_get_light(sc, l, &li, NULL) == LMGI_OK && (!node || !strcmp(lmgi_node_name(sc, li.node), node)))
            return l;
    }
    return -1;
}

/* The artist's edits, each followed by a re-bake and the lightmap saved. */
static int edit(lmgi_scene *sc, lmgi_updater *u, lmgi_output *out, const char *material, const char *light)
{
    lmgi_error e;
    int m = find_material(sc, material), l = find_light(sc, light);
    if (m < 0 || l < 0) {
        fprintf(stderr, "editor_session: no %s '%s'\n", m < 0 ? "material" : "light",
                m < 0 ? (material ? material : "(diffuse)") : (light ? light : "(any)"));
        return 1;
    }
    lmgi_material mat;
    lmgi_get_material(sc, m, &mat, NULL);
    const float teal[3] = {0.1f, 0.55f, 0.5f};
    memcpy(mat.base_color, teal, sizeof teal);
    if (lmgi_set_material(sc, m, &mat, &e) != LMGI_OK)
        return fail("recolour", &e);
    printf("recoloured '%s' teal\n", lmgi_material_name(sc, m));
    if (rebake(u, "recolour") || save(sc, u, out, "lightmap_recoloured.exr"))
        return 1;

    lmgi_light li;
    lmgi_get_light(sc, l, &li, NULL);
    float world[16];
    lmgi_get_node_transform(sc, li.node, world);
    world[12] += 0.25f; /* a quarter unit along x */
    if (lmgi_set_node_transform(sc, li.node, world, &e) != LMGI_OK)
        return fail("move light", &e);
    printf("moved light '%s' by 0.25 along x\n", lmgi_node_name(sc, li.node));
    if (rebake(u, "move") || save(sc, u, out, "lightmap_moved.exr"))
        return 1;

    lmgi_get_light(sc, l, &li, NULL); /* a second lamp like it, half a unit below it */
    li.position[1] -= 0.5f;
    int lamp;
    if (lmgi_add_light(sc, &li, &lamp, &e) != LMGI_OK)
        return fail("add a lamp", &e);
    printf("added light %d below '%s'\n", lamp, lmgi_node_name(sc, li.node));
    return rebake(u, "lamp") || save(sc, u, out, "lightmap_lamp.exr");
}

static int session(lmgi_context *ctx, lmgi_scene *sc, lmgi_output *out, const char *material, const char *light)
{
    lmgi_updater_desc d = {.progress = show, .progress_user = "bake"};
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        return fail("first bake", &e);
    int rc = save(sc, u, out, "lightmap.exr") || edit(sc, u, out, material, light);
    lmgi_camera cam;
    float *frame = malloc(3 * 320 * 240 * sizeof *frame);
    char path[4200];
    if (!rc && (!frame || lmgi_output_file(out, "view.png", path, sizeof path, &e) != LMGI_OK ||
                lmgi_scene_camera(sc, -1, 320, 240, &cam, &e) != LMGI_OK ||
                lmgi_render(u, &cam, 320, 240, frame, &e) != LMGI_OK ||
                lmgi_write_image(path, 320, 240, 3, frame, NULL, &e) != LMGI_OK))
        rc = fail("view", &e);
    free(frame);
    lmgi_export_desc x = {.name = "level", .output = out};
    if (!rc && lmgi_export_gltf(u, NULL, &x, &e) != LMGI_OK)
        rc = fail("export", &e);
    lmgi_updater_free(u);
    return rc;
}

int main(int argc, char **argv)
{
    const char *scene = NULL, *out = NULL, *material = NULL, *light = NULL;
    lmgi_options o;
    lmgi_options_init(&o);
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--material") && i + 1 < argc)
            material = argv[++i];
        else if (!strcmp(argv[i], "--light") && i + 1 < argc)
            light = argv[++i];
        else if (!strcmp(argv[i], "--texels") && i + 1 < argc)
            o.target_texels = atoi(argv[++i]);
        else if (argv[i][0] != '-' && !scene)
            scene = argv[i];
        else if (argv[i][0] != '-' && !out)
            out = argv[i];
        else
            scene = NULL, i = argc;
    }
    if (!scene || !out) {
        fprintf(stderr, "usage: editor_session SCENE OUT_DIR [--material NAME] [--light NODE] [--texels N]\n");
        return 2;
    }
    lmgi_context *ctx = NULL;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load(scene, &o, &sc, &e) != LMGI_OK)
        return fail(scene, &e);
    /* The session's files go beside the last session's and replace them only when it succeeds; an
     * artist's own files in OUT_DIR are never touched, and the scene is never overwritten. */
    const char *const inputs[] = {scene, NULL};
    lmgi_output *dir = NULL;
    if (lmgi_output_open(out, "editor-session", 0, inputs, &dir, &e) != LMGI_OK) {
        lmgi_free(sc);
        return fail("output", &e);
    }
    int rc = lmgi_context_create(NULL, &ctx, &e) == LMGI_OK ? session(ctx, sc, dir, material, light)
                                                            : fail("context", &e);
    if (rc) {
        lmgi_output_abort(dir);
    } else if (lmgi_output_commit(dir, &e) != LMGI_OK) {
        rc = fail("output", &e);
    } else {
        printf("wrote %s: lightmap*.exr, view.png, level.gltf with level_lightmap.exr\n", out);
    }
    lmgi_free(sc);
    lmgi_context_free(ctx);
    return rc;
}
