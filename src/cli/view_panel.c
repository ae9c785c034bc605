/* The viewer's text panel (view_panel.h). */
#include "view_panel.h"

#include <GL/gl.h>
#include <stdarg.h>
#include <stdio.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb/stb_easy_font.h>
#pragma GCC diagnostic pop

#define MARGIN 6.0f

void lm_view_panel_add(lm_view_panel *p, const char *fmt, ...)
{
    if (p->count >= LM_VIEW_PANEL_LINES)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->line[p->count++], LM_VIEW_PANEL_COLUMNS, fmt, ap);
    va_end(ap);
}

void lm_view_panel_draw(const lm_view_panel *p, int width, int height, float scale)
{
    if (p->count == 0 || width <= 0 || height <= 0)
        return;
    static char quads[LM_VIEW_PANEL_COLUMNS * 270]; /* stb_easy_font: about 270 bytes a character */
    float w = 0.0f, line_h = (float)stb_easy_font_height("A") + 3.0f;
    for (int i = 0; i < p->count; i++) {
        float lw = (float)stb_easy_font_width((char *)p->line[i]);
        w = lw > w ? lw : w;
    }
    glMatrixMode(GL_PROJECTION);
    glPushMatrix();
    glLoadIdentity();
    glOrtho(0.0, width, height, 0.0, -1.0, 1.0); /* pixels, y down as the font's */
    glMatrixMode(GL_MODELVIEW);
    glPushMatrix();
    glLoadIdentity();
    glScalef(scale, scale, 1.0f);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glColor4f(0.0f, 0.0f, 0.0f, 0.6f);
    glRectf(0.0f, 0.0f, w + 2.0f * MARGIN, line_h * (float)p->count + 2.0f * MARGIN);
    glColor4f(1.0f, 1.0f, 1.0f, 1.0f);
    glEnableClientState(GL_VERTEX_ARRAY);
    for (int i = 0; i < p->count; i++) {
        int n = stb_easy_font_print(MARGIN, MARGIN + line_h * (float)i, (char *)p->line[i], NULL, quads,
                                    (int)sizeof quads);
        glVertexPointer(2, GL_FLOAT, 16, quads);
        glDrawArrays(GL_QUADS, 0, 4 * n);
    }
    glDisableClientState(GL_VERTEX_ARRAY);
    glDisable(GL_BLEND);
    glPopMatrix();
    glMatrixMode(GL_PROJECTION);
    glPopMatrix();
    glMatrixMode(GL_MODELVIEW);
}
