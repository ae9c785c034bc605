/* Indirect light of a frame (composite.h): one pass into an RGBA32F target with depth. */
#include "composite.h"

#include "gl_api.h"
#include <math.h>
#include <stdlib.h>

#include "../core/vecmath.h"
#include "gl_mesh.h"
#include "gl_shader.h"
#include "lightmap_view.h"
#include "offscreen.h"

struct lm_composite {
    int width, height;   /* atlas */
    float *albedo;       /* atlas-sized RGBA: albedo / pi, a = 1 on covered texels */
    GLuint albedo_tex, prog;
    float limit;
};

static const char *VS =
    "#version 450 core\n"
    "layout(location = 0) in vec3 pos;\n"
    "layout(location = 1) in vec2 uv;\n"
    "uniform mat4 view_proj;\n"
    "out vec2 v_uv;\n"
    "void main() { v_uv = uv; gl_Position = view_proj * vec4(pos, 1.0); }\n";
/* Bilinear over the four nearest texels, each weighed by coverage x validity, renormalised. */
static const char *FS =
    "#version 450 core\n"
    "in vec2 v_uv;\n"
    "uniform sampler2D albedo;\n"
    "uniform sampler2D iim;\n"
    "uniform float limit;\n"
    "out vec4 frag;\n"
    "void main() {\n"
    "    if (v_uv.x < 0.0) { frag = vec4(0.0, 0.0, 0.0, 1.0); return; }\n"
    "    ivec2 size = textureSize(albedo, 0);\n"
    "    vec2 p = v_uv * vec2(size) - 0.5;\n"
    "    ivec2 p0 = ivec2(floor(p));\n"
    "    vec2 f = p - vec2(p0);\n"
    "    vec3 sum = vec3(0.0);\n"
    "    float wsum = 0.0;\n"
    "    for (int j = 0; j < 2; j++)\n"
    "        for (int i = 0; i < 2; i++) {\n"
    "            ivec2 q = clamp(p0 + ivec2(i, j), ivec2(0), size - 1);\n"
    "            vec4 al = texelFetch(albedo, q, 0), e = texelFetch(iim, q, 0);\n"
    "            float w = (i == 1 ? f.x : 1.0 - f.x) * (j == 1 ? f.y : 1.0 - f.y);\n"
    "            w *= al.a * (e.a <= limit ? 1.0 : 0.0);\n"
    "            sum += w * al.rgb * e.rgb;\n"
    "            wsum += w;\n"
    "        }\n"
    "    frag = vec4(wsum > 0.0 ? sum / wsum : vec3(0.0), 1.0);\n"
    "}\n";

/* albedo / pi at each covered texel's centre (its triangle's material, texture at the interpolated UV). */
static void fill_albedo(const lm_scene *s, const lm_atlas *a, float *out)
{
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        const uint32_t *v = s->tris + 3 * (size_t)t->tri;
        const lm_material *m = &s->materials[s->tri_material[t->tri]];
        const float *uvs = m->base_color_uv == 1 && s->uv1 ? s->uv1 : s->uv0;
        float uv[2] = {0.0f, 0.0f}, al[3];
        for (int k = 0; k < 3; k++) {
            uv[0] += t->bary[k] * uvs[2 * (size_t)v[k]];
            uv[1] += t->bary[k] * uvs[2 * (size_t)v[k] + 1];
        }
        lm_material_albedo(s, m, uv[0], uv[1], al);
        float *o = out + 4 * ((size_t)t->y * a->width + t->x);
        for (int c = 0; c < 3; c++)
            o[c] = al[c] / (float)M_PI;
        o[3] = 1.0f;
    }
}

static GLuint upload_rgba(int w, int h, const float *rgba)
{
    GLuint tex;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, w, h, 0, GL_RGBA, GL_FLOAT, rgba);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return tex;
}

lm_status lm_composite_create(const lm_scene *s, const lm_atlas *a, float backface_limit, lm_composite **out,
                              lm_error *err)
{
    *out = NULL;
    lm_composite *c = calloc(1, sizeof *c);
    if (c)
        c->albedo = calloc(4 * (size_t)a->width * a->height, sizeof(float));
    if (!c || !c->albedo) {
        free(c);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the albedo atlas", s->path);
    }
    c->width = a->width;
    c->height = a->height;
    c->limit = backface_limit;
    fill_albedo(s, a, c->albedo);
    lm_status st = lm_gl_program("composite", VS, FS, &c->prog, err);
    if (st != LM_OK) {
        lm_composite_free(c);
        return st;
    }
    c->albedo_tex = upload_rgba(a->width, a->height, c->albedo);
    *out = c;
    return LM_OK;
}

void lm_composite_free(lm_composite *c)
{
    if (!c)
        return;
    if (c->albedo_tex)
        glDeleteTextures(1, &c->albedo_tex);
    if (c->prog)
        glDeleteProgram(c->prog);
    free(c->albedo);
    free(c);
}

int lm_composite_albedo(const lm_composite *c, int x, int y, float out[3])
{
    const float *p = c->albedo + 4 * ((size_t)y * c->width + x);
    for (int k = 0; k < 3; k++)
        out[k] = p[k];
    return p[3] > 0.0f;
}

static void draw(const lm_composite *c, const lm_gl_mesh *mesh, unsigned iim_tex, const lm_view *view, int w, int h)
{
    float vp[16];
    lm_mat4_mul(vp, view->proj, view->view);
    glViewport(0, 0, w, h);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUseProgram(c->prog);
    glUniformMatrix4fv(glGetUniformLocation(c->prog, "view_proj"), 1, GL_FALSE, vp);
    glUniform1f(glGetUniformLocation(c->prog, "limit"), c->limit);
    glUniform1i(glGetUniformLocation(c->prog, "albedo"), 0);
    glUniform1i(glGetUniformLocation(c->prog, "iim"), 1);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, c->albedo_tex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, iim_tex);
    lm_gl_mesh_draw(mesh);
    glActiveTexture(GL_TEXTURE0);
}

lm_status lm_composite_indirect(lm_composite *c, const lm_scene *s, const lm_atlas *a, unsigned iim_tex,
                                const lm_view *view, int width, int height, float *rgb, lm_error *err)
{
    float *verts = lm_lightmapped_vertices(s, a);
    if (!verts)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the composite", s->path);
    lm_gl_mesh mesh;
    const int sizes[2] = {3, 2};
    lm_gl_mesh_create(&mesh, verts, (int)(3 * s->tri_count), sizes, 2);
    free(verts);
    lm_offscreen t;
    lm_status st = lm_offscreen_begin_float(&t, width, height, err);
    if (st == LM_OK) {
        draw(c, &mesh, iim_tex, view, width, height);
        lm_offscreen_read_rgb(&t, rgb);
        lm_offscreen_release(&t);
    }
    lm_gl_mesh_destroy(&mesh);
    return st;
}
