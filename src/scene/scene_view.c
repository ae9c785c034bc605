/* The picture's camera for a scene (scene_view.h): the file's, or one framing the scene. */
#include "scene_view.h"

#include <stdio.h>
#include <string.h>

#include "../core/vecmath.h"

_Static_assert(LM_VIEW_NAME_MAX == LM_NAME_MAX, "a view is named as long as a scene's names");

static void ortho(float m[16], float xmag, float ymag, float znear, float zfar)
{
    lm_mat4_identity(m);
    m[0] = 1.0f / xmag;
    m[5] = 1.0f / ymag;
    m[10] = 2.0f / (znear - zfar);
    m[14] = (zfar + znear) / (znear - zfar);
}

static void from_file(const lm_scene *s, const lm_camera *c, float aspect, lm_view *out)
{
    const float *w = s->nodes[c->node].world;
    /* The camera looks down its node's -Z; the view matrix is the inverse of its world matrix,
     * with the scale removed so a scaled camera node does not squash the picture. */
    lm_vec3 eye = lm_v3(w[12], w[13], w[14]);
    lm_vec3 fwd = lm_normalize(lm_mat4_dir(w, lm_v3(0, 0, -1)));
    lm_vec3 up = lm_normalize(lm_mat4_dir(w, lm_v3(0, 1, 0)));
    lm_mat4_look_at(out->view, eye, lm_add(eye, fwd), up);
    lm_v3_store(out->eye, eye);
    float zfar = c->zfar > 0 ? c->zfar : 10.0f * lm_scene_size(s) + c->znear;
    float znear = c->znear > 0 ? c->znear : 1e-3f * lm_scene_size(s);
    if (c->perspective)
        lm_mat4_perspective(out->proj, c->yfov > 0 ? c->yfov : 0.8f, aspect, znear, zfar);
    else
        ortho(out->proj, c->xmag > 0 ? c->xmag : 1.0f, c->ymag > 0 ? c->ymag : 1.0f, znear, zfar);
    out->from_file = 1;
    snprintf(out->name, sizeof out->name, "%s", c->name[0] ? c->name : "camera");
}

static void automatic(const lm_scene *s, float aspect, lm_view *out)
{
    lm_vec3 lo = lm_v3_load(s->bounds_min), hi = lm_v3_load(s->bounds_max);
    lm_vec3 c = lm_scale(lm_add(lo, hi), 0.5f);
    float r = 0.5f * lm_length(lm_sub(hi, lo));
    if (!(r > 0.0f))
        r = 1.0f;
    const float yfov = 0.8f;
    float fov = aspect < 1.0f ? 2.0f * atanf(tanf(0.5f * yfov) * aspect) : yfov;
    float dist = r / sinf(0.5f * fov);
    lm_vec3 dir = lm_normalize(lm_v3(0.35f, 0.45f, 1.0f));
    lm_vec3 eye = lm_add(c, lm_scale(dir, dist));
    lm_mat4_look_at(out->view, eye, c, lm_v3(0, 1, 0));
    lm_mat4_perspective(out->proj, yfov, aspect, 0.01f * r, dist + 2.0f * r);
    lm_v3_store(out->eye, eye);
    out->from_file = 0;
    snprintf(out->name, sizeof out->name, "automatic");
}

void lm_view_for_scene(const lm_scene *s, int camera, int width, int height, lm_view *out)
{
    memset(out, 0, sizeof *out);
    float aspect = (float)width / (float)(height > 0 ? height : 1);
    if (camera < 0 && s->camera_count > 0)
        camera = 0;
    if (camera >= 0 && camera < s->camera_count && s->cameras[camera].node >= 0 &&
        s->cameras[camera].node < s->node_count) {
        const lm_camera *c = &s->cameras[camera];
        from_file(s, c, aspect, out); /* the picture's aspect wins, as viewers do */
    } else {
        automatic(s, aspect, out);
    }
}
