/* lmgi view --watch (docs/viewer.md): the scene's file followed as an artist saves it from their tool.
 * When the file has changed and then stayed still for a moment (a save in progress is not read half
 * written), it is loaded again and compared with the scene shown. With the same geometry
 * (lmgi_geometry_hash: the nodes that hold triangles and their triangles) and materials, the differences
 * are made as edits through the public API, so that only what changed is recomputed: nodes matched by
 * name moved (lmgi_set_node_transform), materials set (lmgi_set_material), lights matched by their node's
 * name set (lmgi_set_light), a lamp new in the file added (lmgi_add_light, at its world place) and one
 * gone from it removed (lmgi_remove_light). Anything else (a mesh changed, a node with triangles more or
 * less or renamed, a material more or less, a light that changed its type) cannot be an edit, and the
 * caller reloads the scene.
 * Cost: a stat() a frame; a load of the file when it changed. Memory: a name and an id a light the watch
 * added. Not thread-safe. */
#ifndef LM_CLI_VIEW_WATCH_H
#define LM_CLI_VIEW_WATCH_H

#include <lmgi.h>
#include <stddef.h>
#include <sys/stat.h>

#define LM_VIEW_WATCH_SETTLE 0.3 /* seconds a changed file must stay unchanged before it is read */

typedef struct {
    char name[64];         /* its node's name in the file */
    int id;                /* the light lmgi_add_light gave it in the scene shown */
} lm_view_watch_light;

typedef struct {
    const char *path;
    struct timespec mtime;
    off_t size;
    int changed;           /* seen changed, not read yet */
    double changed_at;     /* when it was last seen changing (the caller's clock, seconds) */
    lm_view_watch_light *added; /* the file's lamps the watch added to the scene shown (their nodes are not
                                 * its nodes), to set or remove them at later saves */
    int added_count, added_cap;
} lm_view_watch;

void lm_view_watch_init(lm_view_watch *w, const char *path);
/* Forgets the lights it added (the scene shown was loaded again); w->path stays. */
void lm_view_watch_reset(lm_view_watch *w);
void lm_view_watch_free(lm_view_watch *w);
/* 1 when the file changed since the last time this said so and has been still for
 * LM_VIEW_WATCH_SETTLE seconds at `now`. */
int lm_view_watch_due(lm_view_watch *w, double now);
/* Makes cur the file's next by edits: node transforms (static nodes made dynamic, deepest last: a pass
 * per level of the hierarchy), materials and lights whose values differ, lamps added and removed. Returns
 * how many things changed (what: "2 nodes moved, 1 material, 0 lights changed, 1 added, 0 removed"), or
 * -1 when next cannot be made from cur by edits (the caller reloads; nothing was changed), or -2 when the
 * scene refused an edit or memory ran out (err says why). */
int lm_view_watch_apply(lm_view_watch *w, lmgi_scene *cur, const lmgi_scene *next, char *what, size_t n,
                        lmgi_error *err);

#endif
