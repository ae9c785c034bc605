#include "lightmap_view.h"

#include "../gl/gl_api.h"
#include <math.h>
#include <stdlib.h>

#include "../../core/vecmath.h"
#include "../gl/gl_mesh.h"
#include "../gl/gl_shader.h"
#include "glsl.h"
#include "../gl/offscreen.h"

float *lm_lightmapped_vertices(const lm_scene *s, const lm_atlas *a)
{
    float *v = malloc(sizeof(float) * 15 * (size_t)(s->tri_count ? s->tri_count : 1));
    if (!v)
        return NULL;
    for (uint32_t t = 0; t < s->tri_count; t++)
        for (int k = 0; k < 3; k++) {
            float *o = v + 15 * (size_t)t + 5 * k;
            lm_scene_vertex_world(s, s->tris[3 * (size_t)t + k], o);
            const float *uv = a->corner_uv + 6 * (size_t)t + 2 * k;
            int none = a->tri_chart[t] < 0 || !isfinite(uv[0]);
            o[3] = none ? -1.0f : uv[0];
            o[4] = none ? -1.0f : uv[1];
        }
    return v;
}

static GLuint upload_atlas(const lm_atlas *a, const float *rgb)
{
    GLuint tex;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, a->width, a->height, 0, GL_RGB, GL_FLOAT, rgb);
    lm_texture_linear_clamped();
    return tex;
}

/* The scene's lightmapped triangles drawn with prog into the bound target, the atlas texture tex on unit 0
 * as "atlas", the view's matrix as "view_proj". Fails only when memory runs out. */
static lm_status draw_lightmapped(const lm_scene *s, const lm_atlas *a, GLuint prog, GLuint tex, const lm_view *view,
                                  lm_error *err)
{
    float *verts = lm_lightmapped_vertices(s, a);
    if (!verts)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the lightmap view", s->path);
    lm_gl_mesh mesh;
    const int sizes[2] = {3, 2}; /* position, lightmap UV */
    lm_gl_mesh_create(&mesh, verts, (int)(3 * s->tri_count), sizes, 2);
    free(verts);
    float vp[16];
    lm_mat4_mul(vp, view->proj, view->view);
    glUseProgram(prog);
    glUniformMatrix4fv(glGetUniformLocation(prog, "view_proj"), 1, GL_FALSE, vp);
    glUniform1i(glGetUniformLocation(prog, "atlas"), 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, tex);
    lm_gl_mesh_draw_scene_sides(&mesh, s);
    lm_gl_mesh_destroy(&mesh);
    return LM_OK;
}

lm_status lm_render_lightmap(const lm_scene *s, const lm_atlas *a, const float *rgb, float exposure,
                             const lm_view *view, int width, int height, uint8_t *rgba8, lm_error *err)
{
    GLuint prog = 0;
    lm_status st = lm_gl_program("lightmap_view", lm_glsl_lightmap_view_vs, lm_glsl_lightmap_view_fs, &prog, err);
    if (st != LM_OK)
        return st;
    GLuint tex = upload_atlas(a, rgb);
    lm_offscreen target;
    st = lm_offscreen_begin(&target, width, height, err);
    if (st == LM_OK) {
        glUseProgram(prog);
        glUniform1f(glGetUniformLocation(prog, "exposure"), exposure);
        st = draw_lightmapped(s, a, prog, tex, view, err);
        if (st == LM_OK)
            st = lm_offscreen_end(&target, rgba8, err);
        else
            lm_offscreen_release(&target);
    }
    glDeleteTextures(1, &tex);
    glDeleteProgram(prog);
    return st;
}

lm_status lm_render_atlas_irradiance(const lm_scene *s, const lm_atlas *a, unsigned tex, const lm_view *view,
                                     int width, int height, float *rgb, lm_error *err)
{
    GLuint prog = 0;
    lm_status st = lm_gl_program("atlas_irradiance", lm_glsl_lightmap_view_vs, lm_glsl_atlas_irradiance_fs, &prog, err);
    if (st != LM_OK)
        return st;
    size_t n = 3 * (size_t)width * height;
    float *seen = malloc((n ? n : 1) * sizeof *seen);
    lm_offscreen target;
    st = seen ? lm_offscreen_begin_float(&target, width, height, err)
              : lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the atlas's view", s->path);
    if (st == LM_OK) {
        st = draw_lightmapped(s, a, prog, tex, view, err);
        if (st == LM_OK)
            lm_offscreen_read_rgb(&target, seen);
        lm_offscreen_release(&target);
    }
    for (size_t i = 0; st == LM_OK && i < n; i++)
        rgb[i] += seen[i];
    free(seen);
    glDeleteProgram(prog);
    return st == LM_OK ? lm_gl_check("the atlas's view", err) : st;
}
