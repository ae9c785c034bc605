#include "edits.h"

#include <stdlib.h>
#include <string.h>

#include "world.h"

void lm_edits_free(lm_edit_batch *b)
{
    free(b->lights);
    free(b->materials);
    free(b->effects);
    free(b->dynamic);
    free(b->sky.image);
    free(b->changes.lights);
    free(b->changes.materials);
    lm_effects *decided = b->decided;
    memset(b, 0, sizeof *b);
    b->decided = decided;
}

int lm_edits_pending(const lm_edit_batch *b)
{
    return b && (b->moved || b->light_count || b->material_count || b->effect_count || b->dynamic_count ||
                 b->sky.staged);
}

/* Room for one more item of `size` bytes in *items (count used of *room). */
static int grow(void **items, int count, int *room, size_t size)
{
    if (count < *room)
        return 1;
    int n = *room ? 2 * *room : 8;
    void *p = realloc(*items, size * (size_t)n);
    if (!p)
        return 0;
    *items = p;
    *room = n;
    return 1;
}

static lm_staged_light *staged_light(const lm_edit_batch *b, int id)
{
    for (int i = 0; i < b->light_count; i++)
        if (b->lights[i].id == id)
            return &b->lights[i];
    return NULL;
}

static lm_staged_material *staged_material(const lm_edit_batch *b, int id)
{
    for (int i = 0; i < b->material_count; i++)
        if (b->materials[i].id == id)
            return &b->materials[i];
    return NULL;
}

int lm_edits_light_count(const lm_edit_batch *b, const lm_scene *s)
{
    return s->light_count + (b ? b->lights_added : 0);
}

const lm_light *lm_edits_light(const lm_edit_batch *b, const lm_scene *s, int id)
{
    const lm_staged_light *l = b ? staged_light(b, id) : NULL;
    return l ? &l->value : id >= 0 && id < s->light_count ? &s->lights[id] : NULL;
}

const lm_material *lm_edits_material(const lm_edit_batch *b, const lm_scene *s, int id)
{
    const lm_staged_material *m = b ? staged_material(b, id) : NULL;
    return m ? &m->value : &s->materials[id];
}

void lm_edits_node_effects(const lm_edit_batch *b, const lm_scene *s, int node, int out[4])
{
    const lm_node_settings *st = &s->nodes[node].settings;
    out[0] = st->shadows, out[1] = st->indirect, out[2] = st->reflections, out[3] = st->caustics;
    for (int i = 0; b && i < b->effect_count; i++) /* in the order made: the last one over it decides */
        if (lm_node_under(s, node, b->effects[i].node)) {
            const lm_staged_effects *e = &b->effects[i];
            out[0] = e->shadows, out[1] = e->indirect, out[2] = e->reflections, out[3] = e->caustics;
        }
}

int lm_edits_node_dynamic(const lm_edit_batch *b, const lm_scene *s, int node)
{
    int dynamic = s->nodes[node].dynamic;
    for (int i = 0; b && i < b->dynamic_count; i++)
        if (lm_node_under(s, node, b->dynamic[i].node))
            dynamic = b->dynamic[i].dynamic;
    return dynamic;
}

const lm_staged_sky *lm_edits_sky(const lm_edit_batch *b) { return b && b->sky.staged ? &b->sky : NULL; }

lm_status lm_edits_stage_light(lm_edit_batch *b, const lm_scene *s, int id, const lm_light *value, lm_error *err)
{
    lm_staged_light *l = staged_light(b, id);
    if (!l) {
        if (!grow((void **)&b->lights, b->light_count, &b->light_room, sizeof *b->lights))
            return lm_fail(err, LM_ERR_NOMEM, "%s: no memory to stage an edit of light '%s'", s->path, value->name);
        l = &b->lights[b->light_count++];
        l->id = id;
    }
    l->value = *value;
    return LM_OK;
}

lm_status lm_edits_add_light(lm_edit_batch *b, const lm_scene *s, const lm_light *value, int *id, lm_error *err)
{
    int next = lm_edits_light_count(b, s);
    lm_status st = lm_edits_stage_light(b, s, next, value, err);
    if (st == LM_OK)
        b->lights_added++, *id = next;
    return st;
}

lm_status lm_edits_stage_material(lm_edit_batch *b, const lm_scene *s, int id, const lm_material *value,
                                  lm_error *err)
{
    lm_staged_material *m = staged_material(b, id);
    if (!m) {
        if (!grow((void **)&b->materials, b->material_count, &b->material_room, sizeof *b->materials))
            return lm_fail(err, LM_ERR_NOMEM, "%s: no memory to stage an edit of material '%s'", s->path,
                           value->name);
        m = &b->materials[b->material_count++];
        m->id = id;
    }
    m->value = *value;
    return LM_OK;
}

lm_status lm_edits_stage_effects(lm_edit_batch *b, const lm_staged_effects *e, lm_error *err)
{
    if (!grow((void **)&b->effects, b->effect_count, &b->effect_room, sizeof *b->effects))
        return lm_fail(err, LM_ERR_NOMEM, "no memory to stage an effect switch");
    b->effects[b->effect_count++] = *e;
    return LM_OK;
}

lm_status lm_edits_stage_dynamic(lm_edit_batch *b, int node, int dynamic, lm_error *err)
{
    if (!grow((void **)&b->dynamic, b->dynamic_count, &b->dynamic_room, sizeof *b->dynamic))
        return lm_fail(err, LM_ERR_NOMEM, "no memory to stage a dynamic switch");
    b->dynamic[b->dynamic_count++] = (lm_staged_dynamic){node, dynamic};
    return LM_OK;
}

void lm_edits_stage_sky(lm_edit_batch *b, const lm_staged_sky *sky)
{
    if (b->sky.image != sky->image)
        free(b->sky.image);
    b->sky = *sky;
    b->sky.staged = 1;
}

void lm_edits_note_moved(lm_edit_batch *b)
{
    b->moved++;
    b->changes.moved = 1;
}

/* flags (*cap of them) grown to n, the new ones 0. */
static int grow_flags(uint8_t **flags, int *cap, int n)
{
    if (n <= *cap)
        return 1;
    uint8_t *p = realloc(*flags, (size_t)n);
    if (!p)
        return 0;
    memset(p + *cap, 0, (size_t)(n - *cap));
    *flags = p, *cap = n;
    return 1;
}

static void mark(uint8_t *flags, int id, int *count)
{
    *count += !flags[id];
    flags[id] = 1;
}

/* The staged lights into the scene: the added ones appended (ids in the order made), each whose value
 * differs recorded. */
static lm_status apply_lights(lm_edit_batch *b, lm_scene *s, lm_error *err)
{
    int n = s->light_count + b->lights_added;
    if (b->lights_added) {
        lm_light *l = realloc(s->lights, sizeof *l * (size_t)n);
        if (!l)
            return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for %d more lights", s->path, b->lights_added);
        s->lights = l;
        memset(l + s->light_count, 0, sizeof *l * (size_t)b->lights_added);
    }
    for (int i = 0; i < b->light_count; i++) {
        lm_light *l = &s->lights[b->lights[i].id];
        if (memcmp(l, &b->lights[i].value, sizeof *l))
            mark(b->changes.lights, b->lights[i].id, &b->changes.lights_changed);
        *l = b->lights[i].value;
    }
    s->light_count = n;
    b->light_count = b->lights_added = 0;
    return LM_OK;
}

/* What of a material the photons, AIMs and caustics read: colour, emission, class and its parameters. */
static int same_material(const lm_material *a, const lm_material *b)
{
    return !memcmp(a->base_color, b->base_color, sizeof a->base_color) &&
           !memcmp(a->emissive, b->emissive, sizeof a->emissive) && a->metallic == b->metallic &&
           a->roughness == b->roughness && a->transmission == b->transmission && a->ior == b->ior &&
           a->cls == b->cls;
}

/* Returns 1 when a class changed (the passes' switches follow: pass_version). */
static int apply_materials(lm_edit_batch *b, lm_scene *s)
{
    int classes = 0;
    for (int i = 0; i < b->material_count; i++) {
        const lm_staged_material *m = &b->materials[i];
        if (!same_material(&s->materials[m->id], &m->value))
            mark(b->changes.materials, m->id, &b->changes.materials_changed);
        classes |= m->value.cls != s->materials[m->id].cls;
        s->materials[m->id] = m->value;
    }
    if (b->material_count)
        s->material_version++;
    b->material_count = 0;
    return classes;
}

static void apply_effects(lm_edit_batch *b, lm_scene *s)
{
    for (int i = 0; i < b->effect_count; i++) {
        const lm_staged_effects *e = &b->effects[i];
        for (int n = 0; n < s->node_count; n++)
            if (lm_node_under(s, n, e->node)) { /* as extras inherit: the node and everything under it */
                lm_node_settings *st = &s->nodes[n].settings;
                st->shadows = e->shadows, st->indirect = e->indirect, st->reflections = e->reflections;
                st->caustics = e->caustics;
            }
    }
    if (b->effect_count)
        s->pass_version++;
    b->effect_count = 0;
}

static void apply_sky(lm_edit_batch *b, lm_scene *s)
{
    lm_staged_sky *k = &b->sky;
    int same = s->has_sky && s->sky_kind == k->kind && !memcmp(s->sky, k->sky, sizeof s->sky) &&
               (k->kind != LM_SKY_GRADIENT || !memcmp(s->sky_horizon, k->horizon, sizeof s->sky_horizon)) &&
               k->kind != LM_SKY_IMAGE;
    memcpy(s->sky, k->sky, sizeof s->sky);
    if (k->kind == LM_SKY_GRADIENT)
        memcpy(s->sky_horizon, k->horizon, sizeof s->sky_horizon);
    if (k->kind == LM_SKY_IMAGE || s->sky_kind == LM_SKY_IMAGE) { /* an image replaced, or given up */
        free(s->sky_image);
        s->sky_image = k->image, s->sky_width = k->width, s->sky_height = k->height;
        memcpy(s->sky_image_mean, k->image_mean, sizeof s->sky_image_mean);
    }
    s->sky_kind = k->kind;
    s->has_sky = 1;
    b->changes.sky |= !same;
    memset(k, 0, sizeof *k);
}

/* The staged switches between dynamic and static, and the BVH: rebuilt after a switch (its structure
 * changed), else brought to the model's placements; on a failure the switches are undone (the old BVH is
 * still in place) and kept staged. */
static lm_status apply_bvh(lm_edit_batch *b, const lm_world *w, lm_error *err)
{
    lm_scene *s = w->scene;
    if (!b->dynamic_count) {
        lm_status st = b->moved ? lm_rt_sync_transforms(w->rt, s, err) : LM_OK;
        if (st == LM_OK)
            b->moved = 0;
        return st;
    }
    uint8_t *was = malloc((size_t)s->node_count + 1);
    if (!was)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory to switch nodes dynamic", s->path);
    for (int n = 0; n < s->node_count; n++)
        was[n] = (uint8_t)s->nodes[n].dynamic;
    for (int i = 0; i < b->dynamic_count; i++)
        lm_scene_set_dynamic(s, b->dynamic[i].node, b->dynamic[i].dynamic);
    lm_status st = lm_rt_rebuild(w->rt, err);
    for (int n = 0; st != LM_OK && n < s->node_count; n++)
        s->nodes[n].dynamic = s->nodes[n].settings.dynamic = was[n];
    free(was);
    if (st == LM_OK) /* built from the scene model as it is: every staged placement in it */
        b->moved = 0, b->dynamic_count = 0, b->changes.moved = 1;
    return st;
}

lm_status lm_edits_commit(const lm_world *w, lm_error *err)
{
    lm_edit_batch *b = w->edits;
    if (!lm_edits_pending(b))
        return LM_OK;
    lm_scene *s = w->scene;
    lm_edit_changes *c = &b->changes;
    if (!grow_flags(&c->lights, &c->light_cap, s->light_count + b->lights_added) ||
        !grow_flags(&c->materials, &c->material_cap, s->material_count))
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory to commit edits", s->path);
    int decide = b->lights_added || b->effect_count || b->dynamic_count || b->sky.staged;
    for (int i = 0; i < b->light_count; i++)
        decide |= b->lights[i].value.removed;
    lm_status st = apply_bvh(b, w, err); /* first: the one step that can fail leaves the rest staged */
    if (st == LM_OK)
        st = apply_lights(b, s, err);
    if (st != LM_OK)
        return st;
    if (apply_materials(b, s)) { /* a class changed: the passes' switches follow */
        s->pass_version++;
        decide = 1;
    }
    apply_effects(b, s);
    if (b->sky.staged)
        apply_sky(b, s);
    if (decide && b->decided)
        lm_effects_decide(s, b->decided);
    return LM_OK;
}

const lm_edit_changes *lm_edits_changes(const lm_edit_batch *b)
{
    static const lm_edit_changes none;
    return b ? &b->changes : &none;
}

void lm_edits_clear_changes(lm_edit_batch *b)
{
    if (!b)
        return;
    lm_edit_changes *c = &b->changes;
    if (c->lights_changed)
        memset(c->lights, 0, (size_t)c->light_cap);
    if (c->materials_changed)
        memset(c->materials, 0, (size_t)c->material_cap);
    c->lights_changed = c->materials_changed = c->sky = c->moved = 0;
}
