/* The public API's light and material edits. The photon stage notices a light whose power or placement
 * changed (its emitter snapshot) and re-traces that light's groups alone, and a material whose colour or
 * emission changed (its material snapshot) and re-traces the groups that touch it. */
#include <lmgi.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../core/vecmath.h"
#include "lmgi_scene.h"
#include "lmgi_updater.h"

int lmgi_light_count(const lmgi_scene *sc) { return sc ? sc->scene->light_count : 0; }

lmgi_status lmgi_get_light(const lmgi_scene *sc, int light, lmgi_light *out, lmgi_error *err)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (!sc || !out)
        return lm_api_refuse(err, "lmgi_get_light: %s is NULL", sc ? "out" : "the scene");
    if (light < 0 || light >= sc->scene->light_count)
        return lm_api_refuse(err, "light id %d is out of range (scene has %d lights)", light, sc->scene->light_count);
    const lm_light *l = &sc->scene->lights[light];
    out->type = (lmgi_light_type)l->type;
    out->node = l->node;
    memcpy(out->color, l->color, sizeof out->color);
    out->intensity = l->intensity;
    out->range = l->range;
    out->inner_cone = l->inner_cone;
    out->outer_cone = l->outer_cone;
    out->enabled = !l->off;
    return LMGI_OK;
}

static int in_range(float v, float lo, float hi) { return v >= lo && v <= hi; } /* false for NaN */

lmgi_status lmgi_set_light(lmgi_scene *sc, int light, const lmgi_light *in, lmgi_error *err)
{
    if (!sc || !in)
        return lm_api_refuse(err, "lmgi_set_light: %s is NULL", sc ? "the light" : "the scene");
    if (light < 0 || light >= sc->scene->light_count)
        return lm_api_refuse(err, "light id %d is out of range (scene has %d lights)", light, sc->scene->light_count);
    lm_light *l = &sc->scene->lights[light];
    if ((int)in->type != (int)l->type || in->node != l->node)
        return lm_api_refuse(err, "light '%s': its type and node are fixed at load", l->name);
    for (int c = 0; c < 3; c++)
        if (!in_range(in->color[c], 0.0f, 1000.0f))
            return lm_api_refuse(err, "light '%s': colour %g must be in [0, 1000]", l->name, (double)in->color[c]);
    if (!in_range(in->intensity, 0.0f, 1e15f) || !in_range(in->range, 0.0f, 1e15f))
        return lm_api_refuse(err, "light '%s': intensity %g and range %g must be finite numbers >= 0", l->name,
                      (double)in->intensity, (double)in->range);
    if (l->type == LM_LIGHT_SPOT && !(in_range(in->inner_cone, 0.0f, (float)(LM_PI / 2)) &&
                                      in_range(in->outer_cone, 0.0f, (float)(LM_PI / 2)) && in->inner_cone < in->outer_cone))
        return lm_api_refuse(err, "light '%s': cones %g and %g must satisfy 0 <= inner < outer <= pi/2", l->name,
                      (double)in->inner_cone, (double)in->outer_cone);
    if (sc->updater) /* its photon work reads the lights */
        lm_updater_sync(sc->updater);
    memcpy(l->color, in->color, sizeof l->color);
    l->intensity = in->intensity;
    l->range = in->range;
    if (l->type == LM_LIGHT_SPOT)
        l->inner_cone = in->inner_cone, l->outer_cone = in->outer_cone;
    l->off = !in->enabled;
    return LMGI_OK;
}

int lmgi_material_count(const lmgi_scene *sc) { return sc ? sc->scene->material_count : 0; }

const char *lmgi_material_name(const lmgi_scene *sc, int m)
{
    return sc && m >= 0 && m < sc->scene->material_count ? sc->scene->materials[m].name : NULL;
}

lmgi_status lmgi_get_material(const lmgi_scene *sc, int material, lmgi_material *out, lmgi_error *err)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (!sc || !out)
        return lm_api_refuse(err, "lmgi_get_material: %s is NULL", sc ? "out" : "the scene");
    if (material < 0 || material >= sc->scene->material_count)
        return lm_api_refuse(err, "material id %d is out of range (scene has %d materials)", material,
                      sc->scene->material_count);
    const lm_material *m = &sc->scene->materials[material];
    out->cls = (lmgi_material_class)m->cls;
    memcpy(out->base_color, m->base_color, sizeof out->base_color);
    memcpy(out->emissive, m->emissive, sizeof out->emissive);
    out->metallic = m->metallic;
    out->roughness = m->roughness;
    return LMGI_OK;
}

lmgi_status lmgi_set_material(lmgi_scene *sc, int material, const lmgi_material *in, lmgi_error *err)
{
    if (!sc || !in)
        return lm_api_refuse(err, "lmgi_set_material: %s is NULL", sc ? "the material" : "the scene");
    if (material < 0 || material >= sc->scene->material_count)
        return lm_api_refuse(err, "material id %d is out of range (scene has %d materials)", material,
                      sc->scene->material_count);
    lm_material *m = &sc->scene->materials[material];
    if ((int)in->cls != (int)m->cls)
        return lm_api_refuse(err, "material '%s': its class is fixed at load", m->name);
    for (int c = 0; c < 4; c++)
        if (!in_range(in->base_color[c], 0.0f, 1.0f))
            return lm_api_refuse(err, "material '%s': base colour %g must be in [0, 1]", m->name, (double)in->base_color[c]);
    for (int c = 0; c < 3; c++) {
        if (!in_range(in->emissive[c], 0.0f, 1e20f))
            return lm_api_refuse(err, "material '%s': emission %g must be a finite number >= 0", m->name,
                          (double)in->emissive[c]);
        if (in->emissive[c] > 0.0f && m->cls != LM_MAT_EMITTER)
            return lm_api_refuse(err, "material '%s' was not emissive at load: its triangles are not emitters, so it "
                          "cannot start to emit", m->name);
    }
    if (sc->updater) /* its photon work reads the materials */
        lm_updater_sync(sc->updater);
    memcpy(m->base_color, in->base_color, sizeof m->base_color);
    memcpy(m->emissive, in->emissive, sizeof m->emissive);
    sc->scene->material_version++;
    return LMGI_OK;
}
