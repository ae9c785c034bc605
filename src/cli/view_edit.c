/* The viewer's edits and their undo (view_edit.h). */
#include "view_edit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int lm_view_history_push(lm_view_history *h, const lm_view_step *s)
{
    h->count = h->done;
    if (h->count == h->cap) {
        int cap = h->cap ? 2 * h->cap : 64;
        lm_view_step *g = realloc(h->steps, (size_t)cap * sizeof *g);
        if (!g)
            return 0;
        h->steps = g, h->cap = cap;
    }
    h->steps[h->count++] = *s;
    h->done = h->count;
    return 1;
}

void lm_view_history_free(lm_view_history *h)
{
    free(h->steps);
    memset(h, 0, sizeof *h);
}

/* Puts step s's `forward` side into the scene (1: after, redo; 0: before, undo). */
static int replay(lm_view_step *s, int forward, lmgi_scene *sc, char *what, size_t n, lmgi_error *err)
{
    const char *verb = forward ? "redone" : "undone";
    switch (s->kind) {
    case LM_VIEW_NODE:
        snprintf(what, n, "%s: node %s moved", verb, lmgi_node_name(sc, s->id));
        return lmgi_set_node_transform(sc, s->id, forward ? s->after : s->before, err) == LMGI_OK;
    case LM_VIEW_LIGHT:
        snprintf(what, n, "%s: light %d edited", verb, s->id);
        return lmgi_set_light(sc, s->id, forward ? &s->light_after : &s->light_before, err) == LMGI_OK;
    case LM_VIEW_LIGHT_ADDED:
    case LM_VIEW_LIGHT_REMOVED:
        /* added and redone, or removed and undone: the light comes (back) with a new id */
        if (forward == (s->kind == LM_VIEW_LIGHT_ADDED)) {
            snprintf(what, n, "%s: light added", verb);
            return lmgi_add_light(sc, s->kind == LM_VIEW_LIGHT_ADDED ? &s->light_after : &s->light_before, &s->id,
                                  err) == LMGI_OK;
        }
        snprintf(what, n, "%s: light %d removed", verb, s->id);
        return lmgi_remove_light(sc, s->id, err) == LMGI_OK;
    case LM_VIEW_MATERIAL:
        snprintf(what, n, "%s: material %s edited", verb, lmgi_material_name(sc, s->id));
        return lmgi_set_material(sc, s->id, forward ? &s->material_after : &s->material_before, err) == LMGI_OK;
    case LM_VIEW_EFFECTS:
        snprintf(what, n, "%s: node %s's effects switched", verb, lmgi_node_name(sc, s->id));
        return lmgi_set_node_effects(sc, s->id, forward ? &s->effects_after : &s->effects_before, err) == LMGI_OK;
    }
    return 0;
}

int lm_view_undo(lm_view_history *h, lmgi_scene *sc, char *what, size_t n, lmgi_error *err)
{
    snprintf(what, n, "nothing to undo");
    if (h->done == 0 || !replay(&h->steps[h->done - 1], 0, sc, what, n, err))
        return 0;
    h->done--;
    return 1;
}

int lm_view_redo(lm_view_history *h, lmgi_scene *sc, char *what, size_t n, lmgi_error *err)
{
    snprintf(what, n, "nothing to redo");
    if (h->done == h->count || !replay(&h->steps[h->done], 1, sc, what, n, err))
        return 0;
    h->done++;
    return 1;
}

void lm_view_ray(const lmgi_camera *cam, double x, double y, int w, int h, float org[3], float dir[3])
{
    const float *v = cam->view, *p = cam->proj;
    /* the pixel's direction in view space (looking down -z), then by the view's rotation R^T to the world */
    double ndc_x = 2.0 * x / (w > 0 ? w : 1) - 1.0, ndc_y = 1.0 - 2.0 * y / (h > 0 ? h : 1);
    double d[3] = {ndc_x / p[0], ndc_y / p[5], -1.0}, len = 0.0;
    for (int k = 0; k < 3; k++) {
        org[k] = -(v[4 * k] * v[12] + v[4 * k + 1] * v[13] + v[4 * k + 2] * v[14]);
        double c = v[4 * k] * d[0] + v[4 * k + 1] * d[1] + v[4 * k + 2] * d[2];
        dir[k] = (float)c;
        len += c * c;
    }
    for (int k = 0; k < 3; k++)
        dir[k] = (float)(dir[k] / sqrt(len));
}

int lm_view_ray_plane(const float org[3], const float dir[3], float y, float out[3])
{
    if (fabsf(dir[1]) < 1e-6f)
        return 0;
    float t = (y - org[1]) / dir[1];
    if (!(t > 0.0f))
        return 0;
    for (int k = 0; k < 3; k++)
        out[k] = org[k] + t * dir[k];
    return 1;
}

float lm_view_ray_axis(const float org[3], const float dir[3], const float p[3], const float a[3])
{
    /* the two lines' closest points: w = org - p; s = (w.a - (w.d)(d.a)) / (1 - (d.a)^2) for unit d, a */
    double w[3] = {org[0] - p[0], org[1] - p[1], org[2] - p[2]};
    double wa = w[0] * a[0] + w[1] * a[1] + w[2] * a[2], wd = w[0] * dir[0] + w[1] * dir[1] + w[2] * dir[2];
    double da = (double)dir[0] * a[0] + (double)dir[1] * a[1] + (double)dir[2] * a[2], den = 1.0 - da * da;
    return den < 1e-6 ? 0.0f : (float)((wa - wd * da) / den);
}

void lm_view_turn(const float m[16], float angle, float out[16])
{
    float c = cosf(angle), s = sinf(angle), r[16];
    memcpy(r, m, sizeof r);
    for (int col = 0; col < 3; col++) { /* R_y times each column's x and z; the translation stays */
        float x = m[4 * col], z = m[4 * col + 2];
        r[4 * col] = c * x + s * z;
        r[4 * col + 2] = -s * x + c * z;
    }
    memcpy(out, r, sizeof r);
}
