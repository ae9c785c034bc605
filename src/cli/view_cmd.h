/* `lmgi view SCENE`: a window (GLFW) showing the scene's lighting as the updater keeps it up to date, each
 * frame within a time budget, from a camera the mouse and keys move; lights edited from the keyboard
 * through the same edit API an engine uses; an edit script played at its frames; screenshots
 * (docs/viewer.md). Built on the public API only: the picture is lmgi_render's, tone-mapped by
 * lmgi_tonemap_rgba8, drawn with OpenGL in the window's own context (lmgi's calls leave it current).
 * Where there is no display it fails with a message, before loading anything. */
#ifndef LM_CLI_VIEW_CMD_H
#define LM_CLI_VIEW_CMD_H

#include "args.h"

#define LM_VIEW_WIDTH 640
#define LM_VIEW_HEIGHT 480
#define LM_VIEW_BUDGET_MS 16.0f /* the updater's budget a frame unless --budget says (60 frames a second) */

int lm_cli_view(const lm_cli_args *a);

#endif
