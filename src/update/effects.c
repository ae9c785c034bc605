#include "effects.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../scene/flat_reflectors.h"

const char *lm_effect_name(lm_effect_id e)
{
    static const char *names[LM_EFFECT_COUNT] = {"direct", "shadows", "indirect", "caustics", "reflections",
                                                 "photon updates"};
    return (unsigned)e < LM_EFFECT_COUNT ? names[e] : "?";
}

/* The per-node extras switch that governs an effect. */
static int node_switch(const lm_node *node, lm_effect_id effect)
{
    return effect == LM_EFFECT_INDIRECT      ? node->settings.indirect
         : effect == LM_EFFECT_REFLECTIONS ? node->settings.reflections
                                           : node->settings.caustics;
}

/* Materials of class `cls` used by triangles of nodes where the effect's switch is on, and where off. */
typedef struct {
    int materials_on, materials_off;
    int first_node_on, first_node_off;
} usage;

static usage count_usage(const lm_scene *s, lm_material_class cls, lm_effect_id effect)
{
    usage u = {0, 0, -1, -1};
    unsigned char *seen = calloc(2 * (size_t)s->material_count + 2, 1); /* [on][material] */
    for (int n = 0; n < s->node_count; n++) {
        const lm_node *node = &s->nodes[n];
        int on = node_switch(node, effect) != 0;
        for (uint32_t t = node->first_tri; t < node->first_tri + node->tri_count; t++) {
            int m = s->tri_material[t];
            if (s->materials[m].cls != cls)
                continue;
            int *count = on ? &u.materials_on : &u.materials_off;
            int *first = on ? &u.first_node_on : &u.first_node_off;
            if (*first < 0)
                *first = n;
            if (seen && !seen[2 * (size_t)m + on]) {
                seen[2 * (size_t)m + on] = 1;
                (*count)++;
            }
        }
    }
    free(seen);
    return u;
}

/* Lights of a type (-1: any) that have not been removed. */
static int count_lights(const lm_scene *s, int type)
{
    int n = 0;
    for (int i = 0; i < s->light_count; i++)
        n += !s->lights[i].removed && (type < 0 || (int)s->lights[i].type == type);
    return n;
}

static void describe_lights(const lm_scene *s, char *buf, size_t n)
{
    int p = count_lights(s, LM_LIGHT_POINT), sp = count_lights(s, LM_LIGHT_SPOT);
    int d = count_lights(s, LM_LIGHT_DIRECTIONAL);
    snprintf(buf, n, "%d point, %d spot, %d directional light%s", p, sp, d, count_lights(s, -1) == 1 ? "" : "s");
}

static void decide_direct(const lm_scene *s, lm_effects *e)
{
    char lights[128];
    describe_lights(s, lights, sizeof lights);
    e->on[LM_EFFECT_DIRECT] = count_lights(s, -1) > 0;
    snprintf(e->reason[LM_EFFECT_DIRECT], 256, "%s", count_lights(s, -1) > 0 ? lights : "no point, spot or directional light");

    int casting = 0;
    for (int n = 0; n < s->node_count; n++)
        casting += s->nodes[n].tri_count > 0 && s->nodes[n].settings.shadows;
    e->on[LM_EFFECT_SHADOWS] = count_lights(s, -1) > 0 && casting > 0;
    if (count_lights(s, -1) == 0)
        snprintf(e->reason[LM_EFFECT_SHADOWS], 256, "no point, spot or directional light");
    else if (casting == 0)
        snprintf(e->reason[LM_EFFECT_SHADOWS], 256, "every node has extras shadows: false");
    else
        snprintf(e->reason[LM_EFFECT_SHADOWS], 256, "%d shadow-casting node%s under %s", casting,
                 casting == 1 ? "" : "s", lights);
}

static void decide_indirect(const lm_scene *s, lm_effects *e)
{
    usage emit = count_usage(s, LM_MAT_EMITTER, LM_EFFECT_INDIRECT);
    int receivers = 0;
    for (int n = 0; n < s->node_count; n++)
        receivers += s->nodes[n].tri_count > 0 && s->nodes[n].settings.indirect;
    int emitters = emit.materials_on + emit.materials_off;
    int first_emitter = emit.first_node_on >= 0 ? emit.first_node_on : emit.first_node_off;
    char *r = e->reason[LM_EFFECT_INDIRECT];
    e->on[LM_EFFECT_INDIRECT] = (count_lights(s, -1) > 0 || emitters > 0 || s->has_sky) && receivers > 0;
    if (count_lights(s, -1) == 0 && emitters == 0 && !s->has_sky)
        snprintf(r, 256, "no light, no emissive material and no sky (--sky)");
    else if (receivers == 0)
        snprintf(r, 256, "every node has extras indirect: false");
    else if (count_lights(s, -1) == 0 && emitters == 0)
        snprintf(r, 256, "the sky lights %d node%s", receivers, receivers == 1 ? "" : "s");
    else if (emitters == 0)
        snprintf(r, 256, "%d light%s%s bounce off %d node%s", count_lights(s, -1), count_lights(s, -1) == 1 ? "" : "s",
                 s->has_sky ? " and the sky" : "", receivers, receivers == 1 ? "" : "s");
    else
        snprintf(r, 256, "%d light%s%s and %d emissive material%s (first on node '%s') bounce off %d node%s",
                 count_lights(s, -1), count_lights(s, -1) == 1 ? "" : "s", s->has_sky ? ", the sky" : "", emitters,
                 emitters == 1 ? "" : "s", s->nodes[first_emitter].name, receivers, receivers == 1 ? "" : "s");
}

/* "1 mirror material on node 'x'", "1 mirror and 2 glass materials (the first on node 'x')": the classes'
 * materials where an effect is on; returns their count. */
static int describe_materials(const lm_scene *s, const usage *u, const char *const *kinds, int n, char *out,
                              size_t size)
{
    char what[160] = "";
    int total = 0, first = -1;
    for (int k = 0; k < n; k++) {
        if (!u[k].materials_on)
            continue;
        snprintf(what + strlen(what), sizeof what - strlen(what), "%s%d %s", what[0] ? " and " : "",
                 u[k].materials_on, kinds[k]);
        total += u[k].materials_on;
        first = first < 0 ? u[k].first_node_on : first;
    }
    if (total == 1)
        snprintf(out, size, "%s material on node '%s'", what, s->nodes[first].name);
    else if (total)
        snprintf(out, size, "%s materials (the first on node '%s')", what, s->nodes[first].name);
    return total;
}

/* The first node of the classes' materials where an effect is switched off (-1: none). */
static int first_off(const usage *u, int n)
{
    for (int k = 0; k < n; k++)
        if (u[k].first_node_off >= 0)
            return u[k].first_node_off;
    return -1;
}

/* Caustics come from mirror and glass materials that a light reaches, reflections from mirror, glossy and
 * glass ones. */
static void decide_specular(const lm_scene *s, lm_effects *e)
{
    static const char *const kinds[3] = {"mirror", "glass", "glossy"};
    const usage c[2] = {count_usage(s, LM_MAT_MIRROR, LM_EFFECT_CAUSTICS), count_usage(s, LM_MAT_GLASS, LM_EFFECT_CAUSTICS)};
    usage emit = count_usage(s, LM_MAT_EMITTER, LM_EFFECT_CAUSTICS);
    int lit = count_lights(s, -1) > 0 || emit.materials_on + emit.materials_off > 0;
    char what[200];
    int on = describe_materials(s, c, kinds, 2, what, sizeof what), off = first_off(c, 2);
    e->on[LM_EFFECT_CAUSTICS] = on > 0 && lit;
    if (on > 0 && lit)
        snprintf(e->reason[LM_EFFECT_CAUSTICS], 256, "%s", what);
    else if (on > 0)
        snprintf(e->reason[LM_EFFECT_CAUSTICS], 256, "no light to focus (%s)", what);
    else if (off >= 0)
        snprintf(e->reason[LM_EFFECT_CAUSTICS], 256, "mirror and glass materials only on nodes with caustics "
                 "switched off (first: '%s')", s->nodes[off].name);
    else
        snprintf(e->reason[LM_EFFECT_CAUSTICS], 256, "no mirror or glass material");

    const usage r[3] = {count_usage(s, LM_MAT_MIRROR, LM_EFFECT_REFLECTIONS),
                        count_usage(s, LM_MAT_GLASS, LM_EFFECT_REFLECTIONS),
                        count_usage(s, LM_MAT_GLOSSY, LM_EFFECT_REFLECTIONS)};
    on = describe_materials(s, r, kinds, 3, e->reason[LM_EFFECT_REFLECTIONS], 256);
    off = first_off(r, 3);
    e->on[LM_EFFECT_REFLECTIONS] = on > 0;
    int flat = 0;
    for (int n = 0; on > 0 && n < s->node_count; n++)
        flat += s->nodes[n].settings.reflections && lm_node_is_flat_reflector(s, n);
    if (flat) { /* which of them reflect the view mirrored in their plane, not a cube map */
        size_t len = strlen(e->reason[LM_EFFECT_REFLECTIONS]);
        snprintf(e->reason[LM_EFFECT_REFLECTIONS] + len, 256 - len, "; %d flat node%s: the view mirrored in %s plane",
                 flat, flat == 1 ? "" : "s", flat == 1 ? "its" : "their");
    }
    if (!on && off >= 0)
        snprintf(e->reason[LM_EFFECT_REFLECTIONS], 256, "mirror, glossy and glass materials only on nodes with "
                 "reflections switched off (first: '%s')", s->nodes[off].name);
    else if (!on)
        snprintf(e->reason[LM_EFFECT_REFLECTIONS], 256, "no mirror, glossy or glass material");
}

static void decide_updates(const lm_scene *s, lm_effects *e)
{
    int dyn = 0, first = -1;
    for (int n = 0; n < s->node_count; n++)
        if (lm_node_moves(&s->nodes[n])) {
            if (first < 0)
                first = n;
            dyn++;
        }
    e->on[LM_EFFECT_PHOTON_UPDATES] = e->on[LM_EFFECT_INDIRECT] && dyn > 0;
    if (!e->on[LM_EFFECT_INDIRECT])
        snprintf(e->reason[LM_EFFECT_PHOTON_UPDATES], 256, "no indirect light to update");
    else if (dyn > 0)
        snprintf(e->reason[LM_EFFECT_PHOTON_UPDATES], 256, "%d dynamic node%s (first: '%s'); photons re-traced round robin",
                 dyn, dyn == 1 ? "" : "s", s->nodes[first].name);
    else
        snprintf(e->reason[LM_EFFECT_PHOTON_UPDATES], 256, "nothing moves; photons traced once, updated only on edits");
}

void lm_effects_decide(const lm_scene *s, lm_effects *out)
{
    memset(out, 0, sizeof *out);
    decide_direct(s, out);
    decide_indirect(s, out);
    decide_specular(s, out);
    decide_updates(s, out);
}
