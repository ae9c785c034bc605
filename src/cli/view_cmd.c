/* lmgi view (view_cmd.h): the window, its frames and the panel; the input is view_input.c's. */
#include "view_cmd.h"

#include <GL/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "run_cmd.h"
#include "scene_load.h"
#include "view_panel.h"
#include "view_state.h"

#define FPS 30.0f            /* the animation's frames a second with --frames (as lmgi run) */
#define IDLE_UPDATES 8       /* updates in a row without work before the lighting counts as caught up: the
                              * photon work runs beside the picture, and an update may find none while it
                              * is still under way */

/* What the last action did, on the panel and the terminal. */
void lm_viewer_say(lm_viewer *v, const char *text)
{
    snprintf(v->status, sizeof v->status, "%.150s", text);
    if (!v->a->quiet) {
        printf("%s\n", text);
        fflush(stdout); /* a script or a log reads it now, not when a buffer fills */
    }
}

/* ---------- a frame ---------- */

static int picture_size(lm_viewer *v, int w, int h)
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

static void effects_line(lm_viewer *v, lm_view_panel *p)
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

static void draw_panel(lm_viewer *v, int fw, int fh)
{
    const lmgi_update_stats *s = &v->stats;
    lm_view_panel p = {0};
    lm_view_panel_add(&p, "lmgi view  %s  %dx%d  %.1f fps  t %.2f s%s", v->name, fw, fh, v->fps, (double)v->time,
                      v->paused ? " (paused)" : "");
    lm_view_panel_add(&p, "update %.1f ms of a %.3g ms budget (photons %.1f, gather %.1f)  picture %.1f ms",
                      s->ms_total, (double)v->budget, s->ms_photons, s->ms_gather, v->ms_render);
    lm_view_panel_add(&p, "busiest: %s: %s", s->busiest_stage ? s->busiest_stage : "-", s->why);
    if (v->busy) {
        lm_view_panel_add(&p, "lighting: catching up for %d updates (%.1f s)", v->busy - 1, glfwGetTime() - v->busy_since);
        if (v->need_round)
            lm_view_panel_add(&p, "  photons checked since the last move: %d%% of a round of %d updates",
                              v->round > 0 ? (int)fminf(100.0f, 100.0f * (float)v->idle / (float)v->round) : 100,
                              v->round);
        lm_view_panel_add(&p, "  texels still to move: %u, the largest by %.1f%%", v->stale_texels, 100.0 * v->stale_max);
    } else {
        lm_view_panel_add(&p, "lighting: caught up (no work waiting, no texel to move, every photon checked since "
                              "the last move)");
    }
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
    if (v->node >= 0) {
        lmgi_node_effects fx = {0, 0, 0, 0};
        lmgi_get_node_effects(v->sc, v->node, &fx, &err);
        lm_view_panel_add(&p, "selected node %s (%s), material %s; effects 1 shadows %s, 2 indirect %s, 3 reflections "
                          "%s, 4 caustics %s", lmgi_node_name(v->sc, v->node),
                          lmgi_node_is_dynamic(v->sc, v->node) ? "dynamic" : "static",
                          v->material >= 0 ? lmgi_material_name(v->sc, v->material) : "-", fx.shadows ? "on" : "off",
                          fx.indirect ? "on" : "off", fx.reflections ? "on" : "off", fx.caustics ? "on" : "off");
    }
    if (v->drag == 3)
        lm_view_panel_add(&p, "moving %s %s (X Y Z: along that axis, again: free)", lmgi_node_name(v->sc, v->node),
                          v->axis < 0 ? "on the horizontal plane" : v->axis == 0 ? "along x" : v->axis == 1 ? "along y" : "along z");
    lm_view_panel_add(&p, "view: %s (V: next)", lm_view_map_name(v->map));
    if (v->status[0])
        lm_view_panel_add(&p, "%s", v->status);
    lm_view_panel_add(&p, "drag: orbit (shift, right: pan)  wheel: zoom  WASDQE: fly  click: select  ctrl+drag: move "
                          "(X Y Z: axis)  ctrl+wheel: turn");
    lm_view_panel_add(&p, "lights: L select  + - dim  O off  C colour  N add  Del remove  alt+drag, PgUp PgDn move");
    lm_view_panel_add(&p, "B base colour  G shift+G emission  1-4 effects  ctrl+Z/Y undo/redo  ctrl+S save  [ ] budget");
    lm_view_panel_add(&p, "space: pause  P: screenshot  shift+P: EXR  X: exposure  H: panel  Esc: quit");
    lm_view_panel_draw(&p, fw, fh, fw >= 1000 ? 2.0f : 1.0f);
}

/* Tone-mapped into rgba bottom row first, as glDrawPixels reads it. */
static void tone_map(lm_viewer *v)
{
    lmgi_tonemap op = (lmgi_tonemap)v->a->tonemap;
    size_t row = (size_t)v->width;
    int false_colours = v->map == LM_VIEW_ERROR || v->map == LM_VIEW_ATLAS;
    if (!(v->exposure > 0.0f) && !false_colours)
        v->exposure = lmgi_auto_exposure(op, v->rgb, row * (size_t)v->height);
    for (int y = 0; y < v->height; y++)
        lmgi_tonemap_rgba8(false_colours ? LMGI_TONEMAP_CLAMP : op, false_colours ? 1.0f : v->exposure,
                           v->rgb + 3 * row * (size_t)y, row, v->rgba + 4 * row * (size_t)(v->height - 1 - y));
}

/* The error atlas (LMGI_LIGHTMAP_ERROR: the updater's own estimate of how far the displayed lightmap
 * still is from the lighting as it is now) summed up: the texels still to move and by how much at most. */
static void read_staleness(lm_viewer *v, double now)
{
    lmgi_error err;
    v->stale_at = now;
    lm_view_maps_staleness(&v->maps, v->u, v->sc, &v->stale_texels, &v->stale_max, &err); /* failed: none */
}

static void begin_catching_up(lm_viewer *v, double now)
{
    v->idle = 0;
    if (v->busy)
        return;
    v->busy = 1;
    v->busy_since = now;
    if (!v->a->quiet)
        printf("lighting: catching up\n");
}

void lm_viewer_edited(lm_viewer *v, int moved)
{
    v->need_round |= moved;
    begin_catching_up(v, glfwGetTime());
    lm_view_maps_edited(&v->maps);
}

/* Updates a placement may take to be caught up without the budget: a drag's last motion and its release
 * can come in one poll, so that the first update still has an edit; a third to spare. */
#define CATCH_UP_UPDATES 3

void lm_viewer_placed(lm_viewer *v, const char *what)
{
    v->catch_up = CATCH_UP_UPDATES;
    snprintf(v->catch_up_what, sizeof v->catch_up_what, "%s", what);
}

/* After a placement (lm_viewer_placed): the update that caught it up says so, with its time. */
static void caught_up(lm_viewer *v)
{
    v->catch_up = v->stats.placements_caught_up ? 0 : v->catch_up - 1;
    if (!v->stats.placements_caught_up)
        return;
    char line[200];
    snprintf(line, sizeof line,
             "%s: its light followed at once, in one update of %.0f ms (%u photon groups, %d AIMs, %u texels)",
             v->catch_up_what, v->stats.ms_total, v->stats.groups_at_once, v->stats.aim_surfaces_at_once, v->stats.texels_gathered);
    lm_viewer_say(v, line);
}

/* Whether the lighting still has work waiting. An update that re-traced photon groups, refreshed AIMs,
 * regathered texels, traced caustic photons or redrew reflection faces or shadow maps did work; so did an
 * edit. A light, material or effect edit names the photons it changes (their groups are queued: explicit
 * invalidation), so once no update does work and the error atlas has no texel left to move, the lighting
 * has caught up. A moved node does not: the round robin finds the paths it changed only as it re-traces
 * them, one photon a group an update (the paper's selective re-emission), so after a move, or a change the
 * round robin found, updates without work prove nothing until a whole round has passed. Then the panel
 * says so and the terminal prints "caught up", with how long it took, a line scripts wait for. */
static void track_work(lm_viewer *v, double now)
{
    const lmgi_update_stats *s = &v->stats;
    int working = s->groups_invalidated || s->groups_retraced || s->aim_surfaces_refreshed || s->texels_gathered ||
                  s->caustic_photons_retraced || s->cube_faces_rendered || s->shadow_maps_rendered ||
                  s->shadow_maps_stale;
    v->need_round |= s->groups_invalidated > 0;
    if (working)
        begin_catching_up(v, now);
    else if (v->busy)
        v->idle++;
    if (!v->busy)
        return;
    v->busy++;
    int due = v->idle >= IDLE_UPDATES && (!v->need_round || v->idle > v->round);
    if (due || now - v->stale_at > 0.25)
        read_staleness(v, now);
    if (working || v->stale_texels || v->busy == 2) /* the lightmap still moving (or just edited) */
        v->moved = v->busy - 1, v->moved_at = now;
    if (due && v->stale_texels == 0) {
        char line[160];
        snprintf(line, sizeof line, "lighting: caught up after %d updates (%.2f s); the lightmap last moved at update %d "
                 "(%.2f s)", v->busy - 1, now - v->busy_since, v->moved, v->moved_at - v->busy_since);
        v->busy = v->idle = v->need_round = 0;
        lm_viewer_say(v, line);
    }
    fflush(stdout);
}

/* The updates of a round of the round robin (view_state.h's round). */
static void learn_round(lm_viewer *v)
{
    lmgi_updater_info in;
    lmgi_get_updater_info(v->u, &in);
    uint32_t k = in.photons.retrace_per_group ? in.photons.retrace_per_group : 1;
    v->round = (int)((in.photons.per_group + k - 1) / k);
}

/* --watch: the file changed and settled; its differences made as edits, or the scene reloaded when they
 * cannot be (a mesh changed, a node, material or light more or less). A file that does not load leaves
 * the scene shown as it was. 0 only when the reloaded scene's updater cannot be made. */
static int follow_file(lm_viewer *v)
{
    lmgi_scene *next = NULL;
    if (!lm_cli_run_load(v->a, &next)) {
        lm_viewer_say(v, "the saved file did not load (the terminal says why); still showing the last one");
        return 1;
    }
    char what[160];
    lmgi_error err;
    int r = lm_view_watch_apply(&v->watch, v->sc, next, what, sizeof what, &err);
    if (r >= 0 || r == -2) {
        if (r == -2)
            fprintf(stderr, "lmgi: error: %s\n", err.message);
        lmgi_free(next);
        char line[200];
        snprintf(line, sizeof line, r == -2 ? "the file's edit was refused (the terminal says why)" : "file saved: %s",
                 what);
        if (r > 0) {
            lm_viewer_edited(v, 1);
            lm_viewer_placed(v, "file saved");
        }
        if (v->light < 0 || lmgi_light_is_removed(v->sc, v->light)) /* a lamp removed, or the first added */
            lm_viewer_select_light(v, v->light < 0 ? 0 : v->light + 1);
        lm_viewer_say(v, line);
        return 1;
    }
    lmgi_updater_free(v->u);
    v->u = NULL;
    lmgi_free(v->sc);
    v->sc = next;
    lm_view_history_free(&v->history); /* its steps were the old scene's */
    lm_view_watch_reset(&v->watch);      /* so were the lights it added */
    v->node = v->material = -1;
    if (lmgi_updater_create(v->ctx, v->sc, &v->desc, &v->u, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return 0;
    }
    lm_viewer_select_light(v, 0);
    learn_round(v);
    lm_viewer_edited(v, 0); /* a new updater: its first solution is whole */
    lm_viewer_say(v, "the file's geometry changed: the scene was loaded again");
    return 1;
}

static int frame(lm_viewer *v)
{
    lmgi_error err;
    double now = glfwGetTime();
    lm_viewer_fly(v, (float)(now - v->last));
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
    while (v->have_script && v->next_edit < v->script.edit_count && v->script.edits[v->next_edit].frame <= v->frame) {
        const lm_edit *e = &v->script.edits[v->next_edit];
        if (!lm_edit_script_apply(&v->script, v->next_edit++, v->sc))
            return 0;
        lm_viewer_edited(v, cJSON_GetObjectItemCaseSensitive(e->v, "node") != NULL); /* a node edit moves it */
    }
    /* a placement: its lighting caught up in one update, outside the budget (docs/viewer.md) */
    if (lmgi_update(v->u, v->time, v->catch_up > 0 ? 0.0f : v->budget, &v->stats, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return 0;
    }
    if (v->catch_up > 0)
        caught_up(v);
    track_work(v, glfwGetTime()); /* after the update (and a reload's first solution), not the frame's start */
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
    if (v->map != LM_VIEW_PICTURE && !lm_view_maps_draw(&v->maps, v->u, v->sc, v->map, &cam, fw, fh, v->rgb, &err)) {
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
        lm_viewer_window_shot(v, fw, fh);
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
static int preflight(lm_viewer *v)
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

static int open_window(lm_viewer *v)
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
    lm_viewer_input(v);
    glfwMakeContextCurrent(v->win);
    glfwSwapInterval(0); /* the budget, not the display's refresh, paces the updates */
    return 1;
}

static int start(lm_viewer *v)
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
    lm_viewer_select_light(v, 0);
    learn_round(v);
    if (a->watch)
        lm_view_watch_init(&v->watch, a->files[0]);
    v->start = v->last = v->opened = glfwGetTime();
    return 1;
}

int lm_cli_view(const lm_cli_args *a)
{
    if (a->file_count != 1) {
        fprintf(stderr, "lmgi: usage: lmgi view SCENE [--size WxH] [--budget MS] [--script EDITS.json] [--frames N] "
                        "[--screenshot FILE] [run options]\n");
        return 2;
    }
    lm_viewer v;
    memset(&v, 0, sizeof v);
    v.a = a;
    v.name = strrchr(a->files[0], '/') ? strrchr(a->files[0], '/') + 1 : a->files[0];
    v.light = -1;
    v.node = v.material = v.axis = -1;
    int ok = preflight(&v) && start(&v);
    while (ok) { /* a frame after every poll: an edit and Esc in one poll still show the edit (and its screenshot) */
        glfwPollEvents();
        ok = frame(&v);
        if (glfwWindowShouldClose(v.win) || (a->frames && v.frame >= a->frames))
            break;
    }
    if (ok && a->screenshot_path && v.rgb)
        lm_viewer_write_frame(&v, a->screenshot_path);
    if (ok && !a->quiet) {
        double took = v.win ? glfwGetTime() - v.opened : 0.0;
        printf("view        %d frames of %s in %.1f s (%.1f frames a second)\n", v.frame, v.name, took,
               took > 0.0 ? v.frame / took : 0.0);
    }
    if (v.win)
        glfwDestroyWindow(v.win);
    glfwTerminate();
    lmgi_updater_free(v.u);
    lmgi_context_free(v.ctx);
    lmgi_free(v.sc);
    if (v.have_script)
        lm_edit_script_free(&v.script);
    lm_view_history_free(&v.history);
    lm_view_watch_free(&v.watch);
    free(v.rgb);
    free(v.rgba);
    lm_view_maps_free(&v.maps);
    return ok && !v.failed ? 0 : 1;
}
