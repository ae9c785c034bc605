/* The viewer's on-screen panel (lmgi view, docs/viewer.md): lines of text on a dark translucent box in the
 * window's top-left corner, drawn with OpenGL 1.x's vertex arrays in the current (compatibility) context
 * from stb_easy_font's quads (Debian's libstb-dev). The text is ASCII; longer lines are cut at the
 * window's width. No allocation beyond a fixed vertex buffer on the stack; not thread-safe (GL). */
#ifndef LM_CLI_VIEW_PANEL_H
#define LM_CLI_VIEW_PANEL_H

#define LM_VIEW_PANEL_LINES 20
#define LM_VIEW_PANEL_COLUMNS 160

typedef struct {
    int count;
    char line[LM_VIEW_PANEL_LINES][LM_VIEW_PANEL_COLUMNS];
} lm_view_panel;

/* Appends a line (printf format; cut at LM_VIEW_PANEL_COLUMNS - 1 characters); beyond the last line, nothing. */
void lm_view_panel_add(lm_view_panel *p, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Draws the panel over a window of width x height pixels at `scale` (2: each font pixel two pixels). */
void lm_view_panel_draw(const lm_view_panel *p, int width, int height, float scale);

#endif
