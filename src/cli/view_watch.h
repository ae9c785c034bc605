/* lmgi view --watch (docs/viewer.md): the scene's file followed as an artist saves it from their tool.
 * When the file has changed and then stayed still for a moment (a save in progress is not read half
 * written), it is loaded again and compared with the scene shown: the same geometry (lmgi_geometry_hash),
 * nodes, materials and lights, and the differences are made as edits through the public API
 * (lmgi_set_node_transform, lmgi_set_material, lmgi_set_light), so that only what changed is recomputed;
 * anything else (a mesh changed, a node, material or light more or less) cannot be an edit, and the caller
 * reloads the scene.
 * Cost: a stat() a frame; a load of the file when it changed. Not thread-safe. */
#ifndef LM_CLI_VIEW_WATCH_H
#define LM_CLI_VIEW_WATCH_H

#include <lmgi.h>
#include <stddef.h>
#include <sys/stat.h>

#define LM_VIEW_WATCH_SETTLE 0.3 /* seconds a changed file must stay unchanged before it is read */

typedef struct {
    const char *path;
    struct timespec mtime;
    off_t size;
    int changed;           /* seen changed, not read yet */
    double changed_at;     /* when it was last seen changing (the caller's clock, seconds) */
} lm_view_watch;

void lm_view_watch_init(lm_view_watch *w, const char *path);
/* 1 when the file changed since the last time this said so and has been still for
 * LM_VIEW_WATCH_SETTLE seconds at `now`. */
int lm_view_watch_due(lm_view_watch *w, double now);
/* Makes cur the file's next by edits: node transforms (static nodes made dynamic, deepest last: a pass
 * per level of the hierarchy), materials and lights whose values differ. Returns how many things changed
 * (what: "2 nodes moved, 1 material, 0 lights"), or -1 when next is not cur's geometry, nodes, materials
 * and lights (the caller reloads), or -2 when the scene refused an edit (err says why). */
int lm_view_watch_apply(lmgi_scene *cur, const lmgi_scene *next, char *what, size_t n, lmgi_error *err);

#endif
