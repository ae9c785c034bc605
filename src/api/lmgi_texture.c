/* lmgi_get_lightmap_texture: the displayed IIM as a GL texture of lmgi's context, for a host whose context
 * shares objects with it (docs/api.md, "The lightmap as a GL texture"). The texture is filled the way an
 * engine would fill its own: the whole atlas once, then the rectangles of the surfaces whose version
 * moved, each read with lmgi_get_lightmap_rect (so it holds lmgi_get_lightmap's values, filled and
 * dilated, bit for bit) and uploaded with glTexSubImage2D. */
#include <lmgi.h>

#include <stdlib.h>
#include <string.h>

#include "../gpu/gl/gl_api.h"
#include "lmgi_context.h"
#include "lmgi_scene.h"
#include "lmgi_updater.h"

struct lm_lightmap_texture {
    GLuint name;
    uint32_t *versions; /* per surface: lmgi_surface_version at its last upload */
};

void lm_lightmap_texture_free(lm_lightmap_texture *t)
{
    if (!t)
        return;
    if (t->name)
        glDeleteTextures(1, &t->name);
    free(t->versions);
    free(t);
}

/* The IIM in rect read into buf (which holds it) and uploaded to the texture at its place. */
static lmgi_status upload(lmgi_updater *u, const lm_lightmap_texture *t, const int rect[4], float *buf,
                          lmgi_error *err)
{
    lmgi_status st = lmgi_get_lightmap_rect(u, LMGI_LIGHTMAP_IIM, rect, buf, 4 * (size_t)rect[2] * rect[3], err);
    if (st != LMGI_OK)
        return st;
    lm_error e;
    if (lm_gl_make_current(lm_updater_context(u)->gl, &e) != LM_OK)
        return lm_export_error(err, &e);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glBindTexture(GL_TEXTURE_2D, t->name);
    glTexSubImage2D(GL_TEXTURE_2D, 0, rect[0], rect[1], rect[2], rect[3], GL_RGBA, GL_FLOAT, buf);
    glBindTexture(GL_TEXTURE_2D, 0);
    return LMGI_OK;
}

/* The texture made (storage, sampling) and filled whole. */
static lmgi_status create(lmgi_updater *u, lm_lightmap_texture **out, lmgi_error *err)
{
    const lm_atlas *at = &lm_updater_scene(u)->atlas;
    lm_lightmap_texture *t = calloc(1, sizeof *t);
    float *all = malloc(4 * sizeof(float) * (size_t)at->width * at->height);
    if (t)
        t->versions = calloc((size_t)at->surface_count + 1, sizeof *t->versions);
    if (!t || !all || !t->versions) {
        free(all);
        lm_lightmap_texture_free(t);
        return lm_api_refuse(err, "lmgi_get_lightmap_texture: no memory for the %d x %d lightmap", at->width,
                             at->height);
    }
    lm_error e;
    if (lm_gl_make_current(lm_updater_context(u)->gl, &e) != LM_OK) {
        free(all);
        lm_lightmap_texture_free(t);
        return lm_export_error(err, &e);
    }
    glGenTextures(1, &t->name);
    glBindTexture(GL_TEXTURE_2D, t->name);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, at->width, at->height);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    const int whole[4] = {0, 0, at->width, at->height};
    lmgi_status st = upload(u, t, whole, all, err);
    free(all);
    if (st != LMGI_OK) {
        lm_lightmap_texture_free(t);
        return st;
    }
    for (int s = 0; s < at->surface_count; s++)
        t->versions[s] = lmgi_surface_version(u, s);
    *out = t;
    return LMGI_OK;
}

/* The rectangles of the surfaces whose version moved since their last upload, each read and uploaded. */
static lmgi_status refresh(lmgi_updater *u, lm_lightmap_texture *t, lmgi_error *err)
{
    const lmgi_scene *sc = lm_updater_scene(u);
    float *buf = NULL;
    size_t held = 0;
    lmgi_status st = LMGI_OK;
    for (int s = 0; s < sc->atlas.surface_count && st == LMGI_OK; s++) {
        uint32_t now = lmgi_surface_version(u, s);
        int rect[4];
        if (now == t->versions[s] || !lmgi_surface_lightmap_rect(sc, s, rect))
            continue;
        size_t need = 4 * (size_t)rect[2] * rect[3];
        if (need > held) {
            float *grown = realloc(buf, need * sizeof *buf);
            if (!grown) {
                st = lm_api_refuse(err, "lmgi_get_lightmap_texture: no memory for a %d x %d rectangle", rect[2],
                                   rect[3]);
                break;
            }
            buf = grown;
            held = need;
        }
        st = upload(u, t, rect, buf, err);
        if (st == LMGI_OK)
            t->versions[s] = now;
    }
    free(buf);
    return st;
}

lmgi_status lmgi_get_lightmap_texture(lmgi_updater *u, unsigned *texture, lmgi_error *err)
{
    static const char fn[] = "lmgi_get_lightmap_texture";
    if (texture)
        *texture = 0;
    if (!u || !texture)
        return lm_api_refuse(err, "%s: %s is NULL", fn, u ? "texture" : "the updater");
    lmgi_status st = lm_api_claim(lm_updater_context(u), fn, err);
    if (st != LMGI_OK)
        return st;
    lm_lightmap_texture **t = lm_updater_texture(u);
    st = *t ? refresh(u, *t, err) : create(u, t, err);
    if (st == LMGI_OK) {
        lm_error e;
        if (lm_gl_make_current(lm_updater_context(u)->gl, &e) != LM_OK) {
            st = lm_export_error(err, &e);
        } else {
            glFinish(); /* another context may sample it as soon as this returns */
            *texture = (*t)->name;
        }
    }
    lm_api_release(lm_updater_context(u));
    return st;
}
