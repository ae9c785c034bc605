#include "edits.h"

#include "world.h"

lm_status lm_edits_commit(const lm_world *w, lm_error *err)
{
    if (!w->edits || !w->edits->moved)
        return LM_OK;
    lm_status st = lm_rt_sync_transforms(w->rt, w->scene, err);
    if (st == LM_OK)
        w->edits->moved = 0;
    return st;
}
