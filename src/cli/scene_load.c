#include "scene_load.h"

#include <string.h>

static struct {
    lm_cli_sky kind; /* LM_CLI_SKY_NONE: no --sky */
    float zenith[3], horizon[3];
    const char *image;
} g_sky;

void lm_cli_set_sky(lm_cli_sky kind, const float zenith[3], const float horizon[3], const char *image)
{
    g_sky.kind = kind;
    if (zenith)
        memcpy(g_sky.zenith, zenith, sizeof g_sky.zenith);
    if (horizon)
        memcpy(g_sky.horizon, horizon, sizeof g_sky.horizon);
    g_sky.image = image;
}

const char *lm_cli_sky_image(void)
{
    return g_sky.kind == LM_CLI_SKY_IMAGE ? g_sky.image : NULL;
}

int lm_cli_scene_unlit(const lmgi_scene *sc)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    float sky[3];
    return in.lights == 0 && in.materials_by_class[4] == 0 && !lmgi_get_environment(sc, sky);
}

static lmgi_status set_sky(lmgi_scene *sc, lmgi_error *err)
{
    switch (g_sky.kind) {
    case LM_CLI_SKY_UNIFORM:
        return lmgi_set_environment(sc, g_sky.zenith, err);
    case LM_CLI_SKY_GRADIENT:
        return lmgi_set_environment_gradient(sc, g_sky.zenith, g_sky.horizon, err);
    case LM_CLI_SKY_IMAGE:
        return lmgi_set_environment_image(sc, g_sky.image, 1.0f, err);
    default:
        return LMGI_OK;
    }
}

int lm_cli_load_scene(const char *path, const lmgi_options *o, int lit, lmgi_scene **sc)
{
    lmgi_error err;
    if (lmgi_load(path, o, sc, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return 0;
    }
    if (set_sky(*sc, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: --sky: %s\n", err.message);
        lmgi_free(*sc);
        *sc = NULL;
        return 0;
    }
    lmgi_info in;
    lmgi_get_info(*sc, &in);
    if (lit && in.triangles == 0) {
        fprintf(stderr, "lmgi: error: %s: the scene is empty (no triangles): nothing to light\n", path);
        lmgi_free(*sc);
        *sc = NULL;
        return 0;
    }
    float sky[3];
    if (lit && lm_cli_scene_unlit(*sc) && !lmgi_get_environment(*sc, sky))
        fprintf(stderr, "lmgi: warning: %s: the scene has no light (no light, no emissive material and no sky): "
                "its lightmaps and pictures are black, and nothing is gathered; give it a light, or a sky with "
                "--sky\n", path);
    return 1;
}
