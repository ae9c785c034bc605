#include "photon_path.h"

#include <stdlib.h>

#include "../core/hash.h"
#include "../photonmap/pixel_gather.h"

struct lm_photon_path {
    const lm_frame_loop_settings *set; /* the loop's, borrowed */
    const lm_world *w;                 /* the loop's, borrowed */
    const lm_photon_stage *stage;
    lm_photon_records records;
    lm_photon_gather *gather;
    float radius;         /* the kernel radius for the records held */
    uint32_t radius_live; /* the live records it was derived from */
    uint64_t key;         /* a hash of the records, view, size, radius and scene the last gather saw */
    int keyed;
    unsigned runs;        /* gathers run: turns the stochastic gather's classes */
    uint64_t coverage_key; /* the radius and node scales the direct pass's kernel coverage is for (0: none) */
};

lm_status lm_photon_path_create(const lm_world *w, const lm_photon_stage *stage, const lm_frame_loop_settings *set,
                                lm_photon_path **out, lm_error *err)
{
    *out = calloc(1, sizeof **out);
    if (!*out)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the photon path", w->scene->path);
    (*out)->set = set;
    (*out)->w = w;
    (*out)->stage = stage;
    return LM_OK;
}

void lm_photon_path_free(lm_photon_path *pp)
{
    if (!pp)
        return;
    lm_photon_gather_free(pp->gather);
    lm_photon_records_free(&pp->records);
    free(pp);
}

lm_status lm_photon_path_records(lm_photon_path *pp, lm_photon_gather_stats *stats, lm_error *err)
{
    const lm_photon_store *ps = lm_photons_store(lm_photon_stage_photons(pp->stage));
    lm_status st = LM_OK;
    if (!pp->gather) {
        lm_photon_gather_settings set = pp->set->photon_gather;
        set.kind = pp->set->indirect_path == LM_INDIRECT_HASHGRID     ? LM_PHOTON_GATHER_HASHGRID
                   : pp->set->indirect_path == LM_INDIRECT_BRUTEFORCE ? LM_PHOTON_GATHER_BRUTEFORCE
                                                                       : LM_PHOTON_GATHER_TILED;
        st = lm_photon_gather_create(&set, &pp->gather, err);
    }
    int fresh = !pp->records.rec || pp->records.store_version != ps->version;
    if (st == LM_OK && fresh)
        st = lm_photon_records_update(&pp->records, ps, pp->w->scene, err);
    if (st == LM_OK && fresh)
        st = lm_photon_gather_set_records(pp->gather, &pp->records, stats, err);
    /* The derived radius is kept until the gathered hits change by a tenth (its square root: 5%): a radius
     * that followed every re-traced photon would change the kernel, and so the picture and the coverage
     * atlas, every frame. */
    uint32_t live = pp->records.live, was = pp->radius_live;
    int drifted = live > was + was / 10 || was > live + live / 10;
    if (st == LM_OK && (!(pp->radius > 0.0f) || (fresh && drifted))) {
        pp->radius = pp->set->photon_radius > 0.0f ? pp->set->photon_radius
                                                   : lm_pixel_gather_radius(ps, pp->w->surfaces, LM_PIXEL_GATHER_HITS);
        pp->radius_live = live;
    }
    return st;
}

float lm_photon_path_radius(const lm_photon_path *pp) { return pp->radius; }

lm_status lm_photon_path_coverage(lm_photon_path *pp, lm_direct *direct, lm_error *err)
{
    uint64_t key = lm_hash_bytes(0x9e3779b97f4a7c15ull, &pp->radius, sizeof pp->radius);
    for (int i = 0; i < pp->w->scene->node_count; i++) {
        const float *m = pp->w->scene->nodes[i].world;
        float len2[3];
        for (int c = 0; c < 3; c++)
            len2[c] = m[4 * c] * m[4 * c] + m[4 * c + 1] * m[4 * c + 1] + m[4 * c + 2] * m[4 * c + 2];
        key = lm_hash_bytes(key, len2, sizeof len2);
    }
    if (key == pp->coverage_key || !(pp->radius > 0.0f))
        return LM_OK;
    float *c = malloc((size_t)(pp->w->atlas->texel_count ? pp->w->atlas->texel_count : 1) * sizeof *c);
    if (!c)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the coverage of %u texels", pp->w->atlas->texel_count);
    lm_status st = lm_aim_kernel_coverage(lm_photon_stage_aim(pp->stage), pp->w->scene, pp->w->surfaces, pp->w->atlas,
                                          pp->w->rt, pp->radius, c, err);
    if (st == LM_OK)
        st = lm_direct_set_coverage(direct, c, err);
    free(c);
    pp->coverage_key = st == LM_OK ? key : 0;
    return st;
}

lm_status lm_photon_path_draw(lm_photon_path *pp, lm_direct *direct, const lm_view *view, int w, int h,
                              lm_photon_gather_stats *stats, int *gathers, lm_error *err)
{
    if (!(pp->radius > 0.0f)) /* no photon the gather takes: no indirect light */
        return LM_OK;
    uint64_t key = lm_scene_world_hash(pp->w->scene);
    key = lm_hash_bytes(key, view->view, sizeof view->view);
    key = lm_hash_bytes(key, view->proj, sizeof view->proj);
    const int size[2] = {w, h};
    key = lm_hash_bytes(key, size, sizeof size);
    key = lm_hash_bytes(key, &pp->records.store_version, sizeof pp->records.store_version);
    key = lm_hash_bytes(key, &pp->radius, sizeof pp->radius);
    key = lm_hash_bytes(key, &pp->w->scene->material_version, sizeof pp->w->scene->material_version);
    key = lm_hash_bytes(key, &pp->w->scene->pass_version, sizeof pp->w->scene->pass_version);
    unsigned kd = lm_direct_kd_texture(direct, 0), gbuf = lm_direct_gbuffer_texture(direct);
    lm_status st = LM_OK;
    if (!pp->keyed || key != pp->key) {
        st = lm_photon_gather_run(pp->gather, view, w, h, kd, gbuf, pp->radius, pp->runs++, stats, err);
        (*gathers)++;
        pp->key = key;
        pp->keyed = st == LM_OK;
    }
    if (st == LM_OK)
        st = lm_photon_gather_composite(pp->gather, lm_direct_radiance_texture(direct), kd, gbuf, err);
    return st;
}
