/* The watched scene file (view_watch.h). */
#include "view_watch.h"

#include <stdio.h>
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

static int same_shape(const lmgi_scene *a, const lmgi_scene *b)
{
    if (lmgi_geometry_hash(a) != lmgi_geometry_hash(b) || lmgi_node_count(a) != lmgi_node_count(b) ||
        lmgi_material_count(a) != lmgi_material_count(b) || lmgi_light_count(a) != lmgi_light_count(b))
        return 0;
    for (int l = 0; l < lmgi_light_count(a); l++) {
        lmgi_light x, y;
        lmgi_error err;
        if (lmgi_light_is_removed(a, l) || lmgi_get_light(a, l, &x, &err) != LMGI_OK ||
            lmgi_get_light(b, l, &y, &err) != LMGI_OK || x.type != y.type || x.node != y.node)
            return 0;
    }
    return 1;
}

/* Sets every node of cur whose world matrix differs from next's; the number set (-2: refused). A child set
 * before its parent moves again with it, so the caller repeats until none differs. */
static int nodes_pass(lmgi_scene *cur, const lmgi_scene *next, lmgi_error *err)
{
    int set = 0;
    for (int i = 0; i < lmgi_node_count(cur); i++) {
        float a[16], b[16];
        lmgi_get_node_transform(cur, i, a);
        lmgi_get_node_transform(next, i, b);
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

int lm_view_watch_apply(lmgi_scene *cur, const lmgi_scene *next, char *what, size_t n, lmgi_error *err)
{
    if (!same_shape(cur, next))
        return -1;
    int nodes = 0, materials = 0, lights = 0, set = 1;
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
    for (int l = 0; l < lmgi_light_count(cur); l++) {
        lmgi_light a, b;
        if (lmgi_get_light(cur, l, &a, err) != LMGI_OK || lmgi_get_light(next, l, &b, err) != LMGI_OK)
            return -2;
        if (!light_differs(&a, &b))
            continue;
        if (a.node >= 0) /* placed by its node, which the nodes above have moved */
            memcpy(b.position, a.position, sizeof b.position), memcpy(b.direction, a.direction, sizeof b.direction);
        if (lmgi_set_light(cur, l, &b, err) != LMGI_OK)
            return -2;
        lights++;
    }
    snprintf(what, n, "%d node%s moved, %d material%s, %d light%s changed", nodes, nodes == 1 ? "" : "s", materials,
             materials == 1 ? "" : "s", lights, lights == 1 ? "" : "s");
    return nodes + materials + lights;
}
