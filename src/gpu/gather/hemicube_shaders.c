/* The gather's programs from its shaders (glsl/hemicube_render_vs.glsl, hemicube_render_fs.glsl,
 * hemicube_reduce_cs.glsl) and the defines put before them. SCHEME selects how a texel's plane reaches
 * its R x R tile:
 *   0 viewports: one draw per texel, its view in uniforms, its tile a glViewport;
 *   1 instanced: one instanced draw per pass, instance i's view from a buffer, its clip-space position
 *     scaled into tile i of the big target and cut to it by four clip distances;
 *   2 layered: as 1, but instance i renders into layer i of an array target (gl_Layer from the vertex
 *     shader, GL_ARB_shader_viewport_layer_array). */
#include "hemicube_shaders.h"

#include <stdio.h>

#include "../gl/gl_shader.h"
#include "glsl.h"

/* "#version", the scheme's and sample count's defines and extension, then the body. Returns 0 if it
 * does not fit. */
static int with_header(char *out, size_t size, lm_gather_scheme scheme, int samples, int vertex, const char *body)
{
    int n = snprintf(out, size, "#version 450 core\n%s#define SCHEME %d\n#define SAMPLES %d\n%s",
                     vertex && scheme == LM_GATHER_LAYERED ? "#extension GL_ARB_shader_viewport_layer_array : require\n" : "",
                     (int)scheme, samples, body);
    return n > 0 && (size_t)n < size;
}

lm_status lm_hemicube_programs(lm_gather_scheme scheme, int samples, unsigned *render, unsigned *reduce, lm_error *err)
{
    char vs[5120], fs[4096], cs[2560];
    if (!with_header(vs, sizeof vs, scheme, samples, 1, lm_glsl_hemicube_render_vs) ||
        !with_header(fs, sizeof fs, scheme, samples, 0, lm_glsl_hemicube_render_fs) ||
        !with_header(cs, sizeof cs, scheme, samples, 0, lm_glsl_hemicube_reduce_cs))
        return lm_fail(err, LM_ERR_BACKEND, "hemicube shaders: source buffer too small");
    lm_status st = lm_gl_program("hemicube_render", vs, fs, render, err);
    if (st == LM_OK)
        st = lm_gl_compute_program("hemicube_reduce", cs, reduce, err);
    return st;
}
