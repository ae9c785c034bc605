#include "moved_nodes.h"

#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"

lm_status lm_moved_nodes_init(lm_moved_nodes *m, const lm_scene *s, lm_error *err)
{
    memset(m, 0, sizeof *m);
    size_t n = (size_t)(s->node_count ? s->node_count : 1);
    m->world = malloc(16 * n * sizeof *m->world);
    m->local_box = malloc(6 * n * sizeof *m->local_box);
    if (!m->world || !m->local_box) {
        lm_moved_nodes_free(m);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory to follow moved nodes (%d nodes)", s->path, s->node_count);
    }
    m->node_count = s->node_count;
    for (int i = 0; i < s->node_count; i++)
        memcpy(m->world + 16 * i, s->nodes[i].world, 16 * sizeof(float));
    lm_scene_node_local_boxes(s, m->local_box);
    return LM_OK;
}

void lm_moved_nodes_free(lm_moved_nodes *m)
{
    free(m->world);
    free(m->local_box);
    memset(m, 0, sizeof *m);
}

/* Whether an animation places the node: a channel on it or above it, on a node no edit has taken over. */
static int animated(const lm_scene *s, int node)
{
    for (int a = 0; a < s->animation_count; a++)
        for (int c = 0; c < s->animations[a].channel_count; c++) {
            int target = s->animations[a].channels[c].node;
            if (target >= 0 && target < s->node_count && !s->nodes[target].edited && lm_node_under(s, node, target))
                return 1;
        }
    return 0;
}

int lm_moved_nodes_boxes(lm_moved_nodes *m, const lm_scene *s, float *out, int animated_room)
{
    int boxes = 0;
    for (int n = 0; n < s->node_count && n < m->node_count; n++) {
        float *seen = m->world + 16 * n;
        if (!memcmp(seen, s->nodes[n].world, 16 * sizeof(float)))
            continue;
        const float *b = m->local_box + 6 * n;
        int by_animation = animated(s, n);
        if (b[0] <= b[3] && (!by_animation || animated_room >= 2)) {
            animated_room -= by_animation ? 2 : 0;
            lm_box_placed(b, seen, out + 6 * boxes++);
            lm_box_placed(b, s->nodes[n].world, out + 6 * boxes++);
        }
        memcpy(seen, s->nodes[n].world, 16 * sizeof(float));
    }
    return boxes;
}
