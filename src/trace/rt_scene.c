#include "rt_scene.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <pmmintrin.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xmmintrin.h>

#include "../core/vecmath.h"

struct lm_rt {
    RTCDevice device;
    RTCScene top;
    const lm_scene *scene;
    const int *tri_surface;     /* from surfaces, or NULL */
    unsigned static_inst;       /* instance geomID of the static scene in top, RTC_INVALID_GEOMETRY_ID if none */
    uint32_t static_count;
    uint32_t *static_tri;       /* static primID -> scene triangle */
    float (*static_ng)[3];      /* static primID -> its unit geometric normal (Embree's Ng, normalized
                                 * once here instead of at every hit) */
    float (*static_ns)[3];      /* static primID -> shading normal if the triangle is flat, else NaNs */
    int instance_count;
    int *inst_node;             /* instance geomID -> node */
    int *node_inst;             /* node -> instance geomID, -1 for static nodes */
    float (*inst_world)[16];    /* current world matrix of each instance */
    float (*node_nmat)[9];      /* node -> normal matrix of its world matrix (kept with inst_world) */
    uint64_t top_commits;       /* the top level's commits (lm_rt_top_commits) */
    uint64_t rebuilds;          /* lm_rt_rebuild's (lm_rt_rebuilds) */
    char device_error[256];
};

/* The top level committed (counted for lm_rt_top_commits). */
static void commit_top(lm_rt *rt)
{
    rtcCommitScene(rt->top);
    rt->top_commits++;
}

static void on_device_error(void *user, enum RTCError code, const char *str)
{
    lm_rt *rt = user;
    snprintf(rt->device_error, sizeof rt->device_error, "Embree error %d: %s", (int)code, str ? str : "");
}

void lm_rt_thread_init(void)
{
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

/* A triangle geometry holding `count` scene triangles, in world space (each triangle placed by its
 * node's current world matrix) or in node-local space. */
static RTCGeometry make_triangles(lm_rt *rt, const lm_scene *s, const uint32_t *tris, uint32_t count,
                                  int world_space)
{
    RTCGeometry g = rtcNewGeometry(rt->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                        (size_t)count * 3);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                           count);
    if (!vb || !ib) {
        rtcReleaseGeometry(g);
        return NULL;
    }
    /* Unshared vertices, three per triangle: instanced copies and mixed nodes need no remapping. */
#pragma omp parallel for schedule(static)
    for (uint32_t i = 0; i < count; i++) {
        const uint32_t *t = s->tris + 3 * (size_t)tris[i];
        const float *world = s->nodes[s->tri_node[tris[i]]].world;
        for (int k = 0; k < 3; k++) {
            lm_vec3 p = lm_v3_load(s->positions + 3 * (size_t)t[k]);
            if (world_space)
                p = lm_mat4_point(world, p);
            lm_v3_store(vb + 9 * (size_t)i + 3 * k, p);
            ib[3 * (size_t)i + k] = 3 * i + k;
        }
    }
    rtcCommitGeometry(g);
    return g;
}

static lm_status fail_backend(lm_rt *rt, lm_error *err, const char *what)
{
    return lm_fail(err, LM_ERR_BACKEND, "%s: %s", what, rt->device_error[0] ? rt->device_error : "Embree failed");
}

static lm_status add_static(lm_rt *rt, const lm_scene *s, lm_error *err)
{
    for (int n = 0; n < s->node_count; n++)
        if (!s->nodes[n].dynamic)
            rt->static_count += lm_node_file_tris(s, &s->nodes[n]);
    rt->static_inst = RTC_INVALID_GEOMETRY_ID;
    if (rt->static_count == 0)
        return LM_OK;
    rt->static_tri = malloc(sizeof(uint32_t) * rt->static_count);
    if (!rt->static_tri)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for %u static triangles", s->path, rt->static_count);
    uint32_t k = 0;
    for (int n = 0; n < s->node_count; n++)
        if (!s->nodes[n].dynamic)
            for (uint32_t i = 0; i < lm_node_file_tris(s, &s->nodes[n]); i++)
                rt->static_tri[k++] = s->nodes[n].first_tri + i;
    RTCGeometry g = make_triangles(rt, s, rt->static_tri, rt->static_count, 1);
    if (!g)
        return fail_backend(rt, err, s->path);
    rt->static_ng = malloc(sizeof *rt->static_ng * rt->static_count);
    rt->static_ns = malloc(sizeof *rt->static_ns * rt->static_count);
    if (!rt->static_ng || !rt->static_ns) {
        rtcReleaseGeometry(g);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for %u static triangles", s->path, rt->static_count);
    }
    const float *vb = rtcGetGeometryBufferData(g, RTC_BUFFER_TYPE_VERTEX, 0);
    for (uint32_t i = 0; i < rt->static_count; i++) { /* the direction of Embree's Ng */
        lm_vec3 v0 = lm_v3_load(vb + 9 * (size_t)i), v1 = lm_v3_load(vb + 9 * (size_t)i + 3);
        lm_vec3 v2 = lm_v3_load(vb + 9 * (size_t)i + 6);
        lm_vec3 ng = lm_normalize(lm_cross(lm_sub(v1, v0), lm_sub(v2, v0)));
        lm_v3_store(rt->static_ng[i], ng);
        const uint32_t *idx = s->tris + 3 * (size_t)rt->static_tri[i];
        const float *n0 = s->normals + 3 * (size_t)idx[0];
        int flat = !memcmp(n0, s->normals + 3 * (size_t)idx[1], 3 * sizeof(float)) &&
                   !memcmp(n0, s->normals + 3 * (size_t)idx[2], 3 * sizeof(float));
        lm_vec3 ns = flat ? lm_shading_normal_of(rt->node_nmat[s->tri_node[rt->static_tri[i]]], lm_v3_load(n0), ng)
                          : lm_v3(NAN, NAN, NAN);
        lm_v3_store(rt->static_ns[i], ns);
    }
    /* The static triangles get a scene of their own, placed once with the identity: a top-level
     * commit after a dynamic node moves then rebuilds only the tree over the instances, never the
     * static triangles' BVH. */
    RTCScene world = rtcNewScene(rt->device);
    rtcSetSceneFlags(world, RTC_SCENE_FLAG_ROBUST);
    rtcAttachGeometry(world, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(world);
    float identity[16];
    lm_mat4_identity(identity);
    RTCGeometry inst = rtcNewGeometry(rt->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(inst, world);
    rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, identity);
    rtcCommitGeometry(inst);
    rt->static_inst = rtcAttachGeometry(rt->top, inst);
    rtcReleaseGeometry(inst);
    rtcReleaseScene(world);
    return LM_OK;
}

static lm_status add_instance(lm_rt *rt, const lm_scene *s, int n, lm_error *err)
{
    const lm_node *node = &s->nodes[n];
    uint32_t count = lm_node_file_tris(s, node); /* twins are found through their file triangle's back */
    uint32_t *ids = malloc(sizeof(uint32_t) * (count ? count : 1));
    if (!ids)
        return lm_fail(err, LM_ERR_NOMEM, "node '%s': no memory", node->name);
    for (uint32_t i = 0; i < count; i++)
        ids[i] = node->first_tri + i;
    RTCScene local = rtcNewScene(rt->device);
    rtcSetSceneFlags(local, RTC_SCENE_FLAG_ROBUST);
    RTCGeometry tg = make_triangles(rt, s, ids, count, 0);
    free(ids);
    if (!tg) {
        rtcReleaseScene(local);
        return fail_backend(rt, err, node->name);
    }
    rtcAttachGeometry(local, tg);
    rtcReleaseGeometry(tg);
    rtcCommitScene(local);

    RTCGeometry inst = rtcNewGeometry(rt->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(inst, local);
    rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, node->world);
    if (lm_mat4_singular(node->world))
        rtcDisableGeometry(inst); /* as move_instance: no inverse, no rays */
    rtcCommitGeometry(inst);
    unsigned id = rtcAttachGeometry(rt->top, inst);
    rtcReleaseGeometry(inst);
    rtcReleaseScene(local); /* the instance holds a reference */
    rt->inst_node[id] = n;
    rt->node_inst[n] = (int)id;
    memcpy(rt->inst_world[id], node->world, sizeof(float) * 16);
    lm_mat4_normal_matrix(node->world, rt->node_nmat[n]);
    return LM_OK;
}

static lm_status build(const lm_scene *s, const int *tri_surface, lm_rt **out, lm_error *err)
{
    *out = NULL;
    lm_rt_thread_init();
    lm_rt *rt = calloc(1, sizeof *rt);
    if (!rt)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the ray-tracing scene", s->path);
    rt->scene = s;
    rt->tri_surface = tri_surface;
    rt->device = rtcNewDevice(NULL);
    if (!rt->device) {
        free(rt);
        return lm_fail(err, LM_ERR_BACKEND, "cannot create an Embree device (error %d)", (int)rtcGetDeviceError(NULL));
    }
    rtcSetDeviceErrorFunction(rt->device, on_device_error, rt);
    rt->top = rtcNewScene(rt->device);
    rtcSetSceneFlags(rt->top, RTC_SCENE_FLAG_ROBUST);
    /* Geometry ids are dense from 0: at most one static geometry plus one per dynamic node. */
    size_t slots = (size_t)s->node_count + 1;
    rt->inst_node = malloc(sizeof(int) * slots);
    rt->node_inst = malloc(sizeof(int) * (s->node_count ? s->node_count : 1));
    rt->inst_world = malloc(sizeof(float[16]) * slots);
    rt->node_nmat = malloc(sizeof(float[9]) * (s->node_count ? s->node_count : 1));
    if (!rt->inst_node || !rt->node_inst || !rt->inst_world || !rt->node_nmat) {
        lm_rt_free(rt);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the ray-tracing scene", s->path);
    }
    for (size_t i = 0; i < slots; i++)
        rt->inst_node[i] = -1;
    for (int n = 0; n < s->node_count; n++) {
        rt->node_inst[n] = -1;
        lm_mat4_normal_matrix(s->nodes[n].world, rt->node_nmat[n]);
    }

    lm_status st = add_static(rt, s, err);
    for (int n = 0; st == LM_OK && n < s->node_count; n++)
        if (lm_node_moves(&s->nodes[n])) {
            st = add_instance(rt, s, n, err);
            rt->instance_count += st == LM_OK;
        }
    if (st == LM_OK) {
        commit_top(rt);
        if (rtcGetDeviceError(rt->device) != RTC_ERROR_NONE)
            st = fail_backend(rt, err, s->path);
    }
    if (st != LM_OK) {
        lm_rt_free(rt);
        return st;
    }
    *out = rt;
    return LM_OK;
}

lm_status lm_rt_build(const lm_scene *s, const lm_surfaces *su, lm_rt **out, lm_error *err)
{
    return build(s, su ? su->tri_surface : NULL, out, err);
}

lm_status lm_rt_rebuild(lm_rt *rt, lm_error *err)
{
    lm_rt *fresh = NULL;
    lm_status st = build(rt->scene, rt->tri_surface, &fresh, err);
    if (st != LM_OK)
        return st;
    lm_rt old = *rt; /* the new BVH moves into rt (whose address its users hold), the old one is freed */
    *rt = *fresh;
    *fresh = old;
    rt->top_commits += old.top_commits; /* the counters go on across the rebuild */
    rt->rebuilds = old.rebuilds + 1;
    rtcSetDeviceErrorFunction(rt->device, on_device_error, rt);
    lm_rt_free(fresh);
    return LM_OK;
}

void lm_rt_free(lm_rt *rt)
{
    if (!rt)
        return;
    if (rt->top)
        rtcReleaseScene(rt->top);
    if (rt->device)
        rtcReleaseDevice(rt->device);
    free(rt->static_tri);
    free(rt->static_ng);
    free(rt->static_ns);
    free(rt->inst_node);
    free(rt->node_inst);
    free(rt->inst_world);
    free(rt->node_nmat);
    free(rt);
}

static lm_status move_instance(lm_rt *rt, int node, const float world[16], lm_error *err)
{
    const lm_scene *s = rt->scene;
    if (node < 0 || node >= s->node_count)
        return lm_fail(err, LM_ERR_INVALID, "node id %d is out of range (scene has %d nodes)", node, s->node_count);
    if (rt->node_inst[node] < 0)
        return lm_fail(err, LM_ERR_INVALID, "node '%s' is static (or has no triangles) and cannot be moved; "
                       "mark it dynamic with extras {\"lmgi\": {\"dynamic\": true}}", s->nodes[node].name);
    if (!lm_mat4_finite(world))
        return lm_fail(err, LM_ERR_INVALID, "node '%s': transform has NaN or Inf entries", s->nodes[node].name);
    unsigned id = (unsigned)rt->node_inst[node];
    RTCGeometry inst = rtcGetGeometry(rt->top, id);
    /* A zero scale (an animation hiding a node) has no inverse, which Embree would need to take a ray into
     * the instance: the node is left out of the rays until its transform is regular again. */
    if (lm_mat4_singular(world))
        rtcDisableGeometry(inst);
    else
        rtcEnableGeometry(inst);
    rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, world);
    rtcCommitGeometry(inst);
    memcpy(rt->inst_world[id], world, sizeof(float) * 16);
    lm_mat4_normal_matrix(world, rt->node_nmat[node]);
    return LM_OK;
}

lm_status lm_rt_set_node_transform(lm_rt *rt, int node, const float world[16], lm_error *err)
{
    if (node >= 0 && node < rt->scene->node_count && lm_mat4_finite(world) && lm_mat4_singular(world))
        return lm_fail(err, LM_ERR_INVALID, "node '%s': transform is singular (a zero scale flattens the node)",
                       rt->scene->nodes[node].name);
    lm_status st = move_instance(rt, node, world, err);
    if (st == LM_OK)
        commit_top(rt);
    return st;
}

lm_status lm_rt_sync_transforms(lm_rt *rt, const lm_scene *s, lm_error *err)
{
    for (int n = 0; n < s->node_count; n++) {
        if (rt->node_inst[n] < 0)
            continue;
        lm_status st = move_instance(rt, n, s->nodes[n].world, err);
        if (st != LM_OK)
            return st;
    }
    commit_top(rt);
    return LM_OK;
}

static void setup_ray(struct RTCRayHit *rh, const float org[3], const float dir[3], float tnear, float tfar)
{
    memset(rh, 0, sizeof *rh);
    rh->ray.org_x = org[0];
    rh->ray.org_y = org[1];
    rh->ray.org_z = org[2];
    rh->ray.dir_x = dir[0];
    rh->ray.dir_y = dir[1];
    rh->ray.dir_z = dir[2];
    rh->ray.tnear = tnear;
    rh->ray.tfar = tfar;
    rh->ray.mask = 0xFFFFFFFFu;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/* Whether Embree may take the ray: finite origin and direction within its range (|x| <= 1.8e18, beyond
 * which it asserts and aborts the process), a non-zero direction, 0 <= tnear <= tfar (tfar may be +inf).
 * A ray that fails is answered as a miss: a library must not abort its host over one bad number. */
static int ray_ok(const float org[3], const float dir[3], float tnear, float tfar)
{
    const float big = 1.8e18f;
    for (int k = 0; k < 3; k++)
        if (!(fabsf(org[k]) <= big) || !(fabsf(dir[k]) <= big))
            return 0;
    return (dir[0] != 0.0f || dir[1] != 0.0f || dir[2] != 0.0f) && tnear >= 0.0f && tnear <= big && tfar >= tnear;
}

/* Embree's closest hit (instance inst, primitive prim, its Ng, t, u, v) along direction dir as lmgi's. */
static void decode_hit(const lm_rt *rt, const float dir[3], unsigned inst, unsigned prim, lm_vec3 ng_raw, float t,
                       float u, float v, lm_rt_hit *hit)
{
    lm_vec3 ng;
    if (inst != rt->static_inst) {
        int node = rt->inst_node[inst];
        hit->node = node;
        hit->tri = rt->scene->nodes[node].first_tri + prim;
        /* Embree's Ng is in the instance's space and follows the stored winding, which the loader reversed
         * for a node mirrored at load (lm_node.mirrored): the front is the side its file normals face,
         * through any later transform (nmat keeps that side) */
        ng = lm_normalize(lm_scale(lm_mat3_normal(rt->node_nmat[node], ng_raw), rt->scene->nodes[node].mirrored ? -1.0f : 1.0f));
        hit->ns = NULL;
    } else {
        hit->tri = rt->static_tri[prim];
        hit->node = (int)rt->scene->tri_node[hit->tri];
        ng = lm_v3_load(rt->static_ng[prim]);
        const float *ns = rt->static_ns[prim];
        hit->ns = isnan(ns[0]) ? NULL : ns;
    }
    hit->nmat = rt->node_nmat[hit->node];
    hit->t = t;
    hit->u = u;
    hit->v = v;
    const int32_t *twin = rt->scene->tri_twin;
    if (twin && twin[hit->tri] >= 0 && lm_dot(ng, lm_v3(dir[0], dir[1], dir[2])) > 0.0f) {
        /* the back of a split triangle is its twin: corners (0, 2, 1), so u and v swap */
        hit->tri = (uint32_t)twin[hit->tri];
        hit->u = v;
        hit->v = u;
        ng = lm_scale(ng, -1.0f);
        hit->ns = NULL;
    }
    hit->surface = rt->tri_surface ? rt->tri_surface[hit->tri] : -1;
    lm_v3_store(hit->ng, ng);
}

/* One ray's context and query, if Embree may take the ray (ray_ok): 0 if not. */
static int start_ray(struct RTCIntersectContext *ctx, struct RTCRayHit *rh, const float org[3], const float dir[3],
                     float tnear, float tfar)
{
    if (!ray_ok(org, dir, tnear, tfar))
        return 0;
    rtcInitIntersectContext(ctx);
    setup_ray(rh, org, dir, tnear, tfar);
    return 1;
}

int lm_rt_intersect(const lm_rt *rt, const float org[3], const float dir[3], float tnear, float tfar,
                    lm_rt_hit *hit)
{
    struct RTCIntersectContext ctx;
    struct RTCRayHit rh;
    if (!start_ray(&ctx, &rh, org, dir, tnear, tfar))
        return 0;
    rtcIntersect1(rt->top, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    decode_hit(rt, dir, rh.hit.instID[0], rh.hit.primID, lm_v3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z), rh.ray.tfar,
               rh.hit.u, rh.hit.v, hit);
    return 1;
}

void lm_rt_intersect16(const lm_rt *rt, const float *org, const float *dir, int n, lm_rt_hit *hits, int *hit)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    _Alignas(64) struct RTCRayHit16 r;
    _Alignas(64) int valid[16];
    memset(&r, 0, sizeof r);
    for (int i = 0; i < 16; i++) {
        int on = i < n && ray_ok(org + 3 * i, dir + 3 * i, 0.0f, INFINITY);
        valid[i] = on ? -1 : 0;
        r.ray.org_x[i] = on ? org[3 * i] : 0.0f, r.ray.org_y[i] = on ? org[3 * i + 1] : 0.0f;
        r.ray.org_z[i] = on ? org[3 * i + 2] : 0.0f;
        r.ray.dir_x[i] = on ? dir[3 * i] : 0.0f, r.ray.dir_y[i] = on ? dir[3 * i + 1] : 0.0f;
        r.ray.dir_z[i] = on ? dir[3 * i + 2] : 1.0f;
        r.ray.tfar[i] = on ? INFINITY : 0.0f;
        r.ray.mask[i] = 0xFFFFFFFFu;
        r.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        r.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, rt->top, &ctx, &r);
    for (int i = 0; i < n; i++) {
        hit[i] = valid[i] && r.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
        if (hit[i])
            decode_hit(rt, dir + 3 * i, r.hit.instID[0][i], r.hit.primID[i],
                       lm_v3(r.hit.Ng_x[i], r.hit.Ng_y[i], r.hit.Ng_z[i]), r.ray.tfar[i], r.hit.u[i], r.hit.v[i],
                       &hits[i]);
    }
}

int lm_rt_occluded(const lm_rt *rt, const float org[3], const float dir[3], float tnear, float tfar)
{
    struct RTCIntersectContext ctx;
    struct RTCRayHit rh;
    if (!start_ray(&ctx, &rh, org, dir, tnear, tfar))
        return 0;
    rtcOccluded1(rt->top, &ctx, &rh.ray);
    return rh.ray.tfar < 0.0f; /* Embree sets tfar to -inf on occlusion */
}

int lm_rt_covered(const lm_rt *rt, const float p[3], const float n[3], float lift, float cover)
{
    if (!(cover > 0.0f))
        return 0;
    float org[3];
    for (int c = 0; c < 3; c++)
        org[c] = p[c] + n[c] * lift;
    return lm_rt_occluded(rt, org, n, 0.0f, cover);
}

void lm_rt_occluded8(const lm_rt *rt, const float org[3], const float *dir, const float *tfar, int n, int *blocked)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT; /* one origin: the rays fan out together */
    _Alignas(32) struct RTCRay8 r;
    _Alignas(32) int valid[8];
    memset(&r, 0, sizeof r);
    for (int i = 0; i < 8; i++) {
        int on = i < n && ray_ok(org, dir + 3 * i, 0.0f, tfar[i]);
        valid[i] = on ? -1 : 0;
        r.org_x[i] = org[0], r.org_y[i] = org[1], r.org_z[i] = org[2];
        r.dir_x[i] = on ? dir[3 * i] : 0.0f, r.dir_y[i] = on ? dir[3 * i + 1] : 0.0f;
        r.dir_z[i] = on ? dir[3 * i + 2] : 1.0f;
        r.tnear[i] = 0.0f;
        r.tfar[i] = on ? tfar[i] : 0.0f;
        r.mask[i] = 0xFFFFFFFFu;
    }
    rtcOccluded8(valid, rt->top, &ctx, &r);
    for (int i = 0; i < n; i++)
        blocked[i] = r.tfar[i] < 0.0f; /* Embree sets tfar to -inf on occlusion */
}

uint64_t lm_rt_raw_intersect(const lm_rt *rt, const float *org, const float *dir, uint32_t n)
{
    uint64_t hits = 0;
#pragma omp parallel reduction(+ : hits)
    {
        lm_rt_thread_init();
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
#pragma omp for schedule(static)
        for (int64_t i = 0; i < (int64_t)n; i++) {
            struct RTCRayHit rh;
            setup_ray(&rh, org + 3 * i, dir + 3 * i, 0.0f, INFINITY);
            rtcIntersect1(rt->top, &ctx, &rh);
            hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
    }
    return hits;
}

uint32_t lm_rt_static_triangle_count(const lm_rt *rt) { return rt->static_count; }

uint64_t lm_rt_top_commits(const lm_rt *rt) { return rt->top_commits; }
uint64_t lm_rt_rebuilds(const lm_rt *rt) { return rt->rebuilds; }
