#include "delta_i.h"

#include <math.h>

#include "../core/vecmath.h"

#define SEE_PAIRS 16 /* texel pairs tried between two surfaces */

/* A texel's position now (its node may have moved since load) and its triangle's geometric normal now
 * (the side its light leaves from). */
static lm_vec3 texel_now(const lm_scene *s, const lm_atlas *a, uint32_t texel, lm_vec3 *normal)
{
    const lm_texel *t = &a->texels[texel];
    *normal = lm_scene_tri_normal_world(s, t->tri);
    return lm_mat4_point(s->nodes[s->tri_node[t->tri]].world, lm_v3_load(t->local));
}

int lm_delta_i_sees(const lm_iim_sched *iim, const lm_scene *s, const lm_atlas *at, const lm_rt *rt, int a, int b)
{
    float lift = 1e-3f * lm_scene_size(s);
    uint32_t na = iim->surf_first[a + 1] - iim->surf_first[a], nb = iim->surf_first[b + 1] - iim->surf_first[b];
    if (!na || !nb)
        return 0;
    for (uint32_t k = 0; k < SEE_PAIRS; k++) {
        uint32_t ta = iim->surf_texels[iim->surf_first[a] + (uint32_t)((uint64_t)k * na / SEE_PAIRS)];
        uint32_t tb = iim->surf_texels[iim->surf_first[b] + (uint32_t)((uint64_t)((k * 7 + 3) % SEE_PAIRS) * nb / SEE_PAIRS)];
        lm_vec3 na3, nb3;
        lm_vec3 p = texel_now(s, at, ta, &na3), q = texel_now(s, at, tb, &nb3);
        p = lm_add(p, lm_scale(na3, lift));
        q = lm_add(q, lm_scale(nb3, lift));
        lm_vec3 d = lm_sub(q, p);
        float len = lm_length(d);
        if (!(len > lift))
            continue;
        d = lm_scale(d, 1.0f / len);
        if (!(lm_dot(na3, d) > 0.01f && lm_dot(nb3, d) < -0.01f)) /* not facing each other */
            continue;
        float org[3], dir[3];
        lm_v3_store(org, p);
        lm_v3_store(dir, d);
        if (!lm_rt_occluded(rt, org, dir, 0.0f, len))
            return 1;
    }
    return 0;
}

int lm_delta_i_widen_to_viewers(lm_iim_sched *sched, lm_photon_store *ps, const uint8_t *refreshed,
                                const lm_scene *s, const lm_atlas *at, const lm_rt *rt)
{
    int S = sched->surface_count, n = 0;
    for (int a = 0; a < S; a++) {
        int under_way = sched->cursor[a] > 0;
        if ((ps->surfaces[a].delta_i > sched->delta_threshold && !under_way) || sched->again[a])
            continue;
        for (int b = 0; b < S; b++)
            if (b != a && refreshed[b] && lm_delta_i_sees(sched, s, at, rt, a, b)) {
                if (under_way)
                    sched->again[a] = 1;
                else
                    lm_iim_sched_raise(sched, ps, a);
                n++;
                break;
            }
    }
    return n;
}

void lm_delta_i_save(const lm_iim_sched *sched, const lm_photon_store *ps, double *saved)
{
    for (int s = 0; s < sched->surface_count; s++)
        saved[s] = ps->surfaces[s].delta_i;
}

void lm_delta_i_restore(lm_iim_sched *sched, lm_photon_store *ps, const double *saved)
{
    for (int s = 0; s < sched->surface_count; s++)
        if (sched->commit[s])
            sched->commit[s] = 0, ps->surfaces[s].delta_i = saved[s];
}

double lm_delta_i_pending(const lm_photon_store *ps, int s)
{
    double e = lm_photon_store_iim_energy(ps, s), d = ps->surfaces[s].delta_i;
    return !(d > 0.0) ? 0.0 : e > 0.0 && isfinite(d / e) ? d / e : 1.0;
}
