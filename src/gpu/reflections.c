/* Environment cube maps for mirror and glossy nodes, and the pass that adds their reflections
 * (reflections.h). */
#include "reflections.h"

#include "gl_api.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"
#include "direct_shader.h"
#include "gl_shader.h"

typedef struct {
    int node;
    uint32_t *tris; /* the node's mirror and glossy triangles (their bounds place the map) */
    uint32_t tri_count;
    int glossy;     /* has glossy triangles: the map needs its blurred mip levels */
    int mips_stale; /* a face was rendered since its mips were last built */
    GLuint cube;
} reflector;

struct lm_reflections {
    int size, faces_per_frame, levels;
    reflector *r;
    int count;
    int next;          /* the next face to refresh: reflector next / 6, face next % 6 */
    int primed;        /* every face rendered once */
    GLuint prog;
};

/* Mirror: albedo x env(r). Glossy: ks (n + 2) / (n + 1) max(n.r, 0) x env(r) at the mip level whose texel
 * is the lobe's width 1 / sqrt(n) (lod_base = log2(size / (pi / 2)), a face spanning pi / 2). Glass (ior
 * in the vertex's n): F env(r) + (1 - F) albedo env(t), F the dielectric Fresnel reflectance at the eye
 * ray's angle (Schlick's approximation to it), t the ray refracted into the glass at this first surface
 * (1 under total internal reflection, leaving the inside), looked up as if it left unbent: the glass's
 * far side and the parallax of what lies behind are not modelled. albedo and ks from direct_shader.c's
 * lobes (lm_direct_lobes_glsl), so both passes read a material alike. The back of a single-sided surface
 * reflects nothing. Class numbers as there (1 glossy, 2 mirror, 3 glass). */
static const char *REFLECT_HEAD =
    "#version 450 core\n"
    "in vec3 v_pos, v_ns;\n"
    "flat in vec3 v_base, v_em;\n"
    "flat in vec4 v_par;\n"
    "in vec2 v_uv, v_lm;\n"
    "uniform int has_tex;\n"
    "uniform sampler2D base_tex;\n"
    "uniform samplerCube env;\n"
    "uniform vec3 eye;\n"
    "uniform float lod_base;\n"
    "out vec4 frag;\n";
static const char *REFLECT_MAIN =
    "void main() {\n"
    "    look_up_albedo();\n"
    "    bool two = v_par.y > 0.5;\n"
    "    if (!gl_FrontFacing && !two) { frag = vec4(0.0); return; }\n"
    "    vec3 n = normalize(gl_FrontFacing ? v_ns : -v_ns);\n"
    "    vec3 r = reflect(normalize(v_pos - eye), n);\n"
    "    int cls = int(v_par.w + 0.5);\n"
    "    if (cls == 2) { frag = vec4(albedo * textureLod(env, r, 0.0).rgb, 0.0); return; }\n"
    "    if (cls == 3) {\n"
    "        vec3 d = normalize(v_pos - eye);\n"
    "        float eta = gl_FrontFacing ? 1.0 / v_par.x : v_par.x, c = clamp(-dot(d, n), 0.0, 1.0);\n"
    "        vec3 t = refract(d, n, eta);\n"
    "        float f0 = (1.0 - v_par.x) / (1.0 + v_par.x), F = f0 * f0 + (1.0 - f0 * f0) * pow(1.0 - c, 5.0);\n"
    "        if (dot(t, t) == 0.0) F = 1.0;\n"
    "        vec3 through = dot(t, t) > 0.0 ? albedo * textureLod(env, t, 0.0).rgb : vec3(0.0);\n"
    "        frag = vec4(F * textureLod(env, r, 0.0).rgb + (1.0 - F) * through, 0.0);\n"
    "        return;\n"
    "    }\n"
    "    vec3 kd, ks;\n"
    "    lobes(kd, ks);\n"
    "    float e = v_par.x;\n"
    "    float lod = max(0.0, lod_base - 0.5 * log2(e));\n"
    "    float w = (e + 2.0) / (e + 1.0) * max(dot(n, r), 0.0);\n"
    "    frag = vec4(ks * w * textureLod(env, r, lod).rgb, 0.0);\n"
    "}\n";

static int reflects(lm_material_class c) { return c == LM_MAT_MIRROR || c == LM_MAT_GLOSSY || c == LM_MAT_GLASS; }

/* The nodes with mirror or glossy triangles, each with its list of them (from the node's own range). */
static lm_status find_reflectors(lm_reflections *r, const lm_scene *s, lm_error *err)
{
    r->r = calloc((size_t)s->node_count + 1, sizeof *r->r);
    if (!r->r)
        return lm_fail(err, LM_ERR_NOMEM, "reflections: no memory");
    for (int n = 0; n < s->node_count; n++) {
        const lm_node *node = &s->nodes[n];
        reflector *f = &r->r[r->count];
        if (!node->settings.reflections) /* switched off (extras, lmgi_set_node_effects): drawn black */
            continue;
        for (uint32_t t = node->first_tri; t < node->first_tri + node->tri_count; t++) {
            lm_material_class c = s->materials[s->tri_material[t]].cls;
            if (!reflects(c))
                continue;
            if (!f->tris && !(f->tris = malloc(sizeof(uint32_t) * node->tri_count)))
                return lm_fail(err, LM_ERR_NOMEM, "reflections: no memory");
            f->tris[f->tri_count++] = t;
            f->glossy |= c == LM_MAT_GLOSSY;
        }
        if (f->tri_count) {
            f->node = n;
            r->count++;
        }
    }
    return LM_OK;
}

/* A mirror samples level 0 only: its map gets no mip levels to rebuild (on llvmpipe rebuilding a 128^2
 * float cube's mips costs about as much as rendering a face). */
static GLuint cube_texture(int size, int levels)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_CUBE_MAP, t);
    glTexStorage2D(GL_TEXTURE_CUBE_MAP, levels, GL_RGBA32F, size, size);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    const GLenum wrap[3] = {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R};
    for (int i = 0; i < 3; i++)
        glTexParameteri(GL_TEXTURE_CUBE_MAP, wrap[i], GL_CLAMP_TO_EDGE);
    return t;
}

lm_status lm_reflections_create(const lm_scene *s, int size, int faces_per_frame, lm_reflections **out,
                                lm_error *err)
{
    *out = NULL;
    if (size < 1 || size > 4096 || faces_per_frame < 1)
        return lm_fail(err, LM_ERR_INVALID, "reflections: bad settings (map size %d, faces per frame %d)", size,
                       faces_per_frame);
    lm_reflections *r = calloc(1, sizeof *r);
    if (!r)
        return lm_fail(err, LM_ERR_NOMEM, "reflections: no memory");
    r->size = size;
    r->faces_per_frame = faces_per_frame;
    r->levels = 1 + (int)floor(log2((double)size));
    lm_status st = find_reflectors(r, s, err);
    if (st == LM_OK && r->count == 0) {
        lm_reflections_free(r);
        return LM_OK;
    }
    char fs[4096];
    int len = snprintf(fs, sizeof fs, "%s%s%s", REFLECT_HEAD, lm_direct_lobes_glsl, REFLECT_MAIN);
    if (st == LM_OK && (len < 0 || (size_t)len >= sizeof fs))
        st = lm_fail(err, LM_ERR_BACKEND, "reflections: shader source buffer too small");
    if (st == LM_OK)
        st = lm_gl_program("reflections", lm_direct_vs, fs, &r->prog, err);
    for (int k = 0; st == LM_OK && k < r->count; k++)
        r->r[k].cube = cube_texture(size, r->r[k].glossy ? r->levels : 1);
    if (st == LM_OK)
        st = lm_gl_check("reflections: setup", err);
    if (st != LM_OK) {
        lm_reflections_free(r);
        return st;
    }
    *out = r;
    return LM_OK;
}

void lm_reflections_free(lm_reflections *r)
{
    if (!r)
        return;
    for (int k = 0; k < r->count; k++) {
        free(r->r[k].tris);
        if (r->r[k].cube)
            glDeleteTextures(1, &r->r[k].cube);
    }
    free(r->r);
    if (r->prog)
        glDeleteProgram(r->prog);
    free(r);
}



/* The centre of the reflector's triangles' world bounds, where its map is seen from. */
static void centre(const lm_scene *s, const reflector *f, float c[3])
{
    lm_vec3 lo = lm_v3(INFINITY, INFINITY, INFINITY), hi = lm_scale(lo, -1.0f);
    for (uint32_t i = 0; i < f->tri_count; i++)
        for (int k = 0; k < 3; k++) {
            float p[3];
            lm_scene_vertex_world(s, s->tris[3 * (size_t)f->tris[i] + k], p);
            lo = lm_vmin(lo, lm_v3_load(p));
            hi = lm_vmax(hi, lm_v3_load(p));
        }
    lm_v3_store(c, lm_scale(lm_add(lo, hi), 0.5f));
}

static lm_status render_face(lm_reflections *r, int k, int face, lm_direct *d, const lm_scene *s,
                             const lm_emitters *em, lm_error *err)
{
    float c[3], size = lm_scene_size(s);
    centre(s, &r->r[k], c);
    lm_view v;
    lm_view_cube_face(c, face, 1e-4f * size, 10.0f * size, &v);
    lm_status st = lm_direct_draw_probe(d, s, em, &v, r->size, r->r[k].node, err);
    if (st != LM_OK)
        return st;
    glCopyImageSubData(lm_direct_probe_texture(d), GL_TEXTURE_2D, 0, 0, 0, 0, r->r[k].cube, GL_TEXTURE_CUBE_MAP, 0, 0,
                       0, face, r->size, r->size, 1);
    r->r[k].mips_stale = r->r[k].glossy;
    return LM_OK;
}

lm_status lm_reflections_update(lm_reflections *r, lm_direct *d, const lm_scene *s, const lm_emitters *em,
                                lm_error *err)
{
    if (!r)
        return LM_OK;
    int total = 6 * r->count, n = r->primed ? (r->faces_per_frame < total ? r->faces_per_frame : total) : total;
    lm_status st = LM_OK;
    for (int i = 0; st == LM_OK && i < n; i++) {
        st = render_face(r, r->next / 6, r->next % 6, d, s, em, err);
        r->next = (r->next + 1) % total;
    }
    for (int k = 0; st == LM_OK && k < r->count; k++)
        if (r->r[k].mips_stale) {
            glBindTexture(GL_TEXTURE_CUBE_MAP, r->r[k].cube);
            glGenerateMipmap(GL_TEXTURE_CUBE_MAP);
            r->r[k].mips_stale = 0;
        }
    r->primed = 1;
    return st == LM_OK ? lm_gl_check("reflections: maps", err) : st;
}

lm_status lm_reflections_draw(const lm_reflections *r, const lm_direct *d, const lm_view *view, lm_error *err)
{
    if (!r)
        return LM_OK;
    lm_direct_bind_target(d);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glDisable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    glUseProgram(r->prog);
    float vp[16];
    lm_mat4_mul(vp, view->proj, view->view);
    glUniformMatrix4fv(glGetUniformLocation(r->prog, "view_proj"), 1, GL_FALSE, vp);
    glUniform3fv(glGetUniformLocation(r->prog, "eye"), 1, view->eye);
    glUniform1f(glGetUniformLocation(r->prog, "lod_base"), (float)log2(r->size / (0.5 * LM_PI)));
    glUniform1i(glGetUniformLocation(r->prog, "base_tex"), 2);
    glUniform1i(glGetUniformLocation(r->prog, "env"), 4);
    for (int k = 0; k < r->count; k++) {
        glActiveTexture(GL_TEXTURE4);
        glBindTexture(GL_TEXTURE_CUBE_MAP, r->r[k].cube);
        lm_direct_draw_node(d, r->prog, r->r[k].node);
    }
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return lm_gl_check("reflections: pass", err);
}
