#include "scene_load.h"

#include <string.h>

static float g_sky[3];
static int g_has_sky;

void lm_cli_set_sky(const float sky[3])
{
    memcpy(g_sky, sky, sizeof g_sky);
    g_has_sky = 1;
}

int lm_cli_load_scene(const char *path, const lmgi_options *o, int lit, lmgi_scene **sc)
{
    lmgi_error err;
    if (lmgi_load(path, o, sc, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return 0;
    }
    if (g_has_sky && lmgi_set_environment(*sc, g_sky, &err) != LMGI_OK) {
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
    return 1;
}
