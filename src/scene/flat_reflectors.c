/* Flat reflectors (flat_reflectors.h). */
#include "flat_reflectors.h"

#include <math.h>

#include "../core/vecmath.h"

static lm_vec3 corner(const lm_scene *s, uint32_t t, int k)
{
    float p[3];
    lm_scene_vertex_world(s, s->tris[3 * (size_t)t + k], p);
    return lm_v3_load(p);
}

float lm_node_reflector_plane(const lm_scene *s, int node, float plane[4], float *extent)
{
    const lm_node *nd = &s->nodes[node];
    lm_vec3 sum = lm_v3(0.0f, 0.0f, 0.0f), lo = lm_v3(INFINITY, INFINITY, INFINITY), hi = lm_scale(lo, -1.0f);
    uint32_t first = UINT32_MAX;
    for (uint32_t t = nd->first_tri; t < nd->first_tri + nd->tri_count; t++) {
        if (!lm_material_reflects(s->materials[s->tri_material[t]].cls))
            continue;
        first = first == UINT32_MAX ? t : first;
        lm_vec3 p[3] = {corner(s, t, 0), corner(s, t, 1), corner(s, t, 2)};
        for (int k = 0; k < 3; k++)
            lo = lm_vmin(lo, p[k]), hi = lm_vmax(hi, p[k]);
        lm_vec3 c = lm_cross(lm_sub(p[1], p[0]), lm_sub(p[2], p[0]));
        sum = lm_add(sum, lm_dot(c, sum) < 0.0f ? lm_scale(c, -1.0f) : c);
    }
    *extent = first == UINT32_MAX ? 0.0f : lm_length(lm_sub(hi, lo));
    if (!(lm_length(sum) > 0.0f))
        return -1.0f;
    lm_vec3 n = lm_normalize(sum);
    float w = -lm_dot(n, corner(s, first, 0)), far = 0.0f;
    for (uint32_t t = first; t < nd->first_tri + nd->tri_count; t++)
        for (int k = 0; k < 3 && lm_material_reflects(s->materials[s->tri_material[t]].cls); k++)
            far = fmaxf(far, fabsf(lm_dot(n, corner(s, t, k)) + w));
    lm_v3_store(plane, n);
    plane[3] = w;
    return far;
}

int lm_node_is_flat_reflector(const lm_scene *s, int node)
{
    const lm_node *nd = &s->nodes[node];
    if (nd->settings.has_reflection_box)
        return 0;
    int any = 0;
    for (uint32_t t = nd->first_tri; t < nd->first_tri + nd->tri_count; t++) {
        lm_material_class c = s->materials[s->tri_material[t]].cls;
        if (c == LM_MAT_GLASS)
            return 0;
        any |= c == LM_MAT_MIRROR || c == LM_MAT_GLOSSY;
    }
    float plane[4], extent, far = any ? lm_node_reflector_plane(s, node, plane, &extent) : -1.0f;
    return far >= 0.0f && far <= LM_FLAT_TOLERANCE * extent;
}
