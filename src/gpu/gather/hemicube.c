/* Hemicube weights, F(a) and the IIM texture helpers (hemicube.h). */
#include "hemicube.h"

#include "../../core/vecmath.h"
#include "../gl/gl_api.h"
#include <math.h>

#include "../gl/gl_shader.h"
#include "../../trace/emitter_light.h"


void lm_hemicube_settings_default(lm_hemicube_settings *s)
{
    s->resolution = 32;
    s->enlargement = 2.0f;
    s->sky[0] = s->sky[1] = s->sky[2] = 0.0f;
    s->backface_limit = 0.1f;
    s->offset = 1e-4f;
    s->tiles = 16;
    s->proxy_error = LM_PROXY_DEFAULT_ERROR;
    s->scheme = LM_GATHER_VIEWPORTS;
    s->samples = 4;
    s->coverage_samples = 4;
    s->rim_samples = 64;
    s->ray_samples = 400;
    s->direct_at_hits = 1;
    s->direct_near = 16.0f;
    s->adapt = 0.0f;
    s->seed = 0;
    s->cpu_threads = 0;
}

int lm_gather_coverage_for(const lm_scene *s, int closed_form_emitters)
{
    return !closed_form_emitters && lm_emissive_triangle_count(s) > 0 ? 4 : 1;
}

const char *lm_gather_scheme_name(lm_gather_scheme s)
{
    return s == LM_GATHER_VIEWPORTS ? "viewports" : s == LM_GATHER_INSTANCED ? "instanced"
         : s == LM_GATHER_LAYERED   ? "layered"
                                    : "rays";
}

/* Integral of 1 / (pi (1 + x^2 + y^2)^2) over [0, X] x [0, Y] (odd in X and in Y). */
static double corner(double X, double Y)
{
    double sx = sqrt(1.0 + X * X), sy = sqrt(1.0 + Y * Y);
    return (X / sx * atan(Y / sx) + Y / sy * atan(X / sy)) / (2.0 * LM_PI);
}

double lm_form_factor_rect(double x0, double x1, double y0, double y1, double d)
{
    x0 /= d, x1 /= d, y0 /= d, y1 /= d;
    return corner(x1, y1) - corner(x0, y1) - corner(x1, y0) + corner(x0, y0);
}

double lm_hemicube_coverage(double a)
{
    double b = a / sqrt(1.0 + a * a);
    return 4.0 / LM_PI * b * atan(b);
}

double lm_hemicube_pixel_weight(int R, double a, int i, int j)
{
    double h = 2.0 * a / R;
    return lm_form_factor_rect(-a + i * h, -a + (i + 1) * h, -a + j * h, -a + (j + 1) * h, 1.0);
}

double lm_hemicube_pixel_weight_midpoint(int R, double a, int i, int j)
{
    double h = 2.0 * a / R, x = -a + (i + 0.5) * h, y = -a + (j + 0.5) * h, q = x * x + y * y + 1.0;
    return h * h / (LM_PI * q * q);
}

double lm_hemicube_weight_sum(int R, double a, int midpoint)
{
    double sum = 0.0;
    for (int j = 0; j < R; j++)
        for (int i = 0; i < R; i++)
            sum += midpoint ? lm_hemicube_pixel_weight_midpoint(R, a, i, j) : lm_hemicube_pixel_weight(R, a, i, j);
    return sum;
}

unsigned lm_iim_texture_create(int width, int height)
{
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, width, height);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    const float zero[4] = {0, 0, 0, 0};
    glClearTexImage(tex, 0, GL_RGBA, GL_FLOAT, zero);
    return glGetError() == GL_NO_ERROR ? tex : 0;
}

void lm_iim_texture_free(unsigned tex)
{
    GLuint t = tex;
    if (t)
        glDeleteTextures(1, &t);
}

lm_status lm_iim_texture_read(unsigned tex, int width, int height, float *rgba, lm_error *err)
{
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    (void)width, (void)height; /* rgba must hold the whole texture */
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, rgba);
    return lm_gl_check("reading the IIM texture", err);
}

lm_status lm_iim_texture_read_window(unsigned tex, const int win[4], float *rgba, lm_error *err)
{
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureSubImage(tex, 0, win[0], win[1], 0, win[2], win[3], 1, GL_RGBA, GL_FLOAT,
                         (GLsizei)(sizeof(float) * 4 * (size_t)win[2] * (size_t)win[3]), rgba);
    return lm_gl_check("reading a window of the IIM texture", err);
}

lm_status lm_iim_texture_write(unsigned tex, int width, int height, const float *rgba, lm_error *err)
{
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, rgba);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    return lm_gl_check("writing the IIM texture", err);
}
