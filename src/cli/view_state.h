/* The viewer's state shared by its files (lmgi view, docs/viewer.md): view_cmd.c makes the window and runs
 * the frames, view_input.c turns the mouse and keys into camera moves, edits and screenshots. One viewer
 * a process; everything on the thread that made the window (GLFW's callbacks come from glfwPollEvents). */
#ifndef LM_CLI_VIEW_STATE_H
#define LM_CLI_VIEW_STATE_H

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <lmgi_tools.h>

#include "args.h"
#include "edit_script.h"
#include "view_camera.h"
#include "view_edit.h"
#include "view_maps.h"
#include "view_watch.h"

typedef struct lm_viewer lm_viewer;
struct lm_viewer {
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
    double start, last, opened; /* start: the animation's clock (pausing moves it); opened: the window's */
    int light;               /* the selected light, -1: none */
    int node;                /* the selected node, -1: none */
    int material;            /* the material clicked with it (under the cursor), -1: none */
    int drag;                /* 0, 1 orbit, 2 pan, 3 moving the selected node, 4 the selected light */
    int axis;                /* moving a node: -1 on the horizontal plane, 0 1 2 along world x y z (X Y Z held) */
    lmgi_light light_grab;   /* moving a light: the light then */
    unsigned fly;            /* the fly keys held (W A S D Q E, bits 0-5), pressed without ctrl: from the key
                              * events, so that ctrl+S saves without flying back however its press and
                              * release fall between frames */
    double mouse[2], press[2];
    int catch_up;            /* a move made (lm_viewer_placed): updates left to run without the budget, until
                              * one catches it up (lmgi_update_stats.placements_caught_up) */
    char catch_up_what[32];  /* what made it, for the line that says so */
    float grab[3], grab_start[16]; /* moving a node: the point grabbed and the node's matrix then */
    lm_view_history history;
    int saves;
    lm_view_watch watch;     /* --watch */
    int busy;                /* updates since work began (an edit, photons, AIMs, texels, caustics, faces, shadows) */
    int idle;                /* of them, the last ones in a row that did none and followed no edit */
    double busy_since;
    int moved;               /* of the updates since work began, the last that did work or left texels to
                              * move: the lightmap is still after it (the rest of the wait is the round's
                              * photon checks) */
    double moved_at;
    int round;               /* updates in which the round robin re-traces every stored photon once
                              * (photons per group / re-traced per group a frame): a change a move made is
                              * found within a round, not before */
    int need_round;          /* a node moved (or the round robin found a change) since the lighting last
                              * caught up: a whole round must pass before it can have */
    uint32_t stale_texels;   /* the error atlas (lm_view_maps_staleness): valid texels still to move, */
    float stale_max;         /* and the largest relative change still to come */
    double stale_at;         /* when it was read */
    lmgi_updater_desc desc;  /* the updater's, for a reload */
    float exposure;          /* fixed from the first picture (X meters again) */
    float *rgb;              /* the picture, linear, top row first */
    unsigned char *rgba;     /* tone-mapped, bottom row first (glDrawPixels') */
    int width, height;
    lmgi_update_stats stats;
    double ms_render, fps;
    int map;                 /* what the window shows (view_maps.h): the picture, or a map of the lighting */
    lm_view_maps maps;
    int shots, want_shot;    /* want_shot: P was pressed, the window is captured after its next drawing */
    char status[160];
    int failed;
};

/* What the last action did, on the panel and the terminal (unless -q). */
void lm_viewer_say(lm_viewer *v, const char *text);
/* An edit was made: the lighting is catching up from now on; `moved` (a node moved): for a round of the
 * round robin at least. */
void lm_viewer_edited(lm_viewer *v, int moved);
/* A node or light put somewhere in one go, after lm_viewer_edited: a drag released, an undo, a key's
 * step, the watched file saved. The updater catches a placement up only in an update without a budget
 * (docs/api.md), so the window runs its next updates without it, at most a few, until one has; that one
 * says so, naming `what`. A drag's own moves, and a script's edits (an application's stream), are not
 * this: they stay within the budget. */
void lm_viewer_placed(lm_viewer *v, const char *what);
/* The first light from id `from` on (wrapping) that is not removed; -1 when there is none. */
void lm_viewer_select_light(lm_viewer *v, int from);
/* Installs the window's mouse and key callbacks (the window's user pointer is v). */
void lm_viewer_input(lm_viewer *v);
/* W A S D Q E held: the camera flown for `seconds`. */
void lm_viewer_fly(lm_viewer *v, float seconds);
/* The window as drawn (P) to the next free lmgi-view-NNN.png; the lighting alone to path. */
void lm_viewer_window_shot(lm_viewer *v, int fw, int fh);
void lm_viewer_write_frame(lm_viewer *v, const char *path);

#endif
