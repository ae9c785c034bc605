/* lmgi view (view_cmd.h). */
#include "view_cmd.h"

#define GLFW_INCLUDE_NONE
#include <GL/gl.h>
#include <GLFW/glfw3.h>
#include <lmgi_tools.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "edit_script.h"
#include "run_cmd.h"
#include "scene_load.h"
#include "view_camera.h"
#include "view_edit.h"
#include "view_panel.h"
#include "view_watch.h"

#define FPS 30.0f            /* the animation's frames a second with --frames (as lmgi run) */
#define LIGHT_STEP 1.25f     /* + and - multiply or divide a light's intensity by this */
#define TURN_STEP 0.2617994f /* ctrl + wheel turns the selected node by 15 degrees a step */
#define CLICK_PIXELS 3.0     /* a press and release closer than this is a click (select), not a drag */
#define IDLE_UPDATES 8       /* updates in a row without work before the lighting counts as caught up: the
                              * photon work runs beside the picture, and an update may find none while it
                              * is still under way */

typedef struct {
    const lm_cli_args *a;
    const char *name;        /* the scene's file name, for the title and the panel */
    lmgi_scene *sc;
    lmgi_context *ctx;
    lmgi_updater *u;
    GLFWwindow *win;
    lm_view_camera cam, home;
    lm_edit_script script;
    int have_script, next_edit;
    float budget;
    int panel, paused, frame;
    float time, paused_at;
    double start, last;
    int light;               /* the selected light, -1: none */
    int node;                /* the selected node, -1: none */
    int drag;                /* 0, 1 orbit, 2 pan, 3 moving the selected node */
    double mouse[2], press[2];
    float grab[3], grab_start[16]; /* moving a node: the point grabbed and the node's matrix then */
    lm_view_history history;
    int saves;
    lm_view_watch watch;     /* --watch */
    int busy;                /* updates since work began (photons, AIMs, texels, caustics, faces, shadows) */
    int idle;                /* of them, the last ones in a row that did none */
    double busy_since;
    lmgi_updater_desc desc;  /* the updater's, for a reload */
    float exposure;          /* fixed from the first picture (X meters again) */
    float *rgb;              /* the picture, linear, top row first */
    unsigned char *rgba;     /* tone-mapped, bottom row first (glDrawPixels') */
    int width, height;
    lmgi_update_stats stats;
    double ms_render, fps;
    int shots, want_shot;    /* want_shot: P was pressed, the window is captured after its next drawing */
    char status[160];
    int failed;
} viewer;

/* What the last action did, on the panel and the terminal. */
static void say(viewer *v, const char *text)
{
    snprintf(v->status, sizeof v->status, "%.150s", text);
    if (!v->a->quiet)
        printf("%s\n", text);
}

/* ---------- input ---------- */

static void select_light(viewer *v, int from)
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

/* The selected light changed by f (intensity times f; f = 0: switched off or on again). */
static void edit_light(viewer *v, float f)
{
    lmgi_light l;
    lmgi_error err;
    if (v->light < 0 || lmgi_get_light(v->sc, v->light, &l, &err) != LMGI_OK) {
        say(v, "no light to edit (the scene has none)");
        return;
    }
    lm_view_step step = {.kind = LM_VIEW_LIGHT, .id = v->light, .light_before = l};
    if (f == 0.0f)
        l.enabled = !l.enabled;
    else if (f < 0.0f) { /* the next of a few colours: white, warm, cool */
        static const float colours[3][3] = {{1.0f, 1.0f, 1.0f}, {1.0f, 0.75f, 0.5f}, {0.6f, 0.75f, 1.0f}};
        int next = 0;
        for (int c = 0; c < 3; c++)
            if (!memcmp(l.color, colours[c], sizeof l.color))
                next = (c + 1) % 3;
        memcpy(l.color, colours[next], sizeof l.color);
    } else
        l.intensity *= f;
    step.light_after = l;
    if (lmgi_set_light(v->sc, v->light, &l, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        say(v, "the light edit was refused (the terminal says why)");
        return;
    }
    lm_view_history_push(&v->history, &step);
    char what[128];
    snprintf(what, sizeof what, "light %d %s, intensity %.4g, colour %.2f %.2f %.2f", v->light, l.enabled ? "on" : "off",
             (double)l.intensity, (double)l.color[0], (double)l.color[1], (double)l.color[2]);
    say(v, what);
}

/* N: a point light at the camera's target, raised by a tenth of the scene, as bright as the selected light
 * (or 10 cd); Delete: the selected light removed. */
static void add_light(viewer *v)
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
    if (lmgi_add_light(v->sc, &l, &step.id, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        say(v, "the light was refused (the terminal says why)");
        return;
    }
    lm_view_history_push(&v->history, &step);
    v->light = step.id;
    char what[96];
    snprintf(what, sizeof what, "light %d added at the target", step.id);
    say(v, what);
}

static void remove_light(viewer *v)
{
    lmgi_light l;
    lmgi_error err;
    if (v->light < 0 || lmgi_get_light(v->sc, v->light, &l, &err) != LMGI_OK) {
        say(v, "no light selected");
        return;
    }
    lm_view_step step = {.kind = LM_VIEW_LIGHT_REMOVED, .id = v->light, .light_before = l};
    if (lmgi_remove_light(v->sc, v->light, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        say(v, "the light could not be removed (the terminal says why)");
        return;
    }
    lm_view_history_push(&v->history, &step);
    char what[96];
    snprintf(what, sizeof what, "light %d removed", v->light);
    say(v, what);
    select_light(v, v->light + 1);
}

static void undo_redo(viewer *v, int redo)
{
    char what[160];
    lmgi_error err;
    err.message[0] = '\0';
    int ok = redo ? lm_view_redo(&v->history, v->sc, what, sizeof what, &err)
                  : lm_view_undo(&v->history, v->sc, what, sizeof what, &err);
    if (!ok && err.message[0])
        fprintf(stderr, "lmgi: error: %s\n", err.message);
    say(v, what);
    if (v->light >= 0 && lmgi_light_is_removed(v->sc, v->light))
        select_light(v, v->light + 1);
}

/* Ctrl+S: the scene as edited, with its lightmap, into the next free lmgi-view-scene-NNN folder
 * (lmgi_export_gltf: a glTF an engine or lmgi loads again). */
static void save_scene(viewer *v)
{
    char dir[64];
    do
        snprintf(dir, sizeof dir, "lmgi-view-scene-%03d", ++v->saves);
    while (access(dir, F_OK) == 0 && v->saves < 100000);
    lmgi_export_desc d = {.name = "scene"};
    lmgi_error err;
    if (lmgi_export_gltf(v->u, dir, &d, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        say(v, "the scene could not be saved (the terminal says why)");
        v->failed = 1;
        return;
    }
    char what[96];
    snprintf(what, sizeof what, "saved %s/scene.gltf", dir);
    say(v, what);
}

/* The lighting alone (the linear picture, no panel) to path: .png tone-mapped as shown, .exr the numbers. */
static void write_frame(viewer *v, const char *path)
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
    say(v, what);
}

static double srgb_to_linear(unsigned char c)
{
    double s = c / 255.0;
    return s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4);
}

/* The window as it is drawn (the panel too) to the next free lmgi-view-NNN.png in the working folder
 * (nothing is written over): its 8-bit pixels made linear and written with the clamp tone map at exposure
 * 1, which gives the same 8-bit values back. */
static void window_shot(viewer *v, int fw, int fh)
{
    char name[64];
    do
        snprintf(name, sizeof name, "lmgi-view-%03d.png", ++v->shots);
    while (access(name, F_OK) == 0 && v->shots < 100000);
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
            say(v, what);
        }
    }
    free(px);
    free(lin);
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    viewer *v = glfwGetWindowUserPointer(w);
    if (action == GLFW_RELEASE)
        return;
    if (mods & GLFW_MOD_CONTROL) {
        if (key == GLFW_KEY_Z)
            undo_redo(v, (mods & GLFW_MOD_SHIFT) != 0);
        else if (key == GLFW_KEY_Y)
            undo_redo(v, 1);
        else if (key == GLFW_KEY_S)
            save_scene(v);
        return;
    }
    switch (key) {
    case GLFW_KEY_ESCAPE: glfwSetWindowShouldClose(w, 1); break;
    case GLFW_KEY_H: v->panel = !v->panel; break;
    case GLFW_KEY_R: v->cam = v->home; break;
    case GLFW_KEY_X: v->exposure = 0.0f; break;
    case GLFW_KEY_P:
    case GLFW_KEY_F12:
        if (mods & GLFW_MOD_SHIFT) { /* the lighting alone, the linear numbers */
            char name[64];
            do
                snprintf(name, sizeof name, "lmgi-view-%03d.exr", ++v->shots);
            while (access(name, F_OK) == 0 && v->shots < 100000);
            if (v->rgb)
                write_frame(v, name);
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
    case GLFW_KEY_L: select_light(v, v->light + 1); break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: edit_light(v, 1.0f / LIGHT_STEP); break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD: edit_light(v, LIGHT_STEP); break;
    case GLFW_KEY_O: edit_light(v, 0.0f); break;
    case GLFW_KEY_C: edit_light(v, -1.0f); break;
    case GLFW_KEY_N: add_light(v); break;
    case GLFW_KEY_DELETE: remove_light(v); break;
    default: break;
    }
}

/* The window's camera (window pixels, not the framebuffer's: the cursor's) and the ray under the cursor. */
static void cursor_ray(viewer *v, double x, double y, float org[3], float dir[3])
{
    int ww, wh;
    glfwGetWindowSize(v->win, &ww, &wh);
    lmgi_camera cam;
    lm_view_camera_get(&v->cam, ww, wh, &cam);
    lm_view_ray(&cam, x, y, ww, wh, org, dir);
}

/* The node under the cursor (-1: none), and the point hit. */
static int pick(viewer *v, double x, double y, float at[3])
{
    float org[3], dir[3];
    cursor_ray(v, x, y, org, dir);
    lmgi_hit hit;
    lmgi_intersect(v->sc, org, dir, INFINITY, &hit);
    if (!hit.hit)
        return -1;
    for (int k = 0; k < 3; k++)
        at[k] = org[k] + hit.t * dir[k];
    return hit.node;
}

static void select_node(viewer *v, int node)
{
    v->node = node;
    char what[128];
    snprintf(what, sizeof what, node < 0 ? "nothing selected" : "selected node %.100s", node < 0 ? "" : lmgi_node_name(v->sc, node));
    say(v, what);
}

/* Ctrl + press on a node: select it and start moving it on the horizontal plane through the point grabbed
 * (a static node is made dynamic first: lmgi_set_node_dynamic). */
static void grab_node(viewer *v, double x, double y)
{
    float at[3];
    int node = pick(v, x, y, at);
    select_node(v, node);
    if (node < 0)
        return;
    lmgi_error err;
    if (!lmgi_node_is_dynamic(v->sc, node) && lmgi_set_node_dynamic(v->sc, node, 1, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        say(v, "this node cannot move (the terminal says why)");
        return;
    }
    memcpy(v->grab, at, sizeof v->grab);
    lmgi_get_node_transform(v->sc, node, v->grab_start);
    v->drag = 3;
}

static void move_node(viewer *v, double x, double y)
{
    float org[3], dir[3], p[3], m[16];
    cursor_ray(v, x, y, org, dir);
    if (!lm_view_ray_plane(org, dir, v->grab[1], p))
        return;
    memcpy(m, v->grab_start, sizeof m);
    m[12] += p[0] - v->grab[0];
    m[14] += p[2] - v->grab[2];
    lmgi_error err;
    if (lmgi_set_node_transform(v->sc, v->node, m, &err) != LMGI_OK)
        fprintf(stderr, "lmgi: error: %s\n", err.message);
}

static void end_move(viewer *v)
{
    lm_view_step step = {.kind = LM_VIEW_NODE, .id = v->node};
    memcpy(step.before, v->grab_start, sizeof step.before);
    lmgi_get_node_transform(v->sc, v->node, step.after);
    if (memcmp(step.before, step.after, sizeof step.after) != 0) {
        lm_view_history_push(&v->history, &step);
        char what[128];
        snprintf(what, sizeof what, "moved node %.100s", lmgi_node_name(v->sc, v->node));
        say(v, what);
    }
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    viewer *v = glfwGetWindowUserPointer(w);
    double x, y;
    glfwGetCursorPos(w, &x, &y);
    if (action == GLFW_RELEASE) {
        if (v->drag == 3)
            end_move(v);
        else if (v->drag == 1 && fabs(x - v->press[0]) + fabs(y - v->press[1]) < CLICK_PIXELS) {
            float at[3];
            select_node(v, pick(v, x, y, at));
        }
        v->drag = 0;
        return;
    }
    v->mouse[0] = v->press[0] = x, v->mouse[1] = v->press[1] = y;
    if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_CONTROL))
        grab_node(v, x, y);
    else
        v->drag = button == GLFW_MOUSE_BUTTON_LEFT && !(mods & GLFW_MOD_SHIFT) ? 1 : 2;
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    viewer *v = glfwGetWindowUserPointer(w);
    int ww, wh;
    glfwGetWindowSize(w, &ww, &wh);
    if (v->drag == 1)
        lm_view_camera_orbit(&v->cam, x - v->mouse[0], y - v->mouse[1], wh);
    else if (v->drag == 2)
        lm_view_camera_pan(&v->cam, x - v->mouse[0], y - v->mouse[1], wh);
    else if (v->drag == 3)
        move_node(v, x, y);
    v->mouse[0] = x, v->mouse[1] = y;
}

/* The wheel zooms; with ctrl it turns the selected node about the vertical, 15 degrees a step. */
static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    (void)dx;
    viewer *v = glfwGetWindowUserPointer(w);
    if (!(glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS)) {
        lm_view_camera_zoom(&v->cam, dy);
        return;
    }
    lmgi_error err;
    if (v->node < 0 ||
        (!lmgi_node_is_dynamic(v->sc, v->node) && lmgi_set_node_dynamic(v->sc, v->node, 1, &err) != LMGI_OK)) {
        say(v, "select a node that may move first (click it)");
        return;
    }
    lm_view_step step = {.kind = LM_VIEW_NODE, .id = v->node};
    lmgi_get_node_transform(v->sc, v->node, step.before);
    lm_view_turn(step.before, (float)dy * TURN_STEP, step.after);
    if (lmgi_set_node_transform(v->sc, v->node, step.after, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return;
    }
    lm_view_history_push(&v->history, &step);
    say(v, "turned the selected node");
}

/* W A S D fly along and across the view, Q E down and up; shift: four times as fast. */
static void fly(viewer *v, float seconds)
{
    GLFWwindow *w = v->win;
    if (glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS)
        return; /* ctrl + S saves, it does not fly */
    float f = (float)(glfwGetKey(w, GLFW_KEY_W) == GLFW_PRESS) - (float)(glfwGetKey(w, GLFW_KEY_S) == GLFW_PRESS);
    float r = (float)(glfwGetKey(w, GLFW_KEY_D) == GLFW_PRESS) - (float)(glfwGetKey(w, GLFW_KEY_A) == GLFW_PRESS);
    float u = (float)(glfwGetKey(w, GLFW_KEY_E) == GLFW_PRESS) - (float)(glfwGetKey(w, GLFW_KEY_Q) == GLFW_PRESS);
    if (glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS)
        seconds *= 4.0f;
    if (f != 0.0f || r != 0.0f || u != 0.0f)
        lm_view_camera_fly(&v->cam, f, r, u, seconds);
}

/* ---------- a frame ---------- */

static int picture_size(viewer *v, int w, int h)
{
    if (w == v->width && h == v->height && v->rgb)
        return 1;
    free(v->rgb);
    free(v->rgba);
    v->width = w, v->height = h;
    v->rgb = malloc((size_t)w * (size_t)h * 3 * sizeof *v->rgb);
    v->rgba = malloc((size_t)w * (size_t)h * 4);
    if (!v->rgb || !v->rgba) {
        fprintf(stderr, "lmgi: error: no memory for a %dx%d picture\n", w, h);
        return 0;
    }
    return 1;
}

static void effects_line(viewer *v, lm_view_panel *p)
{
    char line[LM_VIEW_PANEL_COLUMNS] = "effects:";
    for (int i = 0; i < lmgi_effect_count(v->sc); i++) {
        lmgi_effect e;
        lmgi_get_effect(v->sc, i, &e);
        size_t n = strlen(line);
        snprintf(line + n, sizeof line - n, " %s %s,", e.name, e.on ? "on" : "off");
    }
    line[strlen(line) - 1] = '\0';
    lm_view_panel_add(p, "%s", line);
}

static void draw_panel(viewer *v, int fw, int fh)
{
    const lmgi_update_stats *s = &v->stats;
    lm_view_panel p = {0};
    lm_view_panel_add(&p, "lmgi view  %s  %dx%d  %.1f fps  t %.2f s%s", v->name, fw, fh, v->fps, (double)v->time,
                      v->paused ? " (paused)" : "");
    lm_view_panel_add(&p, "update %.1f ms of a %.3g ms budget (photons %.1f, gather %.1f)  picture %.1f ms",
                      s->ms_total, (double)v->budget, s->ms_photons, s->ms_gather, v->ms_render);
    lm_view_panel_add(&p, "busiest: %s: %s", s->busiest_stage ? s->busiest_stage : "-", s->why);
    if (v->busy)
        lm_view_panel_add(&p, "lighting: catching up for %d updates (%.1f s)", v->busy, glfwGetTime() - v->busy_since);
    else
        lm_view_panel_add(&p, "lighting: caught up (nothing waits)");
    lm_view_panel_add(&p, "texels %u (allowed %d)  photons %u  AIM surfaces %d  surfaces changed %d",
                      s->texels_gathered, s->texels_budget, s->photons_retraced, s->aim_surfaces_refreshed,
                      s->surfaces_changed);
    effects_line(v, &p);
    lmgi_light l;
    lmgi_error err;
    if (v->light >= 0 && lmgi_get_light(v->sc, v->light, &l, &err) == LMGI_OK)
        lm_view_panel_add(&p, "light %d of %d: %s, intensity %.4g, colour %.2f %.2f %.2f", v->light,
                          lmgi_light_count(v->sc), l.enabled ? "on" : "off", (double)l.intensity,
                          (double)l.color[0], (double)l.color[1], (double)l.color[2]);
    if (v->node >= 0)
        lm_view_panel_add(&p, "selected node %s (%s): ctrl+drag moves it, ctrl+wheel turns it", lmgi_node_name(v->sc, v->node),
                          lmgi_node_is_dynamic(v->sc, v->node) ? "dynamic" : "static");
    if (v->status[0])
        lm_view_panel_add(&p, "%s", v->status);
    lm_view_panel_add(&p, "drag: orbit (shift, right: pan)  wheel: zoom  WASDQE: fly  click: select  L + - O C N Del: "
                          "lights  ctrl+Z/Y: undo/redo");
    lm_view_panel_add(&p, "ctrl+S: save scene  [ ]: budget  space: pause  P: screenshot  H: panel  Esc: quit");
    lm_view_panel_draw(&p, fw, fh, fw >= 1000 ? 2.0f : 1.0f);
}

/* Tone-mapped into rgba bottom row first, as glDrawPixels reads it. */
static void tone_map(viewer *v)
{
    lmgi_tonemap op = (lmgi_tonemap)v->a->tonemap;
    size_t row = (size_t)v->width;
    if (!(v->exposure > 0.0f))
        v->exposure = lmgi_auto_exposure(op, v->rgb, row * (size_t)v->height);
    for (int y = 0; y < v->height; y++)
        lmgi_tonemap_rgba8(op, v->exposure, v->rgb + 3 * row * (size_t)y, row,
                           v->rgba + 4 * row * (size_t)(v->height - 1 - y));
}

/* Whether the lighting still has work waiting: an update that found photon paths changed, refreshed AIMs,
 * regathered texels, traced caustic photons or redrew reflection faces or shadow maps (the one photon group
 * a still scene re-traces each update to look for changes is not work waiting). From the first such
 * update the lighting is "catching up"; after IDLE_UPDATES without any, "caught up", with how long that
 * took (the panel, and a line on the terminal a script can wait for). */
static void track_work(viewer *v, double now)
{
    const lmgi_update_stats *s = &v->stats;
    int working = s->groups_invalidated || s->aim_surfaces_refreshed || s->texels_gathered ||
                  s->caustic_photons_retraced || s->cube_faces_rendered || s->shadow_maps_rendered ||
                  s->shadow_maps_stale;
    if (working) {
        v->idle = 0;
        if (!v->busy++) {
            v->busy_since = now;
            if (!v->a->quiet)
                printf("lighting: catching up\n");
        }
    } else if (v->busy && ++v->idle >= IDLE_UPDATES) {
        char line[96];
        snprintf(line, sizeof line, "lighting: caught up after %d updates (%.2f s)", v->busy, now - v->busy_since);
        v->busy = v->idle = 0;
        say(v, line);
    }
    fflush(stdout);
}

/* --watch: the file changed and settled; its differences made as edits, or the scene reloaded when they
 * cannot be (a mesh changed, a node, material or light more or less). A file that does not load leaves
 * the scene shown as it was. 0 only when the reloaded scene's updater cannot be made. */
static int follow_file(viewer *v)
{
    lmgi_scene *next = NULL;
    if (!lm_cli_run_load(v->a, &next)) {
        say(v, "the saved file did not load (the terminal says why); still showing the last one");
        return 1;
    }
    char what[160];
    lmgi_error err;
    int r = lm_view_watch_apply(v->sc, next, what, sizeof what, &err);
    if (r >= 0 || r == -2) {
        if (r == -2)
            fprintf(stderr, "lmgi: error: %s\n", err.message);
        lmgi_free(next);
        char line[200];
        snprintf(line, sizeof line, r == -2 ? "the file's edit was refused (the terminal says why)" : "file saved: %s",
                 what);
        say(v, line);
        return 1;
    }
    lmgi_updater_free(v->u);
    v->u = NULL;
    lmgi_free(v->sc);
    v->sc = next;
    lm_view_history_free(&v->history); /* its steps were the old scene's */
    v->node = -1;
    if (lmgi_updater_create(v->ctx, v->sc, &v->desc, &v->u, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return 0;
    }
    select_light(v, 0);
    say(v, "the file's geometry changed: the scene was loaded again");
    return 1;
}

static int frame(viewer *v)
{
    lmgi_error err;
    double now = glfwGetTime();
    fly(v, (float)(now - v->last));
    v->fps = now > v->last ? 0.9 * v->fps + 0.1 / (now - v->last) : v->fps;
    v->last = now;
    if (v->a->still)
        v->time = 0.0f;
    else if (v->a->frames)
        v->time = (float)v->frame / FPS;
    else if (!v->paused)
        v->time = (float)(now - v->start);
    if (v->a->watch && lm_view_watch_due(&v->watch, now) && !follow_file(v))
        return 0;
    while (v->have_script && v->next_edit < v->script.edit_count && v->script.edits[v->next_edit].frame <= v->frame)
        if (!lm_edit_script_apply(&v->script, v->next_edit++, v->sc))
            return 0;
    if (lmgi_update(v->u, v->time, v->budget, &v->stats, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return 0;
    }
    track_work(v, now);
    int fw, fh;
    glfwGetFramebufferSize(v->win, &fw, &fh);
    if (fw <= 0 || fh <= 0) /* minimised */
        return 1;
    if (!picture_size(v, fw, fh))
        return 0;
    lmgi_camera cam;
    lm_view_camera_get(&v->cam, fw, fh, &cam);
    double t0 = glfwGetTime();
    if (lmgi_render(v->u, &cam, fw, fh, v->rgb, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return 0;
    }
    v->ms_render = 1e3 * (glfwGetTime() - t0);
    tone_map(v);
    glViewport(0, 0, fw, fh);
    glClear(GL_COLOR_BUFFER_BIT);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glRasterPos2f(-1.0f, -1.0f);
    glDrawPixels(fw, fh, GL_RGBA, GL_UNSIGNED_BYTE, v->rgba);
    if (v->panel)
        draw_panel(v, fw, fh);
    if (v->want_shot) {
        v->want_shot = 0;
        window_shot(v, fw, fh);
    }
    glfwSwapBuffers(v->win);
    v->frame++;
    return 1;
}

/* ---------- set-up ---------- */

static void glfw_error(int code, const char *message)
{
    fprintf(stderr, "lmgi: view: the window system says (%d): %s\n", code, message);
}

/* What the window needs before anything is loaded: a display, a screenshot path that is free or forced,
 * a script that reads. */
static int preflight(viewer *v)
{
    const lm_cli_args *a = v->a;
    if (!getenv("DISPLAY") && !getenv("WAYLAND_DISPLAY")) {
        fprintf(stderr, "lmgi: error: view needs a display to open its window on, and there is none (DISPLAY and "
                        "WAYLAND_DISPLAY are unset); `lmgi run SCENE --out DIR` writes the frames as pictures "
                        "without one, and `xvfb-run lmgi view ...` gives it a virtual one\n");
        return 0;
    }
    if (a->screenshot_path && access(a->screenshot_path, F_OK) == 0 && !a->force) {
        fprintf(stderr, "lmgi: error: %s exists; view writes its screenshot only over a file it is told it may "
                        "(--force)\n", a->screenshot_path);
        return 0;
    }
    if (a->script_path) {
        if (!lm_edit_script_read(a->script_path, &v->script))
            return 0;
        v->have_script = 1;
    }
    return 1;
}

static int open_window(viewer *v)
{
    glfwSetErrorCallback(glfw_error);
    if (!glfwInit()) {
        fprintf(stderr, "lmgi: error: view cannot open a window: the window system did not start (above)\n");
        return 0;
    }
    char title[300];
    snprintf(title, sizeof title, "lmgi view - %s", v->name);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
    v->win = glfwCreateWindow(v->a->width ? v->a->width : LM_VIEW_WIDTH, v->a->height ? v->a->height : LM_VIEW_HEIGHT,
                              title, NULL, NULL);
    if (!v->win) {
        fprintf(stderr, "lmgi: error: view cannot open a window with an OpenGL 2.1 context (above)\n");
        return 0;
    }
    glfwSetWindowUserPointer(v->win, v);
    glfwSetKeyCallback(v->win, on_key);
    glfwSetMouseButtonCallback(v->win, on_button);
    glfwSetCursorPosCallback(v->win, on_cursor);
    glfwSetScrollCallback(v->win, on_scroll);
    glfwMakeContextCurrent(v->win);
    glfwSwapInterval(0); /* the budget, not the display's refresh, paces the updates */
    return 1;
}

static int start(viewer *v)
{
    const lm_cli_args *a = v->a;
    lmgi_error err;
    if (!lm_cli_run_load(a, &v->sc))
        return 0;
    lm_cli_updater_desc(a, &v->desc);
    v->desc.frame.width = v->desc.frame.height = 0; /* the window draws with lmgi_render from its own camera */
    if (lmgi_context_create(NULL, &v->ctx, &err) != LMGI_OK ||
        lmgi_updater_create(v->ctx, v->sc, &v->desc, &v->u, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return 0;
    }
    if (!open_window(v))
        return 0;
    int fw, fh;
    glfwGetFramebufferSize(v->win, &fw, &fh);
    lmgi_camera cam;
    lmgi_info in;
    lmgi_get_info(v->sc, &in);
    if (lmgi_scene_camera(v->sc, a->camera ? a->camera : -1, fw, fh, &cam, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return 0;
    }
    lm_view_camera_from(&v->home, &cam, in.bounds_min, in.bounds_max);
    v->cam = v->home;
    v->budget = a->budget_ms > 0.0f ? a->budget_ms : LM_VIEW_BUDGET_MS;
    v->panel = 1;
    select_light(v, 0);
    if (a->watch)
        lm_view_watch_init(&v->watch, a->files[0]);
    v->start = v->last = glfwGetTime();
    return 1;
}

int lm_cli_view(const lm_cli_args *a)
{
    if (a->file_count != 1) {
        fprintf(stderr, "lmgi: usage: lmgi view SCENE [--size WxH] [--budget MS] [--script EDITS.json] [--frames N] "
                        "[--screenshot FILE] [run options]\n");
        return 2;
    }
    viewer v;
    memset(&v, 0, sizeof v);
    v.a = a;
    v.name = strrchr(a->files[0], '/') ? strrchr(a->files[0], '/') + 1 : a->files[0];
    v.light = -1;
    v.node = -1;
    int ok = preflight(&v) && start(&v);
    while (ok) { /* a frame after every poll: an edit and Esc in one poll still show the edit (and its screenshot) */
        glfwPollEvents();
        ok = frame(&v);
        if (glfwWindowShouldClose(v.win) || (a->frames && v.frame >= a->frames))
            break;
    }
    if (ok && a->screenshot_path && v.rgb)
        write_frame(&v, a->screenshot_path);
    if (ok && !a->quiet)
        printf("view        %d frames of %s\n", v.frame, v.name);
    if (v.win)
        glfwDestroyWindow(v.win);
    glfwTerminate();
    lmgi_updater_free(v.u);
    lmgi_context_free(v.ctx);
    lmgi_free(v.sc);
    if (v.have_script)
        lm_edit_script_free(&v.script);
    lm_view_history_free(&v.history);
    free(v.rgb);
    free(v.rgba);
    return ok && !v.failed ? 0 : 1;
}
