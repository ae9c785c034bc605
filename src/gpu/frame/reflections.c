/* Environment cube maps for mirror and glossy nodes, and the pass that adds their reflections
 * (reflections.h; glsl/reflections_fs.glsl over the direct light's direct_vs.glsl). */
#include "reflections.h"

#include "../gl/gl_api.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../core/hash.h"
#include "../../core/vecmath.h"
#include "../../scene/flat_reflectors.h"
#include "glsl.h"
#include "../gl/gl_shader.h"

typedef struct {
    int node;
    uint32_t *tris; /* the node's mirror and glossy triangles (their bounds place the map) */
    uint32_t tri_count;
    int glossy;     /* has glossy triangles: the map needs its blurred mip levels */
    int mips_stale; /* a face was rendered since its mips were last built */
    float centre[3]; /* where its faces were last rendered from */
    long dirty[6];  /* per face: the update it became dirty at, 0 when clean */
    GLuint cube;
    /* a flat reflector (planar): the view mirrored in its plane, no cube map */
    int planar;
    GLuint plane_tex, plane_depth; /* the mirrored picture's radiance (mips when glossy) and depth */
    int plane_w, plane_h, plane_levels;
    uint64_t plane_key;            /* what it was drawn from (0: never drawn) */
} reflector;

struct lm_reflections {
    int size, faces_per_frame, levels;
    int frame_faces; /* lm_reflections_limit_faces's (0: faces_per_frame) */
    reflector *r;
    int count;
    long frame;        /* updates so far */
    int primed;        /* every face rendered once */
    /* what the faces saw when they were rendered: node matrices, lightmap versions, the lighting */
    int node_count, surface_count;
    float (*world)[16];
    float (*local_box)[6]; /* per node, its triangles' bounds in its own space (min > max: none) */
    uint32_t *surface_version;
    uint64_t lighting;
    GLuint prog;
};


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
            if (!lm_material_reflects(c))
                continue;
            if (!f->tris && !(f->tris = malloc(sizeof(uint32_t) * node->tri_count)))
                return lm_fail(err, LM_ERR_NOMEM, "reflections: no memory");
            f->tris[f->tri_count++] = t;
            f->glossy |= c == LM_MAT_GLOSSY;
        }
        if (f->tri_count) {
            f->node = n;
            f->planar = lm_node_is_flat_reflector(s, n);
            r->count++;
        }
    }
    return LM_OK;
}

/* Every node's triangles' bounds in its own space, and the matrices they are seen at (none yet). */
static lm_status node_boxes(lm_reflections *r, const lm_scene *s, lm_error *err)
{
    r->node_count = s->node_count;
    r->world = calloc((size_t)s->node_count + 1, sizeof *r->world);
    r->local_box = malloc(((size_t)s->node_count + 1) * sizeof *r->local_box);
    if (!r->world || !r->local_box)
        return lm_fail(err, LM_ERR_NOMEM, "reflections: no memory");
    lm_scene_node_local_boxes(s, &r->local_box[0][0]);
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
    if (st == LM_OK)
        st = node_boxes(r, s, err);
    if (st == LM_OK)
        st = lm_gl_program("reflections", lm_glsl_direct_vs, lm_glsl_reflections_fs, &r->prog, err);
    for (int k = 0; st == LM_OK && k < r->count; k++)
        if (!r->r[k].planar)
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
        if (r->r[k].plane_tex)
            glDeleteTextures(1, &r->r[k].plane_tex);
        if (r->r[k].plane_depth)
            glDeleteTextures(1, &r->r[k].plane_depth);
    }
    free(r->r);
    free(r->world);
    free(r->local_box);
    free(r->surface_version);
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
                             const lm_emitters *em, lm_caustic_pass *caustics, lm_error *err)
{
    reflector *f = &r->r[k];
    float size = lm_scene_size(s);
    centre(s, f, f->centre);
    lm_view v;
    lm_view_cube_face(f->centre, face, 1e-4f * size, 10.0f * size, &v);
    const lm_frame_targets *t = lm_direct_targets(d);
    lm_status st = lm_direct_draw_probe(d, s, em, &v, r->size, f->node, err);
    if (st == LM_OK && caustics) /* the face's caustics, over its own depth */
        st = lm_caustic_pass_run(caustics, LM_CAUSTIC_SLOT_PROBE, &v, lm_frame_targets_depth(t, LM_FRAME_PROBE), r->size,
                                 r->size, d, NULL, err);
    if (st != LM_OK)
        return st;
    glCopyImageSubData(lm_frame_targets_radiance(t, LM_FRAME_PROBE), GL_TEXTURE_2D, 0, 0, 0, 0, f->cube,
                       GL_TEXTURE_CUBE_MAP, 0, 0, 0, face, r->size, r->size, 1);
    f->mips_stale = f->glossy;
    f->dirty[face] = 0;
    return LM_OK;
}

/* Marks a face dirty (keeping the update it first became dirty at). */
static void mark(lm_reflections *r, int k, int face)
{
    if (!r->r[k].planar && !r->r[k].dirty[face])
        r->r[k].dirty[face] = r->frame;
}

/* Node n's world bounds under matrix m (its local box's corners placed); 0 when it has no triangles. */
static int world_box(const lm_reflections *r, int n, const float m[16], float out[6])
{
    const float *b = r->local_box[n];
    if (!(b[0] <= b[3]))
        return 0;
    lm_box_placed(b, m, out);
    return 1;
}

/* Whether a world box meets cube face `face` seen from c (lm_view_cube_face's order: +x -x +y -y +z -z): a
 * point d = p - c is in the face's frustum when its component along the face's axis is at least each
 * other's magnitude; the box is out when all 8 corners fail one of those four planes. */
static int box_meets_face(const float box[6], const float c[3], int face)
{
    int axis = face / 2, u = (axis + 1) % 3, v = (axis + 2) % 3;
    float sign = face & 1 ? -1.0f : 1.0f;
    for (int plane = 0; plane < 4; plane++) {
        int other = plane < 2 ? u : v;
        float s2 = plane & 1 ? -1.0f : 1.0f;
        int out = 1;
        for (int k = 0; k < 8 && out; k++) {
            float d[3] = {box[k & 1 ? 3 : 0] - c[0], box[k & 2 ? 4 : 1] - c[1], box[k & 4 ? 5 : 2] - c[2]};
            out = sign * d[axis] + s2 * d[other] < 0.0f;
        }
        if (out)
            return 0;
    }
    return 1;
}

/* Marks the faces of every map that see the world box (those of the map of node `self` all). */
static void mark_box(lm_reflections *r, const float box[6], int self)
{
    for (int k = 0; k < r->count; k++)
        for (int face = 0; face < 6; face++)
            if (r->r[k].node == self || box_meets_face(box, r->r[k].centre, face))
                mark(r, k, face);
}

/* Dirty faces from what changed since the last update: the lighting (every face), moved nodes (the faces
 * that saw them where they were or see them where they are; all of a moved reflector's own), surfaces
 * whose displayed lightmap changed. */
static lm_status mark_changes(lm_reflections *r, const lm_scene *s, const lm_reflection_inputs *in, lm_error *err)
{
    int all = !r->primed || in->lighting != r->lighting;
    r->lighting = in->lighting;
    for (int k = 0; k < r->count; k++)
        for (int face = 0; face < 6 && all; face++)
            mark(r, k, face);
    for (int n = 0; n < r->node_count; n++) {
        const float *w = s->nodes[n].world;
        if (!memcmp(w, r->world[n], sizeof r->world[n]))
            continue;
        float box[6];
        if (r->primed && world_box(r, n, r->world[n], box))
            mark_box(r, box, n);
        if (world_box(r, n, w, box))
            mark_box(r, box, n);
        memcpy(r->world[n], w, sizeof r->world[n]);
    }
    if (!in->surface_version || !in->surfaces)
        return LM_OK;
    int S = in->surfaces->surface_count;
    if (r->surface_count != S) {
        free(r->surface_version);
        r->surface_version = calloc((size_t)S + 1, sizeof *r->surface_version);
        if (!r->surface_version)
            return lm_fail(err, LM_ERR_NOMEM, "reflections: no memory");
        r->surface_count = S;
    }
    for (int k = 0; k < S; k++) {
        if (in->surface_version[k] == r->surface_version[k])
            continue;
        r->surface_version[k] = in->surface_version[k];
        int n = in->surfaces->surfaces[k].node;
        float box[6];
        if (world_box(r, n, s->nodes[n].world, box))
            mark_box(r, box, -1);
    }
    return LM_OK;
}

/* The dirty face that became dirty first (reflector * 6 + face), -1 when none. */
static int oldest_dirty(const lm_reflections *r)
{
    int best = -1;
    long since = 0;
    for (int k = 0; k < r->count; k++)
        for (int face = 0; face < 6; face++) {
            long d = r->r[k].dirty[face];
            if (d && (best < 0 || d < since))
                best = 6 * k + face, since = d;
        }
    return best;
}

lm_status lm_reflections_update(lm_reflections *r, lm_direct *d, const lm_scene *s, const lm_emitters *em,
                                const lm_reflection_inputs *in, int *faces, lm_error *err)
{
    *faces = 0;
    if (!r)
        return LM_OK;
    r->frame++;
    lm_status st = mark_changes(r, s, in, err);
    /* the first update renders every face, then at most faces_per_frame, the longest dirty first */
    int budget = !r->primed ? lm_reflections_face_count(r) : r->frame_faces ? r->frame_faces : r->faces_per_frame;
    for (int i = 0; st == LM_OK && i < budget; i++) {
        int f = oldest_dirty(r);
        if (f < 0)
            break;
        st = render_face(r, f / 6, f % 6, d, s, em, in->caustics, err);
        ++*faces;
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

void lm_reflections_limit_faces(lm_reflections *r, int most)
{
    if (r)
        r->frame_faces = most > 0 ? most : 0;
}

int lm_reflections_face_count(const lm_reflections *r)
{
    int n = 0;
    for (int k = 0; r && k < r->count; k++)
        n += r->r[k].planar ? 0 : 6;
    return n;
}

int lm_reflections_dirty_faces(const lm_reflections *r)
{
    int n = 0;
    for (int k = 0; r && k < r->count; k++)
        for (int face = 0; face < 6; face++)
            n += r->r[k].dirty[face] != 0;
    return n;
}

/* The reflection about plane (n, w), p -> p - 2 (n.p + w) n, as a column-major matrix. */
static void reflection_matrix(const float plane[4], float m[16])
{
    lm_mat4_identity(m);
    for (int c = 0; c < 3; c++) {
        for (int row = 0; row < 3; row++)
            m[4 * c + row] -= 2.0f * plane[row] * plane[c];
        m[12 + c] = -2.0f * plane[3] * plane[c];
    }
}

/* The flat reflector's picture textures at width x height (re-made when that changes). */
static void plane_textures(reflector *f, int width, int height)
{
    if (f->plane_tex && f->plane_w == width && f->plane_h == height)
        return;
    if (f->plane_tex)
        glDeleteTextures(1, &f->plane_tex);
    if (f->plane_depth)
        glDeleteTextures(1, &f->plane_depth);
    int side = width > height ? width : height;
    f->plane_levels = f->glossy ? 1 + (int)floor(log2((double)side)) : 1;
    glGenTextures(1, &f->plane_tex);
    glBindTexture(GL_TEXTURE_2D, f->plane_tex);
    glTexStorage2D(GL_TEXTURE_2D, f->plane_levels, GL_RGBA32F, width, height);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, f->plane_levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glGenTextures(1, &f->plane_depth);
    glBindTexture(GL_TEXTURE_2D, f->plane_depth);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH_COMPONENT24, width, height);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindTexture(GL_TEXTURE_2D, 0);
    f->plane_w = width, f->plane_h = height;
    f->plane_key = 0;
}

/* What a flat reflector's picture is drawn from: the mirrored view, its size, the lighting, where every
 * node is, the displayed lightmaps and the shadow maps. */
static uint64_t plane_key(const lm_view *mirrored, int width, int height, const lm_scene *s,
                          const lm_reflection_inputs *in, const lm_direct *d)
{
    uint64_t key = lm_hash_bytes(lm_scene_world_hash(s), mirrored->view, sizeof mirrored->view);
    key = lm_hash_bytes(key, mirrored->proj, sizeof mirrored->proj);
    const int size[2] = {width, height};
    long maps = lm_direct_shadow_maps_rendered(d);
    key = lm_hash_bytes(key, size, sizeof size);
    key = lm_hash_bytes(key, &in->lighting, sizeof in->lighting);
    key = lm_hash_bytes(key, &maps, sizeof maps);
    if (in->surfaces && in->surface_version)
        key = lm_hash_bytes(key, in->surface_version,
                            sizeof *in->surface_version * (size_t)in->surfaces->surface_count);
    return key | 1; /* never 0, "never drawn" */
}

lm_status lm_reflections_draw_planes(lm_reflections *r, lm_direct *d, const lm_scene *s, const lm_emitters *em,
                                     const lm_reflection_inputs *in, const lm_view *view, int width, int height,
                                     int *drawn, lm_error *err)
{
    *drawn = 0;
    lm_status st = LM_OK;
    for (int k = 0; r && st == LM_OK && k < r->count; k++) {
        reflector *f = &r->r[k];
        if (!f->planar)
            continue;
        float extent, plane[4];
        lm_node_reflector_plane(s, f->node, plane, &extent);
        float side = lm_dot(lm_v3_load(plane), lm_v3_load(view->eye)) + plane[3];
        if (side < 0.0f) /* the eye's side positive: what lies there is what the plane reflects */
            for (int c = 0; c < 4; c++)
                plane[c] = -plane[c];
        lm_view m = *view;
        float refl[16];
        reflection_matrix(plane, refl);
        lm_mat4_mul(m.view, view->view, refl);
        lm_v3_store(m.eye, lm_mat4_point(refl, lm_v3_load(view->eye)));
        plane_textures(f, width, height);
        uint64_t key = plane_key(&m, width, height, s, in, d);
        if (key == f->plane_key)
            continue;
        /* what touches the plane stays in (an object standing on it): the cut lies 1e-4 of the scene's
         * size behind it */
        float clip[4] = {plane[0], plane[1], plane[2], plane[3] + 1e-4f * lm_scene_size(s)};
        st = lm_direct_draw_mirror(d, s, em, &m, width, height, f->node, clip, err);
        const lm_frame_targets *t = lm_direct_targets(d);
        if (st == LM_OK && in->caustics) { /* the picture's caustics, over its own depth */
            lm_caustic_pass_set_clip(in->caustics, clip);
            st = lm_caustic_pass_run(in->caustics, LM_CAUSTIC_SLOT_MIRROR, &m,
                                     lm_frame_targets_depth(t, LM_FRAME_MIRROR), width, height, d, NULL, err);
            lm_caustic_pass_set_clip(in->caustics, NULL);
        }
        if (st != LM_OK)
            break;
        glCopyImageSubData(lm_frame_targets_radiance(t, LM_FRAME_MIRROR), GL_TEXTURE_2D, 0, 0, 0, 0, f->plane_tex,
                           GL_TEXTURE_2D, 0, 0, 0, 0, width, height, 1);
        glCopyImageSubData(lm_frame_targets_depth(t, LM_FRAME_MIRROR), GL_TEXTURE_2D, 0, 0, 0, 0, f->plane_depth,
                           GL_TEXTURE_2D, 0, 0, 0, 0, width, height, 1);
        if (f->plane_levels > 1) {
            glBindTexture(GL_TEXTURE_2D, f->plane_tex);
            glGenerateMipmap(GL_TEXTURE_2D);
            glBindTexture(GL_TEXTURE_2D, 0);
        }
        f->plane_key = key;
        ++*drawn;
    }
    return st == LM_OK ? lm_gl_check("reflections: flat reflectors", err) : st;
}

lm_status lm_reflections_draw(const lm_reflections *r, const lm_direct *d, const lm_scene *s, const lm_view *view,
                              lm_error *err)
{
    if (!r)
        return LM_OK;
    lm_frame_targets_bind_radiance(lm_direct_targets(d), LM_FRAME_VIEW);
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
    glUniform1i(glGetUniformLocation(r->prog, "plane_tex"), 5);
    glUniform1i(glGetUniformLocation(r->prog, "plane_depth"), 6);
    int ortho = view->proj[11] == 0.0f;
    /* a mirrored picture's pixel (x, y) is the view's; its depths turned back into distances along the
     * view's axis (perspective: P14 / (z_ndc + P10); orthographic: -(z_ndc - P14) / P10) */
    glUniform4f(glGetUniformLocation(r->prog, "lens"), view->proj[10], view->proj[14], view->proj[5], (float)ortho);
    for (int k = 0; k < r->count; k++) {
        const reflector *f = &r->r[k];
        glUniform1i(glGetUniformLocation(r->prog, "planar"), f->planar);
        if (f->planar) {
            if (!f->plane_key) /* not drawn for this view: lm_reflections_draw_planes first */
                continue;
            glUniform3f(glGetUniformLocation(r->prog, "plane_size"), (float)f->plane_w, (float)f->plane_h,
                        (float)(f->plane_levels - 1));
            glActiveTexture(GL_TEXTURE5);
            glBindTexture(GL_TEXTURE_2D, f->plane_tex);
            glActiveTexture(GL_TEXTURE6);
            glBindTexture(GL_TEXTURE_2D, f->plane_depth);
            lm_direct_draw_node(d, r->prog, f->node);
            continue;
        }
        const lm_node_settings *ns = &s->nodes[r->r[k].node].settings;
        glUniform1i(glGetUniformLocation(r->prog, "use_box"), ns->has_reflection_box);
        glUniform3fv(glGetUniformLocation(r->prog, "box_lo"), 1, ns->reflection_box);
        glUniform3fv(glGetUniformLocation(r->prog, "box_hi"), 1, ns->reflection_box + 3);
        glUniform3fv(glGetUniformLocation(r->prog, "centre"), 1, r->r[k].centre);
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
