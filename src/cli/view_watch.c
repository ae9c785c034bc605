/* The watched scene file (view_watch.h). */
#include "view_watch.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_PASSES 16 /* levels of the node hierarchy set right one a pass */

static int stat_of(const char *path, struct timespec *mtime, off_t *size)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return 0;
    *mtime = st.st_mtim;
    *size = st.st_size;
    return 1;
}

void lm_view_watch_init(lm_view_watch *w, const char *path)
{
    memset(w, 0, sizeof *w);
    w->path = path;
    stat_of(path, &w->mtime, &w->size);
}

void lm_view_watch_reset(lm_view_watch *w) { w->added_count = 0; }

void lm_view_watch_free(lm_view_watch *w)
{
    free(w->added);
    w->added = NULL;
    w->added_count = w->added_cap = 0;
}

int lm_view_watch_due(lm_view_watch *w, double now)
{
    struct timespec m;
    off_t size;
    if (stat_of(w->path, &m, &size) &&
        (m.tv_sec != w->mtime.tv_sec || m.tv_nsec != w->mtime.tv_nsec || size != w->size)) {
        w->mtime = m, w->size = size;
        w->changed = 1;
        w->changed_at = now;
    }
    if (!w->changed || now - w->changed_at < LM_VIEW_WATCH_SETTLE)
        return 0;
    w->changed = 0;
    return 1;
}

/* Whether two lights differ in what an edit may set (a light with a node gets its place from the node). */
static int light_differs(const lmgi_light *a, const lmgi_light *b)
{
    return memcmp(a->color, b->color, sizeof a->color) || a->intensity != b->intensity || a->range != b->range ||
           a->inner_cone != b->inner_cone || a->outer_cone != b->outer_cone || a->enabled != b->enabled ||
           (a->node < 0 && (memcmp(a->position, b->position, sizeof a->position) ||
                            memcmp(a->direction, b->direction, sizeof a->direction)));
}

/* The name of the node that places light l of sc ("" for a light without one). */
static const char *light_name(const lmgi_scene *sc, int l)
{
    lmgi_light x;
    lmgi_error err;
    if (lmgi_light_is_removed(sc, l) || lmgi_get_light(sc, l, &x, &err) != LMGI_OK || x.node < 0)
        return "";
    const char *name = lmgi_node_name(sc, x.node);
    return name ? name : "";
}

/* The light of the scene shown that the file's lamp named `name` is: a light of the file placed by a node
 * of that name, or one the watch added for it; -1 when there is none (a new lamp). */
static int shown_light(const lm_view_watch *w, const lmgi_scene *cur, const char *name)
{
    if (!name[0])
        return -1;
    for (int l = 0; l < lmgi_light_count(cur); l++)
        if (!lmgi_light_is_removed(cur, l) && !strcmp(light_name(cur, l), name))
            return l;
    for (int k = 0; k < w->added_count; k++)
        if (!strcmp(w->added[k].name, name) && !lmgi_light_is_removed(cur, w->added[k].id))
            return w->added[k].id;
    return -1;
}

/* Whether next can be made from cur by edits: the same geometry and materials, and each lamp of the file
 * that the scene shown has still of its type. */
static int same_shape(const lm_view_watch *w, const lmgi_scene *cur, const lmgi_scene *next)
{
    if (lmgi_geometry_hash(cur) != lmgi_geometry_hash(next) || lmgi_material_count(cur) != lmgi_material_count(next))
        return 0;
    for (int l = 0; l < lmgi_light_count(next); l++) {
        lmgi_light x, y;
        lmgi_error err;
        if (lmgi_light_is_removed(next, l) || lmgi_get_light(next, l, &y, &err) != LMGI_OK)
            continue;
        const char *name = light_name(next, l);
        int c = shown_light(w, cur, name);
        if (!name[0] || (c >= 0 && (lmgi_get_light(cur, c, &x, &err) != LMGI_OK || x.type != y.type)))
            return 0; /* a lamp without a node cannot be told from another; a type cannot change */
    }
    return 1;
}

/* Sets every node of cur whose world matrix differs from that of next's node of the same name; the number
 * set (-2: refused). A child set before its parent moves again with it, so the caller repeats until none
 * differs. Nodes in one file only (lamps, cameras, empties: the geometry is the same) are left. */
static int nodes_pass(lmgi_scene *cur, const lmgi_scene *next, lmgi_error *err)
{
    int set = 0;
    for (int j = 0; j < lmgi_node_count(next); j++) {
        int i = lmgi_find_node(cur, lmgi_node_name(next, j));
        float a[16], b[16];
        if (i < 0)
            continue;
        lmgi_get_node_transform(cur, i, a);
        lmgi_get_node_transform(next, j, b);
        if (!memcmp(a, b, sizeof a))
            continue;
        if (!lmgi_node_is_dynamic(cur, i) && lmgi_set_node_dynamic(cur, i, 1, err) != LMGI_OK)
            return -2;
        if (lmgi_set_node_transform(cur, i, b, err) != LMGI_OK)
            return -2;
        set++;
    }
    return set;
}

/* The file's lamp (next's light l, named) made in cur: set where it is shown, added where it is new.
 * Counts what it did; 0 when refused or out of memory (err says why). */
static int follow_light(lm_view_watch *w, lmgi_scene *cur, const lmgi_scene *next, int l, int *changed, int *added,
                        lmgi_error *err)
{
    lmgi_light a, b;
    if (lmgi_get_light(next, l, &b, err) != LMGI_OK)
        return 0;
    const char *name = light_name(next, l);
    int c = shown_light(w, cur, name);
    if (c < 0) {
        if (w->added_count == w->added_cap) {
            int cap = w->added_cap ? 2 * w->added_cap : 8;
            lm_view_watch_light *g = realloc(w->added, (size_t)cap * sizeof *g);
            if (!g) {
                snprintf(err->message, sizeof err->message, "view --watch: no memory for the lamps it added");
                return 0;
            }
            w->added = g, w->added_cap = cap;
        }
        lm_view_watch_light *k = &w->added[w->added_count];
        snprintf(k->name, sizeof k->name, "%s", name);
        if (lmgi_add_light(cur, &b, &k->id, err) != LMGI_OK) /* at the world place its node gave it */
            return 0;
        w->added_count++;
        ++*added;
        return 1;
    }
    if (lmgi_get_light(cur, c, &a, err) != LMGI_OK)
        return 0;
    if (!light_differs(&a, &b))
        return 1;
    if (a.node >= 0) /* placed by its node, which the nodes' passes have moved */
        memcpy(b.position, a.position, sizeof b.position), memcpy(b.direction, a.direction, sizeof b.direction);
    ++*changed;
    return lmgi_set_light(cur, c, &b, err) == LMGI_OK;
}

/* Whether the scene shown's light c is one of the file's lamps (next's). */
static int in_file(const lm_view_watch *w, const lmgi_scene *cur, const lmgi_scene *next, int c)
{
    for (int l = 0; l < lmgi_light_count(next); l++)
        if (!lmgi_light_is_removed(next, l) && shown_light(w, cur, light_name(next, l)) == c)
            return 1;
    return 0;
}

int lm_view_watch_apply(lm_view_watch *w, lmgi_scene *cur, const lmgi_scene *next, char *what, size_t n,
                        lmgi_error *err)
{
    if (!same_shape(w, cur, next))
        return -1;
    int nodes = 0, materials = 0, lights = 0, added = 0, removed = 0, set = 1;
    for (int pass = 0; set > 0 && pass < MAX_PASSES; pass++) {
        set = nodes_pass(cur, next, err);
        if (set < 0)
            return -2;
        nodes = pass == 0 ? set : nodes;
    }
    for (int m = 0; m < lmgi_material_count(cur); m++) {
        lmgi_material a, b;
        if (lmgi_get_material(cur, m, &a, err) != LMGI_OK || lmgi_get_material(next, m, &b, err) != LMGI_OK)
            return -2;
        b.cls = a.cls; /* read only: the set accepts the old class */
        if (!memcmp(&a, &b, sizeof a))
            continue;
        if (lmgi_set_material(cur, m, &b, err) != LMGI_OK)
            return -2;
        materials++;
    }
    int shown = lmgi_light_count(cur); /* the lights before any is added: those the file may have dropped */
    for (int c = 0; c < shown; c++)
        if (!lmgi_light_is_removed(cur, c) && !in_file(w, cur, next, c)) {
            if (lmgi_remove_light(cur, c, err) != LMGI_OK)
                return -2;
            removed++;
        }
    for (int l = 0; l < lmgi_light_count(next); l++)
        if (!lmgi_light_is_removed(next, l) && !follow_light(w, cur, next, l, &lights, &added, err))
            return -2;
    snprintf(what, n, "%d node%s moved, %d material%s, %d light%s changed, %d added, %d removed", nodes,
             nodes == 1 ? "" : "s", materials, materials == 1 ? "" : "s", lights, lights == 1 ? "" : "s", added,
             removed);
    return nodes + materials + lights + added + removed;
}
