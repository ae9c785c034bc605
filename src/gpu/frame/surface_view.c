#include "surface_view.h"

#include "../gl/gl_api.h"
#include <stdlib.h>
#include <string.h>

#include "../../core/palette.h"
#include "../../core/vecmath.h"
#include "../gl/gl_mesh.h"
#include "../gl/gl_shader.h"
#include "glsl.h"
#include "../gl/offscreen.h"

/* The surface index as a colour: id + 2 in 24 bits (1: a specular triangle, 0: nothing drawn). */
static void index_color(int id, uint8_t rgb[3])
{
    uint32_t v = (uint32_t)(id + 2);
    rgb[0] = (uint8_t)(v & 255u), rgb[1] = (uint8_t)((v >> 8) & 255u), rgb[2] = (uint8_t)((v >> 16) & 255u);
}

/* Interleaved position + colour (color(surface id)), three unshared corners per triangle, world space. */
static float *build_vertices(const lm_scene *s, const lm_surfaces *su, void (*color)(int, uint8_t[3]))
{
    float *v = malloc(sizeof(float) * 18 * (size_t)(s->tri_count ? s->tri_count : 1));
    if (!v)
        return NULL;
    for (uint32_t t = 0; t < s->tri_count; t++) {
        uint8_t rgb[3];
        color(su->tri_surface[t], rgb);
        for (int k = 0; k < 3; k++) {
            float *o = v + 18 * (size_t)t + 6 * k;
            lm_scene_vertex_world(s, s->tris[3 * (size_t)t + k], o);
            for (int c = 0; c < 3; c++)
                o[3 + c] = rgb[c] / 255.0f;
        }
    }
    return v;
}

static lm_status render(const lm_scene *s, const lm_surfaces *su, const lm_view *view, int width, int height,
                        void (*color)(int, uint8_t[3]), uint8_t *rgba8, lm_error *err)
{
    GLuint prog = 0;
    lm_status st = lm_gl_program("surface_ids", lm_glsl_surface_view_vs, lm_glsl_surface_view_fs, &prog, err);
    if (st != LM_OK)
        return st;
    float *verts = build_vertices(s, su, color);
    if (!verts) {
        glDeleteProgram(prog);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the surface view", s->path);
    }
    lm_gl_mesh mesh;
    const int sizes[2] = {3, 3}; /* position, colour */
    lm_gl_mesh_create(&mesh, verts, (int)(3 * s->tri_count), sizes, 2);
    free(verts);

    lm_offscreen target;
    st = lm_offscreen_begin(&target, width, height, err);
    if (st == LM_OK) {
        float vp[16];
        lm_mat4_mul(vp, view->proj, view->view);
        glUseProgram(prog);
        glUniformMatrix4fv(glGetUniformLocation(prog, "view_proj"), 1, GL_FALSE, vp);
        lm_gl_mesh_draw_scene_sides(&mesh, s);
        st = lm_offscreen_end(&target, rgba8, err);
    }
    lm_gl_mesh_destroy(&mesh);
    glDeleteProgram(prog);
    return st;
}

lm_status lm_render_surface_ids(const lm_scene *s, const lm_surfaces *su, const lm_view *view, int width,
                                int height, uint8_t *rgba8, lm_error *err)
{
    return render(s, su, view, width, height, lm_id_color, rgba8, err);
}

lm_status lm_render_surface_index(const lm_scene *s, const lm_surfaces *su, const lm_view *view, int width,
                                  int height, int32_t *ids, lm_error *err)
{
    lm_status st = render(s, su, view, width, height, index_color, (uint8_t *)ids, err);
    if (st != LM_OK)
        return st;
    for (size_t i = 0, n = (size_t)width * (size_t)height; i < n; i++) { /* in place: 4 bytes in, 4 out */
        const uint8_t *c = (const uint8_t *)(ids + i);
        ids[i] = (int32_t)((uint32_t)c[0] | (uint32_t)c[1] << 8 | (uint32_t)c[2] << 16) - 2;
    }
    return LM_OK;
}
