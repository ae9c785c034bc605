/* The public API's light, material and sky edits: each checked, then staged until the next commit
 * (update/edits.h), never waiting for the photon work. The commit hands the photon stage the lights and
 * materials whose values changed: it re-traces a changed light's groups alone, and the groups that touch
 * a changed material. Reads (lmgi_get_light, ...) see the staged values. */
#include <lmgi.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"
#include "../scene/sky.h"
#include "../update/effects.h"
#include "lmgi_scene.h"

int lmgi_light_count(const lmgi_scene *sc) { return sc ? lm_edits_light_count(&sc->edits, sc->scene) : 0; }

int lmgi_light_is_removed(const lmgi_scene *sc, int light)
{
    const lm_light *l = sc ? lm_edits_light(&sc->edits, sc->scene, light) : NULL;
    return l && l->removed;
}

/* The light `light` names as the edits left it, or NULL with err filled (an id out of range, or of a
 * removed light). */
static const lm_light *live_light(const lmgi_scene *sc, int light, lmgi_error *err)
{
    const lm_light *l = lm_edits_light(&sc->edits, sc->scene, light);
    if (!l) {
        lm_api_refuse(err, "light id %d is out of range (scene has %d lights)", light, lmgi_light_count(sc));
        return NULL;
    }
    if (l->removed) {
        lm_api_refuse(err, "light %d ('%s') was removed", light, l->name);
        return NULL;
    }
    return l;
}

lmgi_status lmgi_get_light(const lmgi_scene *sc, int light, lmgi_light *out, lmgi_error *err)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (!sc || !out)
        return lm_api_refuse(err, "lmgi_get_light: %s is NULL", sc ? "out" : "the scene");
    const lm_light *l = live_light(sc, light, err);
    if (!l)
        return LMGI_ERR_INVALID;
    out->type = (lmgi_light_type)l->type;
    out->node = l->node;
    memcpy(out->color, l->color, sizeof out->color);
    out->intensity = l->intensity;
    out->range = l->range;
    out->inner_cone = l->inner_cone;
    out->outer_cone = l->outer_cone;
    out->enabled = !l->off;
    lm_light_place(sc->scene, l, out->position, out->direction);
    for (int k = 0; k < 3; k++) /* lmgi's world to the file's */
        out->position[k] += sc->scene->origin[k];
    return LMGI_OK;
}

static int in_range(float v, float lo, float hi) { return v >= lo && v <= hi; } /* false for NaN */

/* What lmgi_set_light and lmgi_add_light accept of in for a light of type `type` named `name`; the
 * placement (position, direction) too when `placed`. */
static lmgi_status check_light(const lmgi_light *in, lm_light_type type, const char *name, int placed,
                               lmgi_error *err)
{
    char what[LM_NAME_MAX + 16];
    snprintf(what, sizeof what, "light '%s'", name);
    lm_error e;
    if (lm_light_check(what, in->color, in->intensity, in->range, type == LM_LIGHT_SPOT, in->inner_cone,
                       in->outer_cone, &e) != LM_OK)
        return lm_export_error(err, &e);
    if (!placed)
        return LMGI_OK;
    for (int k = 0; k < 3; k++)
        if (!in_range(in->position[k], -LM_MAX_COORDINATE, LM_MAX_COORDINATE) || !isfinite(in->direction[k]))
            return lm_api_refuse(err, "light '%s': position (%g %g %g) and direction must be finite, the position "
                                 "within %g of the origin", name, (double)in->position[0], (double)in->position[1],
                                 (double)in->position[2], (double)LM_MAX_COORDINATE);
    lm_vec3 d = lm_v3_load(in->direction);
    if (type != LM_LIGHT_POINT && !(lm_dot(d, d) > 1e-30f))
        return lm_api_refuse(err, "light '%s': a %s light needs a direction (it is 0)", name,
                             lm_light_type_name(type));
    return LMGI_OK;
}

/* The edit in made on l (checked): colour, intensity, range, cones, on or off, and an added light's
 * place. */
static void apply_light(const lmgi_scene *sc, lm_light *l, const lmgi_light *in)
{
    memcpy(l->color, in->color, sizeof l->color);
    l->intensity = in->intensity;
    l->range = in->range;
    if (l->type == LM_LIGHT_SPOT)
        l->inner_cone = in->inner_cone, l->outer_cone = in->outer_cone;
    l->off = !in->enabled;
    if (l->node < 0) {
        lm_vec3 d = lm_v3_load(in->direction);
        lm_v3_store(l->pos, lm_sub(lm_v3_load(in->position), lm_v3_load(sc->scene->origin)));
        lm_v3_store(l->dir, lm_dot(d, d) > 1e-30f ? lm_normalize(d) : lm_v3(0, 0, -1));
    }
}

lmgi_status lmgi_set_light(lmgi_scene *sc, int light, const lmgi_light *in, lmgi_error *err)
{
    if (!sc || !in)
        return lm_api_refuse(err, "lmgi_set_light: %s is NULL", sc ? "the light" : "the scene");
    const lm_light *l = live_light(sc, light, err);
    if (!l)
        return LMGI_ERR_INVALID;
    if ((int)in->type != (int)l->type || in->node != l->node)
        return lm_api_refuse(err, "light '%s': its type and node are fixed at load", l->name);
    lmgi_status st = check_light(in, l->type, l->name, l->node < 0, err);
    if (st != LMGI_OK)
        return st;
    lm_light edited = *l;
    apply_light(sc, &edited, in);
    return lm_scene_stage_light(sc, "lmgi_set_light", light, &edited, err);
}

lmgi_status lmgi_add_light(lmgi_scene *sc, const lmgi_light *in, int *id, lmgi_error *err)
{
    if (id)
        *id = -1;
    if (!sc || !in || !id)
        return lm_api_refuse(err, "lmgi_add_light: %s is NULL", !sc ? "the scene" : !in ? "the light" : "id");
    if ((int)in->type < LMGI_LIGHT_POINT || (int)in->type > LMGI_LIGHT_DIRECTIONAL)
        return lm_api_refuse(err, "lmgi_add_light: type %d is not a light type (0 point, 1 spot, 2 directional)",
                             (int)in->type);
    int count = lmgi_light_count(sc);
    char name[LM_NAME_MAX];
    snprintf(name, sizeof name, "added light %d", count);
    lmgi_status st = check_light(in, (lm_light_type)in->type, name, 1, err);
    if (st != LMGI_OK)
        return st;
    if (count >= 1 << 20)
        return lm_api_refuse(err, "lmgi_add_light: the scene has %d lights, the most it may have", count);
    lm_light l;
    memset(&l, 0, sizeof l);
    memcpy(l.name, name, sizeof l.name);
    l.type = (lm_light_type)in->type;
    l.node = -1;
    l.added = 1;
    l.inner_cone = 0.0f, l.outer_cone = (float)(LM_PI / 4);
    apply_light(sc, &l, in);
    st = lm_scene_stage_light(sc, "lmgi_add_light", -1, &l, err);
    if (st == LMGI_OK)
        *id = count;
    return st;
}

lmgi_status lmgi_remove_light(lmgi_scene *sc, int light, lmgi_error *err)
{
    if (!sc)
        return lm_api_refuse(err, "lmgi_remove_light: the scene is NULL");
    const lm_light *l = live_light(sc, light, err);
    if (!l)
        return LMGI_ERR_INVALID;
    lm_light removed = *l;
    removed.removed = 1;
    return lm_scene_stage_light(sc, "lmgi_remove_light", light, &removed, err);
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
    const lm_material *m = lm_edits_material(&sc->edits, sc->scene, material);
    out->cls = (lmgi_material_class)m->cls;
    memcpy(out->base_color, m->base_color, sizeof out->base_color);
    memcpy(out->emissive, m->emissive, sizeof out->emissive);
    out->metallic = m->metallic;
    out->roughness = m->roughness;
    out->transmission = m->transmission;
    out->ior = m->ior;
    return LMGI_OK;
}

/* The class in's parameters give m by the load's rule (docs/materials.md), or why m cannot take them. */
static lmgi_status new_class(const lm_material *m, const lmgi_material *in, lm_material_class *out, lmgi_error *err)
{
    int same = in->metallic == m->metallic && in->roughness == m->roughness &&
               in->transmission == m->transmission && in->ior == m->ior;
    if (m->cls == LM_MAT_EMITTER) { /* its triangles are the emitters: only its emission and colour change */
        *out = LM_MAT_EMITTER;
        return same ? LMGI_OK : lm_api_refuse(err, "material '%s' is an emitter: its triangles emit, and its class "
                                              "(metallic, roughness, transmission, ior) is fixed", m->name);
    }
    lm_material probe = *m;
    probe.metallic = in->metallic, probe.roughness = in->roughness;
    probe.transmission = in->transmission, probe.ior = in->ior;
    memset(probe.emissive, 0, sizeof probe.emissive);
    *out = lm_material_classify(&probe);
    if (!lm_material_is_specular(*out) && !m->lightmapped)
        return lm_api_refuse(err, "material '%s' was %s at load, so its triangles have no lightmap texels and it "
                             "cannot become %s (mirror and glass it may; load the scene with the new material)",
                             m->name, lm_material_class_name(m->cls), lm_material_class_name(*out));
    if ((int)in->cls != (int)m->cls && (int)in->cls != (int)*out)
        return lm_api_refuse(err, "material '%s': its class is read only (cls): metallic %g, roughness %g and transmission %g "
                             "make it %s (docs/materials.md)", m->name, (double)in->metallic, (double)in->roughness,
                             (double)in->transmission, lm_material_class_name(*out));
    return LMGI_OK;
}

lmgi_status lmgi_set_material(lmgi_scene *sc, int material, const lmgi_material *in, lmgi_error *err)
{
    if (!sc || !in)
        return lm_api_refuse(err, "lmgi_set_material: %s is NULL", sc ? "the material" : "the scene");
    if (material < 0 || material >= sc->scene->material_count)
        return lm_api_refuse(err, "material id %d is out of range (scene has %d materials)", material,
                      sc->scene->material_count);
    const lm_material *m = lm_edits_material(&sc->edits, sc->scene, material);
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
    if (!in_range(in->metallic, 0.0f, 1.0f) || !in_range(in->roughness, 0.0f, 1.0f) ||
        !in_range(in->transmission, 0.0f, 1.0f) || !(in_range(in->ior, 1.0f, 10.0f) || in->ior == m->ior))
        return lm_api_refuse(err, "material '%s': metallic %g, roughness %g and transmission %g must be in [0, 1], "
                             "ior %g in [1, 10]", m->name, (double)in->metallic, (double)in->roughness,
                             (double)in->transmission, (double)in->ior);
    lm_material_class cls;
    lmgi_status st = new_class(m, in, &cls, err);
    if (st != LMGI_OK)
        return st;
    lm_material edited = *m;
    memcpy(edited.base_color, in->base_color, sizeof edited.base_color);
    memcpy(edited.emissive, in->emissive, sizeof edited.emissive);
    edited.metallic = in->metallic, edited.roughness = in->roughness;
    edited.transmission = in->transmission, edited.ior = in->ior;
    edited.cls = cls;
    return lm_scene_stage_material(sc, "lmgi_set_material", material, &edited, err);
}

/* A sky's radiance, refused unless finite and in [0, LM_MAX_EMISSION]. */
static lmgi_status check_sky(const float *rgb, const char *what, lmgi_error *err)
{
    for (int c = 0; c < 3; c++)
        if (!in_range(rgb[c], 0.0f, (float)LM_MAX_EMISSION))
            return lm_api_refuse(err, "sky radiance %s(%g %g %g) must be finite numbers in [0, %g]", what,
                                 (double)rgb[0], (double)rgb[1], (double)rgb[2], LM_MAX_EMISSION);
    return LMGI_OK;
}

/* Before a sky edit: an updater that gathers by hemicube cannot show a sky that is not uniform. */
static lmgi_status sky_edit_allowed(lmgi_scene *sc, int uniform, lmgi_error *err)
{
    if (!sc->updater)
        return LMGI_OK;
    lm_gather_scheme scheme = lm_frame_loop_get_settings(sc->loop)->gather.scheme;
    if (!uniform && scheme != LM_GATHER_RAYS)
        return lm_api_refuse(err, "%s: a gradient or image sky needs the rays gather, and this updater draws "
                             "hemicubes (%s): give the sky before lmgi_updater_create, or ask for rays",
                             sc->scene->path, lm_gather_scheme_name(scheme));
    return LMGI_OK;
}

/* A uniform or gradient sky staged. */
static lmgi_status sky_set(lmgi_scene *sc, lm_sky_kind kind, const float sky[3], const float *horizon, lmgi_error *err)
{
    lm_staged_sky k;
    memset(&k, 0, sizeof k);
    k.kind = kind;
    memcpy(k.sky, sky, sizeof k.sky);
    if (horizon)
        memcpy(k.horizon, horizon, sizeof k.horizon);
    return lm_scene_stage_sky(sc, "the sky edit", &k, err);
}

lmgi_status lmgi_set_environment(lmgi_scene *sc, const float radiance[3], lmgi_error *err)
{
    if (!sc || !radiance)
        return lm_api_refuse(err, "lmgi_set_environment: %s is NULL", sc ? "the radiance" : "the scene");
    lmgi_status st = check_sky(radiance, "", err);
    if (st == LMGI_OK)
        st = sky_edit_allowed(sc, 1, err);
    return st == LMGI_OK ? sky_set(sc, LM_SKY_UNIFORM, radiance, NULL, err) : st;
}

lmgi_status lmgi_set_environment_gradient(lmgi_scene *sc, const float zenith[3], const float horizon[3],
                                          lmgi_error *err)
{
    if (!sc || !zenith || !horizon)
        return lm_api_refuse(err, "lmgi_set_environment_gradient: %s is NULL", sc ? "a colour" : "the scene");
    lmgi_status st = check_sky(zenith, "at the zenith ", err);
    if (st == LMGI_OK)
        st = check_sky(horizon, "at the horizon ", err);
    if (st == LMGI_OK)
        st = sky_edit_allowed(sc, 0, err);
    return st == LMGI_OK ? sky_set(sc, LM_SKY_GRADIENT, zenith, horizon, err) : st;
}

lmgi_status lmgi_set_environment_image(lmgi_scene *sc, const char *path, float scale, lmgi_error *err)
{
    if (!sc || !path)
        return lm_api_refuse(err, "lmgi_set_environment_image: %s is NULL", sc ? "the path" : "the scene");
    lmgi_status st = sky_edit_allowed(sc, 0, err);
    if (st != LMGI_OK)
        return st;
    /* read into a scene of its own (lm_sky_load_image's errors name the file), then staged */
    lm_scene *probe = calloc(1, sizeof *probe);
    if (!probe)
        return lm_export_error(err, &(lm_error){LM_ERR_NOMEM, "lmgi_set_environment_image: no memory"});
    snprintf(probe->path, sizeof probe->path, "%s", sc->scene->path);
    lm_error e;
    const float k[3] = {scale, scale, scale};
    if (lm_sky_load_image(probe, path, k, &e) != LM_OK) {
        free(probe);
        return lm_export_error(err, &e);
    }
    lm_staged_sky sky = {0, LM_SKY_IMAGE, {k[0], k[1], k[2]}, {0}, probe->sky_image, probe->sky_width,
                         probe->sky_height, {0}};
    memcpy(sky.image_mean, probe->sky_image_mean, sizeof sky.image_mean);
    free(probe);
    st = lm_scene_stage_sky(sc, "lmgi_set_environment_image", &sky, err);
    if (st != LMGI_OK)
        free(sky.image);
    return st;
}

int lmgi_get_environment(const lmgi_scene *sc, float out[3])
{
    const lm_staged_sky *k = sc ? lm_edits_sky(&sc->edits) : NULL;
    int has = k || (sc && sc->scene->has_sky);
    for (int c = 0; out && c < 3; c++)
        out[c] = k ? k->sky[c] : has ? sc->scene->sky[c] : 0.0f;
    return has;
}
