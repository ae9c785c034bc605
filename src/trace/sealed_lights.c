/* Lights sealed inside closed opaque objects (sealed_lights.h). */
#include "sealed_lights.h"

#include <math.h>
#include <string.h>

/* 1 when the ray's first hit is the back of a single-sided opaque surface. */
static int hits_back(const lm_scene *s, const lm_rt *rt, const float org[3], const float dir[3], lm_rt_hit *hit)
{
    if (!lm_rt_intersect(rt, org, dir, 0.0f, INFINITY, hit))
        return 0;
    const lm_material *m = &s->materials[s->tri_material[hit->tri]];
    float facing = dir[0] * hit->ng[0] + dir[1] * hit->ng[1] + dir[2] * hit->ng[2];
    return facing > 0.0f && !m->double_sided && m->cls != LM_MAT_GLASS;
}

int lm_point_sealed(const lm_scene *s, const lm_rt *rt, const float p[3])
{
    float lift = lm_scene_ray_lift(s);
    static const float dirs[14][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1},
                                      {1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {1, -1, -1}, {-1, 1, 1}, {-1, 1, -1},
                                      {-1, -1, 1}, {-1, -1, -1}};
    for (int k = 0; k < 14; k++) {
        lm_rt_hit hit;
        if (hits_back(s, rt, p, dirs[k], &hit))
            continue;
        if (!(hit.t > 0.0f) || !lm_rt_intersect(rt, p, dirs[k], 0.0f, INFINITY, &hit))
            return 0; /* escapes */
        /* A front: the object's own bottom may lie in that surface's plane (a box on a floor), and the
         * ray found the floor. Then the floor there is inside the object: straight out from it, the
         * ray meets the object's inside, a back. */
        float ng[3] = {hit.ng[0], hit.ng[1], hit.ng[2]};
        if (dirs[k][0] * ng[0] + dirs[k][1] * ng[1] + dirs[k][2] * ng[2] > 0.0f)
            return 0; /* the back of a double-sided or glass surface: light goes on */
        float org[3];
        for (int a = 0; a < 3; a++)
            org[a] = p[a] + dirs[k][a] * hit.t + ng[a] * lift;
        lm_rt_hit out;
        if (!hits_back(s, rt, org, ng, &out))
            return 0;
    }
    return 1;
}

int lm_emitters_seal(lm_emitters *em, const lm_scene *s, const lm_rt *rt)
{
    int n = 0;
    for (int e = 0; e < em->count; e++) {
        lm_emitter *x = &em->e[e];
        if (x->kind != LM_EMIT_POINT && x->kind != LM_EMIT_SPOT)
            continue;
        if (x->luminance == 0.0f || !lm_point_sealed(s, rt, x->pos))
            continue;
        em->total_luminance -= x->luminance;
        memset(x->power, 0, sizeof x->power);
        memset(x->radiant, 0, sizeof x->radiant);
        x->luminance = 0.0f;
        n++;
    }
    return n;
}
