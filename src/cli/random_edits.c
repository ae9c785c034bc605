/* Random edits through the public API (random_edits.h). */
#include "random_edits.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* xorshift64*: a fixed, fast stream for a seed (never 0 inside). */
static uint64_t next(lm_random_edits *r)
{
    r->rng ^= r->rng >> 12, r->rng ^= r->rng << 25, r->rng ^= r->rng >> 27;
    return r->rng * 0x2545F4914F6CDD1DULL;
}
static float uniform(lm_random_edits *r) { return (float)(next(r) >> 40) / 16777216.0f; }
static int below(lm_random_edits *r, int n) { return (int)(next(r) % (uint64_t)n); }

int lm_random_edits_lights(const lmgi_scene *sc)
{
    int on = 0;
    for (int i = 0; i < lmgi_light_count(sc); i++)
        on += !lmgi_light_is_removed(sc, i);
    return on;
}

int lm_random_edits_init(lm_random_edits *r, const lmgi_scene *sc, int max_lights, uint64_t seed)
{
    memset(r, 0, sizeof *r);
    r->rng = seed * 0x9E3779B97F4A7C15ULL + 1u;
    r->max_lights = max_lights;
    lmgi_info in;
    lmgi_get_info(sc, &in);
    memcpy(r->lo, in.bounds_min, sizeof r->lo);
    memcpy(r->hi, in.bounds_max, sizeof r->hi);
    double sum = 0.0;
    int n = 0;
    for (int i = 0; i < lmgi_light_count(sc); i++) {
        lmgi_light l;
        if (lmgi_get_light(sc, i, &l, NULL) == LMGI_OK && l.type != LMGI_LIGHT_DIRECTIONAL)
            sum += l.intensity, n++;
    }
    r->mean_intensity = n ? (float)(sum / n) : 1.0f;
    for (int i = 0; i < lmgi_node_count(sc) && r->nodes < LM_RANDOM_EDITS_MAX_NODES; i++)
        if (lmgi_node_is_dynamic(sc, i) && lmgi_get_node_transform(sc, i, r->home[r->nodes]))
            r->node[r->nodes++] = i;
    r->added = malloc(sizeof *r->added * (size_t)(max_lights > 0 ? max_lights : 1));
    return r->added ? 0 : -1;
}

void lm_random_edits_free(lm_random_edits *r)
{
    free(r->added);
    r->added = NULL;
}

/* A dynamic node set at its home position plus a random offset of up to a tenth of the scene's size on
 * each axis: a walk that never leaves the neighbourhood it was modelled in. */
static lmgi_status move_node(lm_random_edits *r, lmgi_scene *sc, lmgi_error *err)
{
    int k = below(r, r->nodes);
    float m[16];
    memcpy(m, r->home[k], sizeof m);
    for (int a = 0; a < 3; a++)
        m[12 + a] += 0.1f * (r->hi[a] - r->lo[a]) * (2.0f * uniform(r) - 1.0f);
    return lmgi_set_node_transform(sc, r->node[k], m, err);
}

/* A live light (never 0 when called) dimmed or brightened by up to 2x and recoloured. */
static lmgi_status edit_light(lm_random_edits *r, lmgi_scene *sc, lmgi_error *err)
{
    int k = below(r, lm_random_edits_lights(sc)), id = -1;
    while (k >= 0) /* id: the k-th light still on */
        k -= !lmgi_light_is_removed(sc, ++id);
    lmgi_light l;
    lmgi_status st = lmgi_get_light(sc, id, &l, err);
    if (st != LMGI_OK)
        return st;
    float scale = powf(2.0f, 2.0f * uniform(r) - 1.0f);
    l.intensity = fminf(l.intensity * scale, 4.0f * r->mean_intensity);
    for (int c = 0; c < 3; c++)
        l.color[c] = 0.5f + 0.5f * uniform(r);
    return lmgi_set_light(sc, id, &l, err);
}

static lmgi_status edit_material(lm_random_edits *r, lmgi_scene *sc, lmgi_error *err)
{
    int id = below(r, lmgi_material_count(sc));
    lmgi_material m;
    lmgi_status st = lmgi_get_material(sc, id, &m, err);
    if (st != LMGI_OK)
        return st;
    for (int c = 0; c < 3; c++)
        m.base_color[c] = 0.1f + 0.8f * uniform(r);
    return lmgi_set_material(sc, id, &m, err);
}

static lmgi_status add_light(lm_random_edits *r, lmgi_scene *sc, lmgi_error *err)
{
    lmgi_light l;
    memset(&l, 0, sizeof l);
    l.type = below(r, 3) == 0 ? LMGI_LIGHT_SPOT : LMGI_LIGHT_POINT;
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    l.intensity = r->mean_intensity;
    l.enabled = 1;
    l.inner_cone = 0.3f, l.outer_cone = 0.7f;
    for (int a = 0; a < 3; a++)
        l.position[a] = r->lo[a] + (0.1f + 0.8f * uniform(r)) * (r->hi[a] - r->lo[a]);
    l.direction[1] = -1.0f; /* spots point down at the floor */
    int id = -1;
    lmgi_status st = lmgi_add_light(sc, &l, &id, err);
    if (st == LMGI_OK)
        r->added[r->added_count++] = id;
    return st;
}

static lmgi_status remove_light(lm_random_edits *r, lmgi_scene *sc, lmgi_error *err)
{
    int k = below(r, r->added_count);
    lmgi_status st = lmgi_remove_light(sc, r->added[k], err);
    if (st == LMGI_OK)
        r->added[k] = r->added[--r->added_count];
    return st;
}

lmgi_status lm_random_edit(lm_random_edits *r, lmgi_scene *sc, lm_edit_kind *kind, lmgi_error *err)
{
    /* the mix: 4 in 10 node moves (light edits where the scene has no dynamic node), 2 light edits,
     * 2 material edits, 2 lights added or removed */
    int roll = below(r, 10), lights = lm_random_edits_lights(sc);
    lm_edit_kind k = roll < 4 ? LM_EDIT_NODE : roll < 6 ? LM_EDIT_LIGHT : roll < 8 ? LM_EDIT_MATERIAL
                   : lights < r->max_lights ? LM_EDIT_ADD_LIGHT : LM_EDIT_REMOVE_LIGHT;
    if (k == LM_EDIT_NODE && r->nodes == 0)
        k = LM_EDIT_LIGHT;
    if (k == LM_EDIT_LIGHT && lights == 0)
        k = LM_EDIT_MATERIAL;
    if (k == LM_EDIT_REMOVE_LIGHT && r->added_count == 0)
        k = LM_EDIT_MATERIAL;
    if (k == LM_EDIT_MATERIAL && lmgi_material_count(sc) == 0)
        k = LM_EDIT_ADD_LIGHT;
    if (kind)
        *kind = k;
    r->made[k]++;
    switch (k) {
    case LM_EDIT_NODE: return move_node(r, sc, err);
    case LM_EDIT_LIGHT: return edit_light(r, sc, err);
    case LM_EDIT_MATERIAL: return edit_material(r, sc, err);
    case LM_EDIT_ADD_LIGHT: return add_light(r, sc, err);
    default: return remove_light(r, sc, err);
    }
}

const char *lm_edit_kind_name(lm_edit_kind k)
{
    static const char *names[LM_EDIT_KINDS] = {"node moved", "light edited", "material recoloured",
                                               "light added", "light removed"};
    return k >= 0 && k < LM_EDIT_KINDS ? names[k] : "?";
}
