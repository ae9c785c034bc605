/* The viewer's mouse and keys (view_state.h): camera moves, node and light edits with their undo,
 * saving, screenshots. */
#include "view_state.h"

#include <GL/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define LIGHT_STEP 1.25f     /* + and - multiply or divide a light's intensity by this */
#define TURN_STEP 0.2617994f /* ctrl + wheel turns the selected node by 15 degrees a step */
#define CLICK_PIXELS 3.0     /* a press and release closer than this is a click (select), not a drag */

/* The next name of `fmt` (a number, then `tail`) that no file in the working folder has, counting on from
 * *counter: what the viewer writes never replaces a file. */
static void free_name(char *out, size_t n, const char *fmt, const char *tail, int *counter)
{
    do
        snprintf(out, n, fmt, ++*counter, tail);
    while (access(out, F_OK) == 0 && *counter < 100000);
}

void lm_viewer_select_light(lm_viewer *v, int from)
{
    int n = lmgi_light_count(v->sc);
    v->light = -1;
    for (int k = 0; k < n; k++) {
        int id = (from + k) % n;
        if (!lmgi_light_is_removed(v->sc, id)) {
            v->light = id;
            break;
        }
    }
}

/* The window's camera (window pixels, not the framebuffer's: the cursor's) and the ray under the cursor. */
static void cursor_ray(lm_viewer *v, double x, double y, float org[3], float dir[3])
{
    int ww, wh;
    glfwGetWindowSize(v->win, &ww, &wh);
    lmgi_camera cam;
    lm_view_camera_get(&v->cam, ww, wh, &cam);
    lm_view_ray(&cam, x, y, ww, wh, org, dir);
}

/* An edit the scene took (st) kept as a step undo can take back, the lighting told to catch up; a
 * refusal said instead. 1 when taken. */
static int keep_step(lm_viewer *v, lmgi_status st, const lm_view_step *step, const lmgi_error *err, const char *what)
{
    if (st != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err->message);
        char line[96];
        snprintf(line, sizeof line, "the %s was refused (the terminal says why)", what);
        lm_viewer_say(v, line);
        return 0;
    }
    lm_view_history_push(&v->history, step);
    lm_viewer_edited(v, step->kind == LM_VIEW_NODE);
    return 1;
}

/* The selected light set to l (before: as it was), as a step undo can take back. */
static void commit_light(lm_viewer *v, const lmgi_light *before, const lmgi_light *l)
{
    lmgi_error err;
    lm_view_step step = {.kind = LM_VIEW_LIGHT, .id = v->light, .light_before = *before, .light_after = *l};
    if (!keep_step(v, lmgi_set_light(v->sc, v->light, l, &err), &step, &err, "light edit"))
        return;
    char what[160];
    snprintf(what, sizeof what, "light %d %s, intensity %.4g, colour %.2f %.2f %.2f, at %.2f %.2f %.2f", v->light,
             l->enabled ? "on" : "off", (double)l->intensity, (double)l->color[0], (double)l->color[1],
             (double)l->color[2], (double)l->position[0], (double)l->position[1], (double)l->position[2]);
    lm_viewer_say(v, what);
}

/* rgb made the colour after it in palette (of n), or the first when it is none of them. */
static void next_colour(float rgb[3], const float palette[][3], int n)
{
    int next = 0;
    for (int c = 0; c < n; c++)
        if (!memcmp(rgb, palette[c], sizeof palette[c]))
            next = (c + 1) % n;
    memcpy(rgb, palette[next], sizeof palette[next]);
}

/* The selected light changed by f (intensity times f; f = 0: switched off or on again; f < 0: the next
 * of a few colours). */
static void edit_light(lm_viewer *v, float f)
{
    lmgi_light l, before;
    lmgi_error err;
    if (v->light < 0 || lmgi_get_light(v->sc, v->light, &l, &err) != LMGI_OK) {
        lm_viewer_say(v, "no light to edit (the scene has none)");
        return;
    }
    before = l;
    if (f == 0.0f)
        l.enabled = !l.enabled;
    else if (f < 0.0f) { /* white, warm, cool */
        static const float colours[3][3] = {{1.0f, 1.0f, 1.0f}, {1.0f, 0.75f, 0.5f}, {0.6f, 0.75f, 1.0f}};
        next_colour(l.color, colours, 3);
    } else
        l.intensity *= f;
    commit_light(v, &before, &l);
}

/* Holds the selected light (and its node's matrix, when a node places it) as the start of a move; 0 with a
 * message when there is no light with a place to move. */
static int hold_light(lm_viewer *v)
{
    lmgi_error err;
    if (v->light < 0 || lmgi_get_light(v->sc, v->light, &v->light_grab, &err) != LMGI_OK ||
        v->light_grab.type == LMGI_LIGHT_DIRECTIONAL) {
        lm_viewer_say(v, "select a point or spot light first (L): a directional light has no place");
        return 0;
    }
    if (v->light_grab.node >= 0)
        lmgi_get_node_transform(v->sc, v->light_grab.node, v->grab_start);
    return 1;
}

/* The held light placed at its start plus d: a light of the file by moving its node (a node without
 * triangles may move even when static), an added one by its own position. */
static void place_light(lm_viewer *v, const float d[3])
{
    lmgi_error err;
    lmgi_status st;
    if (v->light_grab.node >= 0) {
        float m[16];
        memcpy(m, v->grab_start, sizeof m);
        for (int k = 0; k < 3; k++)
            m[12 + k] += d[k];
        st = lmgi_set_node_transform(v->sc, v->light_grab.node, m, &err);
    } else {
        lmgi_light l = v->light_grab;
        for (int k = 0; k < 3; k++)
            l.position[k] += d[k];
        st = lmgi_set_light(v->sc, v->light, &l, &err);
    }
    if (st != LMGI_OK)
        fprintf(stderr, "lmgi: error: %s\n", err.message);
    else
        lm_viewer_edited(v, v->light_grab.node >= 0); /* its node moved: anything under it too */
}

/* The held light's move as a step undo can take back (none when it did not move); `how` names it (a drag
 * released, a key's step) for the line that says when its light followed (lm_viewer_placed). */
static void end_light_move(lm_viewer *v, const char *how)
{
    lmgi_light l;
    lmgi_error err;
    if (lmgi_get_light(v->sc, v->light, &l, &err) != LMGI_OK || !memcmp(l.position, v->light_grab.position, sizeof l.position))
        return;
    lm_viewer_placed(v, how);
    lm_view_step step = {.kind = LM_VIEW_LIGHT, .id = v->light, .light_before = v->light_grab, .light_after = l};
    if (l.node >= 0) {
        step.kind = LM_VIEW_NODE, step.id = l.node;
        memcpy(step.before, v->grab_start, sizeof step.before);
        lmgi_get_node_transform(v->sc, l.node, step.after);
    }
    lm_view_history_push(&v->history, &step);
    char what[128];
    snprintf(what, sizeof what, "light %d moved to %.2f %.2f %.2f", v->light, (double)l.position[0],
             (double)l.position[1], (double)l.position[2]);
    lm_viewer_say(v, what);
}

/* Page up / down: the selected light raised or lowered by a twentieth of the scene. */
static void raise_light(lm_viewer *v, float sign)
{
    if (!hold_light(v))
        return;
    const float d[3] = {0.0f, sign * 0.05f * v->cam.scene_size, 0.0f};
    place_light(v, d);
    end_light_move(v, sign > 0.0f ? "light raised" : "light lowered");
}

/* Alt + press: the selected light follows the cursor on the horizontal plane at its height. */
static void grab_light(lm_viewer *v, double x, double y)
{
    float org[3], dir[3];
    if (!hold_light(v))
        return;
    cursor_ray(v, x, y, org, dir);
    if (!lm_view_ray_plane(org, dir, v->light_grab.position[1], v->grab)) {
        lm_viewer_say(v, "look down at the light's height to move it (its plane is behind or level with the eye)");
        return;
    }
    v->drag = 4;
}

static void move_light(lm_viewer *v, double x, double y)
{
    float org[3], dir[3], p[3];
    cursor_ray(v, x, y, org, dir);
    if (!lm_view_ray_plane(org, dir, v->grab[1], p))
        return;
    const float d[3] = {p[0] - v->grab[0], 0.0f, p[2] - v->grab[2]};
    place_light(v, d);
}

/* The material clicked last, changed: B its base colour to the next of a few (its own first), G and
 * shift+G an emitter's emission brighter or dimmer (x 1.25). */
static void edit_material(lm_viewer *v, int emission, float f)
{
    lmgi_material m, before;
    lmgi_error err;
    if (v->material < 0 || lmgi_get_material(v->sc, v->material, &m, &err) != LMGI_OK) {
        lm_viewer_say(v, "click a surface first: its material is the one edited");
        return;
    }
    before = m;
    if (emission) {
        if (m.cls != LMGI_MATERIAL_EMITTER) {
            lm_viewer_say(v, "that material does not emit (only one emissive in the file can: docs/materials.md)");
            return;
        }
        for (int k = 0; k < 3; k++)
            m.emissive[k] *= f;
    } else {
        static const float colours[5][3] = {
            {0.8f, 0.8f, 0.8f}, {0.7f, 0.1f, 0.1f}, {0.1f, 0.6f, 0.1f}, {0.1f, 0.2f, 0.7f}, {0.8f, 0.6f, 0.2f}};
        next_colour(m.base_color, colours, 5);
    }
    lm_view_step step = {.kind = LM_VIEW_MATERIAL, .id = v->material, .material_before = before, .material_after = m};
    if (!keep_step(v, lmgi_set_material(v->sc, v->material, &m, &err), &step, &err, "material edit"))
        return;
    char what[200];
    snprintf(what, sizeof what, "material %.80s: base colour %.2f %.2f %.2f, emission %.3g %.3g %.3g",
             lmgi_material_name(v->sc, v->material), (double)m.base_color[0], (double)m.base_color[1],
             (double)m.base_color[2], (double)m.emissive[0], (double)m.emissive[1], (double)m.emissive[2]);
    lm_viewer_say(v, what);
}

/* 1 2 3 4: the selected node's shadows, indirect light, reflections, caustics switched (and its
 * children's: lmgi_set_node_effects). */
static void switch_effect(lm_viewer *v, int which)
{
    lmgi_node_effects e, before;
    lmgi_error err;
    if (v->node < 0 || lmgi_get_node_effects(v->sc, v->node, &e, &err) != LMGI_OK) {
        lm_viewer_say(v, "click a node first: its effects are the ones switched");
        return;
    }
    before = e;
    int *sw[4] = {&e.shadows, &e.indirect, &e.reflections, &e.caustics};
    static const char *const names[4] = {"shadows", "indirect light", "reflections", "caustics"};
    *sw[which] = !*sw[which];
    lm_view_step step = {.kind = LM_VIEW_EFFECTS, .id = v->node, .effects_before = before, .effects_after = e};
    if (!keep_step(v, lmgi_set_node_effects(v->sc, v->node, &e, &err), &step, &err, "switch"))
        return;
    char what[160];
    snprintf(what, sizeof what, "node %.80s: %s %s", lmgi_node_name(v->sc, v->node), names[which],
             *sw[which] ? "on" : "off");
    lm_viewer_say(v, what);
}

/* V, shift+V: the next or previous view (view_maps.h); the exposure is metered again for it. */
static void next_map(lm_viewer *v, int step)
{
    v->map = (v->map + step + LM_VIEW_MAP_COUNT) % LM_VIEW_MAP_COUNT;
    v->exposure = 0.0f;
    char what[64];
    snprintf(what, sizeof what, "view: %s", lm_view_map_name(v->map));
    lm_viewer_say(v, what);
}

/* N: a point light at the camera's target, raised by a tenth of the scene, as bright as the selected light
 * (or 10 cd); Delete: the selected light removed. */
static void add_light(lm_viewer *v)
{
    lmgi_light l = {.type = LMGI_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 10.0f, .enabled = 1,
                    .direction = {0, -1, 0}, .outer_cone = 0.785398f};
    lmgi_light sel;
    lmgi_error err;
    if (v->light >= 0 && lmgi_get_light(v->sc, v->light, &sel, &err) == LMGI_OK && sel.type != LMGI_LIGHT_DIRECTIONAL)
        l.intensity = sel.intensity;
    memcpy(l.position, v->cam.target, sizeof l.position);
    l.position[1] += 0.1f * v->cam.scene_size;
    lm_view_step step = {.kind = LM_VIEW_LIGHT_ADDED, .light_after = l};
    if (!keep_step(v, lmgi_add_light(v->sc, &l, &step.id, &err), &step, &err, "new light"))
        return;
    v->light = step.id;
    char what[96];
    snprintf(what, sizeof what, "light %d added at the target", step.id);
    lm_viewer_say(v, what);
}

static void remove_light(lm_viewer *v)
{
    lmgi_light l;
    lmgi_error err;
    if (v->light < 0 || lmgi_get_light(v->sc, v->light, &l, &err) != LMGI_OK) {
        lm_viewer_say(v, "no light selected");
        return;
    }
    lm_view_step step = {.kind = LM_VIEW_LIGHT_REMOVED, .id = v->light, .light_before = l};
    if (!keep_step(v, lmgi_remove_light(v->sc, v->light, &err), &step, &err, "removal"))
        return;
    char what[96];
    snprintf(what, sizeof what, "light %d removed", v->light);
    lm_viewer_say(v, what);
    lm_viewer_select_light(v, v->light + 1);
}

static void undo_redo(lm_viewer *v, int redo)
{
    const lm_view_history *h = &v->history;
    const lm_view_step *step = redo ? (h->done < h->count ? &h->steps[h->done] : NULL)
                                    : (h->done > 0 ? &h->steps[h->done - 1] : NULL);
    /* a node or a light put back where it was (a light's colour or power places nothing) */
    int places = step && (step->kind == LM_VIEW_NODE ||
                          (step->kind == LM_VIEW_LIGHT &&
                           memcmp(step->light_before.position, step->light_after.position, sizeof step->light_after.position)));
    char what[160];
    lmgi_error err;
    err.message[0] = '\0';
    int ok = redo ? lm_view_redo(&v->history, v->sc, what, sizeof what, &err)
                  : lm_view_undo(&v->history, v->sc, what, sizeof what, &err);
    if (!ok && err.message[0])
        fprintf(stderr, "lmgi: error: %s\n", err.message);
    if (ok)
        lm_viewer_edited(v, 1); /* a step of any kind, a move among them */
    if (ok && places)
        lm_viewer_placed(v, redo ? "redo" : "undo");
    lm_viewer_say(v, what);
    if (v->light >= 0 && lmgi_light_is_removed(v->sc, v->light))
        lm_viewer_select_light(v, v->light + 1);
}

/* Ctrl+S: the scene as edited, with its lightmap, into the next free lmgi-view-scene-NNN folder
 * (lmgi_export_gltf: a glTF an engine or lmgi loads again). */
static void save_scene(lm_viewer *v)
{
    char dir[64];
    free_name(dir, sizeof dir, "lmgi-view-scene-%03d%s", "", &v->saves);
    lmgi_export_desc d = {.name = "scene"};
    lmgi_error err;
    if (lmgi_export_gltf(v->u, dir, &d, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        lm_viewer_say(v, "the scene could not be saved (the terminal says why)");
        v->failed = 1;
        return;
    }
    char what[96];
    snprintf(what, sizeof what, "saved %s/scene.gltf", dir);
    lm_viewer_say(v, what);
}

/* The lighting alone (the linear picture, no panel) to path: .png tone-mapped as shown, .exr the numbers. */
void lm_viewer_write_frame(lm_viewer *v, const char *path)
{
    lmgi_image_desc d = {(lmgi_tonemap)v->a->tonemap, v->exposure, 0};
    lmgi_error err;
    if (lmgi_write_image(path, v->width, v->height, 3, v->rgb, &d, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        v->failed = 1;
        return;
    }
    char what[300];
    snprintf(what, sizeof what, "wrote %.280s", path);
    lm_viewer_say(v, what);
}

static double srgb_to_linear(unsigned char c)
{
    double s = c / 255.0;
    return s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4);
}

/* The window as it is drawn (the panel too) to the next free lmgi-view-NNN.png in the working folder
 * (nothing is written over): its 8-bit pixels made linear and written with the clamp tone map at exposure
 * 1, which gives the same 8-bit values back. */
void lm_viewer_window_shot(lm_viewer *v, int fw, int fh)
{
    char name[64];
    free_name(name, sizeof name, "lmgi-view-%03d%s", ".png", &v->shots);
    unsigned char *px = malloc((size_t)fw * (size_t)fh * 3);
    float *lin = malloc((size_t)fw * (size_t)fh * 3 * sizeof *lin);
    if (!px || !lin) {
        fprintf(stderr, "lmgi: error: no memory for a screenshot of %dx%d\n", fw, fh);
        v->failed = 1;
    } else {
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadBuffer(GL_BACK);
        glReadPixels(0, 0, fw, fh, GL_RGB, GL_UNSIGNED_BYTE, px);
        for (int y = 0; y < fh; y++) /* GL's rows bottom first, the file's top first */
            for (size_t i = 0; i < 3 * (size_t)fw; i++)
                lin[3 * (size_t)fw * (size_t)y + i] = (float)srgb_to_linear(px[3 * (size_t)fw * (size_t)(fh - 1 - y) + i]);
        lmgi_image_desc d = {LMGI_TONEMAP_CLAMP, 1.0f, 0};
        lmgi_error err;
        if (lmgi_write_image(name, fw, fh, 3, lin, &d, &err) != LMGI_OK) {
            fprintf(stderr, "lmgi: error: %s\n", err.message);
            v->failed = 1;
        } else {
            char what[96];
            snprintf(what, sizeof what, "wrote %s (the window)", name);
            lm_viewer_say(v, what);
        }
    }
    free(px);
    free(lin);
}

/* W A S D fly along and across the view, Q E down and up; shift: four times as fast. */
void lm_viewer_fly(lm_viewer *v, float seconds)
{
    GLFWwindow *w = v->win;
    unsigned k = v->fly;
    float f = (float)((k >> 0) & 1) - (float)((k >> 2) & 1), r = (float)((k >> 3) & 1) - (float)((k >> 1) & 1);
    float u = (float)((k >> 5) & 1) - (float)((k >> 4) & 1);
    if (glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS)
        seconds *= 4.0f;
    if (f != 0.0f || r != 0.0f || u != 0.0f)
        lm_view_camera_fly(&v->cam, f, r, u, seconds);
}

/* A fly key's bit (W A S D Q E: 0 to 5), or 0. */
static unsigned fly_bit(int key)
{
    static const int keys[6] = {GLFW_KEY_W, GLFW_KEY_A, GLFW_KEY_S, GLFW_KEY_D, GLFW_KEY_Q, GLFW_KEY_E};
    for (int i = 0; i < 6; i++)
        if (keys[i] == key)
            return 1u << i;
    return 0;
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    lm_viewer *v = glfwGetWindowUserPointer(w);
    if (action == GLFW_RELEASE) {
        v->fly &= ~fly_bit(key);
        return;
    }
    if (v->drag == 3 && key >= GLFW_KEY_X && key <= GLFW_KEY_Z) { /* moving a node: lock to an axis, or free */
        int axis = key - GLFW_KEY_X;
        v->axis = v->axis == axis ? -1 : axis;
        return;
    }
    if (mods & GLFW_MOD_CONTROL) {
        if (key == GLFW_KEY_Z)
            undo_redo(v, (mods & GLFW_MOD_SHIFT) != 0);
        else if (key == GLFW_KEY_Y)
            undo_redo(v, 1);
        else if (key == GLFW_KEY_S)
            save_scene(v);
        return;
    }
    v->fly |= fly_bit(key);
    switch (key) {
    case GLFW_KEY_ESCAPE: glfwSetWindowShouldClose(w, 1); break;
    case GLFW_KEY_H: v->panel = !v->panel; break;
    case GLFW_KEY_R: v->cam = v->home; break;
    case GLFW_KEY_X: v->exposure = 0.0f; break;
    case GLFW_KEY_P:
    case GLFW_KEY_F12:
        if (mods & GLFW_MOD_SHIFT) { /* the lighting alone, the linear numbers */
            char name[64];
            free_name(name, sizeof name, "lmgi-view-%03d%s", ".exr", &v->shots);
            if (v->rgb)
                lm_viewer_write_frame(v, name);
        } else {
            v->want_shot = 1;
        }
        break;
    case GLFW_KEY_SPACE:
        v->paused = !v->paused;
        v->paused_at = v->time;
        v->start = glfwGetTime() - v->time;
        break;
    case GLFW_KEY_LEFT_BRACKET: v->budget = fmaxf(0.5f, 0.5f * v->budget); break;
    case GLFW_KEY_RIGHT_BRACKET: v->budget = fminf(1000.0f, 2.0f * v->budget); break;
    case GLFW_KEY_L: lm_viewer_select_light(v, v->light + 1); break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: edit_light(v, 1.0f / LIGHT_STEP); break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD: edit_light(v, LIGHT_STEP); break;
    case GLFW_KEY_O: edit_light(v, 0.0f); break;
    case GLFW_KEY_C: edit_light(v, -1.0f); break;
    case GLFW_KEY_N: add_light(v); break;
    case GLFW_KEY_DELETE: remove_light(v); break;
    case GLFW_KEY_PAGE_UP: raise_light(v, 1.0f); break;
    case GLFW_KEY_PAGE_DOWN: raise_light(v, -1.0f); break;
    case GLFW_KEY_B: edit_material(v, 0, 1.0f); break;
    case GLFW_KEY_G: edit_material(v, 1, mods & GLFW_MOD_SHIFT ? 1.0f / LIGHT_STEP : LIGHT_STEP); break;
    case GLFW_KEY_1:
    case GLFW_KEY_2:
    case GLFW_KEY_3:
    case GLFW_KEY_4: switch_effect(v, key - GLFW_KEY_1); break;
    case GLFW_KEY_V: next_map(v, mods & GLFW_MOD_SHIFT ? -1 : 1); break;
    default: break;
    }
}

/* What is under the cursor (hit.node -1: nothing), and the point hit. */
static lmgi_hit pick(lm_viewer *v, double x, double y, float at[3])
{
    float org[3], dir[3];
    cursor_ray(v, x, y, org, dir);
    lmgi_hit hit;
    lmgi_intersect(v->sc, org, dir, INFINITY, &hit);
    for (int k = 0; hit.hit && k < 3; k++)
        at[k] = org[k] + hit.t * dir[k];
    return hit;
}

/* The node hit selected, with the material of the triangle clicked. */
static void select_node(lm_viewer *v, const lmgi_hit *hit)
{
    v->node = hit->hit ? hit->node : -1;
    v->material = hit->hit ? hit->material : -1;
    char what[200];
    if (v->node < 0)
        snprintf(what, sizeof what, "nothing selected");
    else
        snprintf(what, sizeof what, "selected node %.80s, material %.80s", lmgi_node_name(v->sc, v->node),
                 v->material >= 0 ? lmgi_material_name(v->sc, v->material) : "-");
    lm_viewer_say(v, what);
}

/* Ctrl + press on a node: select it and start moving it on the horizontal plane through the point grabbed
 * (a static node is made dynamic first: lmgi_set_node_dynamic). */
static void grab_node(lm_viewer *v, double x, double y)
{
    float at[3];
    lmgi_hit hit = pick(v, x, y, at);
    select_node(v, &hit);
    int node = v->node;
    if (node < 0)
        return;
    lmgi_error err;
    if (!lmgi_node_is_dynamic(v->sc, node) && lmgi_set_node_dynamic(v->sc, node, 1, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        lm_viewer_say(v, "this node cannot move (the terminal says why)");
        return;
    }
    memcpy(v->grab, at, sizeof v->grab);
    lmgi_get_node_transform(v->sc, node, v->grab_start);
    v->drag = 3;
    v->axis = -1;
}

/* The node follows the cursor on the horizontal plane through the point grabbed, or, with an axis
 * locked (X Y Z during the drag), along that world axis through it. */
static void move_node(lm_viewer *v, double x, double y)
{
    float org[3], dir[3], p[3], m[16];
    cursor_ray(v, x, y, org, dir);
    memcpy(m, v->grab_start, sizeof m);
    if (v->axis >= 0) {
        float a[3] = {0.0f, 0.0f, 0.0f};
        a[v->axis] = 1.0f;
        m[12 + v->axis] += lm_view_ray_axis(org, dir, v->grab, a);
    } else {
        if (!lm_view_ray_plane(org, dir, v->grab[1], p))
            return;
        m[12] += p[0] - v->grab[0];
        m[14] += p[2] - v->grab[2];
    }
    lmgi_error err;
    if (lmgi_set_node_transform(v->sc, v->node, m, &err) != LMGI_OK)
        fprintf(stderr, "lmgi: error: %s\n", err.message);
    else
        lm_viewer_edited(v, 1);
}

static void end_move(lm_viewer *v)
{
    lm_view_step step = {.kind = LM_VIEW_NODE, .id = v->node};
    memcpy(step.before, v->grab_start, sizeof step.before);
    lmgi_get_node_transform(v->sc, v->node, step.after);
    if (memcmp(step.before, step.after, sizeof step.after) != 0) {
        lm_view_history_push(&v->history, &step);
        char what[128];
        snprintf(what, sizeof what, "moved node %.100s", lmgi_node_name(v->sc, v->node));
        lm_viewer_say(v, what);
        lm_viewer_placed(v, "drag released");
    }
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    lm_viewer *v = glfwGetWindowUserPointer(w);
    double x, y;
    glfwGetCursorPos(w, &x, &y);
    if (action == GLFW_RELEASE) {
        if (v->drag == 3)
            end_move(v);
        else if (v->drag == 4)
            end_light_move(v, "drag released");
        else if (v->drag == 1 && fabs(x - v->press[0]) + fabs(y - v->press[1]) < CLICK_PIXELS) {
            float at[3];
            lmgi_hit hit = pick(v, x, y, at);
            select_node(v, &hit);
        }
        v->drag = 0;
        return;
    }
    v->mouse[0] = v->press[0] = x, v->mouse[1] = v->press[1] = y;
    if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_CONTROL))
        grab_node(v, x, y);
    else if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_ALT))
        grab_light(v, x, y);
    else
        v->drag = button == GLFW_MOUSE_BUTTON_LEFT && !(mods & GLFW_MOD_SHIFT) ? 1 : 2;
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    lm_viewer *v = glfwGetWindowUserPointer(w);
    int ww, wh;
    glfwGetWindowSize(w, &ww, &wh);
    if (v->drag == 1)
        lm_view_camera_orbit(&v->cam, x - v->mouse[0], y - v->mouse[1], wh);
    else if (v->drag == 2)
        lm_view_camera_pan(&v->cam, x - v->mouse[0], y - v->mouse[1], wh);
    else if (v->drag == 3)
        move_node(v, x, y);
    else if (v->drag == 4)
        move_light(v, x, y);
    v->mouse[0] = x, v->mouse[1] = y;
}

/* The wheel zooms; with ctrl it turns the selected node about the vertical, 15 degrees a step. */
static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    (void)dx;
    lm_viewer *v = glfwGetWindowUserPointer(w);
    if (!(glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS)) {
        lm_view_camera_zoom(&v->cam, dy);
        return;
    }
    lmgi_error err;
    if (v->node < 0 ||
        (!lmgi_node_is_dynamic(v->sc, v->node) && lmgi_set_node_dynamic(v->sc, v->node, 1, &err) != LMGI_OK)) {
        lm_viewer_say(v, "select a node that may move first (click it)");
        return;
    }
    lm_view_step step = {.kind = LM_VIEW_NODE, .id = v->node};
    lmgi_get_node_transform(v->sc, v->node, step.before);
    lm_view_turn(step.before, (float)dy * TURN_STEP, step.after);
    if (keep_step(v, lmgi_set_node_transform(v->sc, v->node, step.after, &err), &step, &err, "turn")) {
        lm_viewer_say(v, "turned the selected node");
        lm_viewer_placed(v, "turn");
    }
}

void lm_viewer_input(lm_viewer *v)
{
    glfwSetWindowUserPointer(v->win, v);
    glfwSetKeyCallback(v->win, on_key);
    glfwSetMouseButtonCallback(v->win, on_button);
    glfwSetCursorPosCallback(v->win, on_cursor);
    glfwSetScrollCallback(v->win, on_scroll);
}
