/* The reference solver's driver: adaptive passes, stopping rule, results and cache (reference.h). */
#include "reference.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/log.h"
#include "../core/timing.h"
#include "../core/vecmath.h"
#include "ref_cache.h"
#include "ref_caustic.h"
#include "ref_paths.h"

#define LM_REF_DARK_FLOOR 0.01    /* relative errors are taken against max(mean, 1% of the mean entry) */
#define LM_REF_PROGRESS_SECONDS 3.0
#define LM_REF_POOL_RADIUS 2          /* pixels: the error pools the 5 x 5 around each (entry_errors) */
#define LM_REF_POOL_RADIUS_TEXELS 12  /* texels: the 25 around each in the atlas's order */

void lm_ref_settings_default(lm_ref_settings *s)
{
    memset(s, 0, sizeof *s);
    s->target_error = 0.02f;
    s->samples = 64;
    s->min_samples = 128;
    s->max_samples = 65536;
    s->seed = 1;
    s->max_depth = LM_REF_MAX_DEPTH;
    s->rr_depth = 3;
    s->caustic_photons = LM_REF_CAUSTIC_PHOTONS;
    s->use_cache = 1;
    s->progress = 1;
}

static double lum(const double c[3]) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

/* ---- per-entry statistics ---- */

typedef struct {
    uint32_t n, cut;
    double mean[2], m2[2];  /* Welford over the luminance of E_full [0] and E_iim [1] (texels) */
    double full[3];         /* RGB sums */
    double part[LM_REF_BACKWARD_PARTS][3];
} entry_stat;

static void stat_add(entry_stat *st, const lm_ref_sample *smp)
{
    const float *v[2] = {smp->full, smp->part[LM_REF_INDIRECT]};
    st->n++;
    st->cut += smp->cut;
    for (int w = 0; w < 2; w++) {
        double rgb[3] = {v[w][0], v[w][1], v[w][2]}, x = lum(rgb), d = x - st->mean[w];
        st->mean[w] += d / st->n;
        st->m2[w] += d * (x - st->mean[w]); /* Welford: M2 += (x - mean_old)(x - mean_new) */
    }
    for (int c = 0; c < 3; c++) {
        st->full[c] += smp->full[c];
        for (int p = 0; p < LM_REF_BACKWARD_PARTS; p++)
            st->part[p][c] += smp->part[p][c];
    }
}

/* Relative variance of one sample: M2 / (n - 1) / max(mean, floor)^2 (its standard error's square times n). */
static double rel_var(const entry_stat *st, int w, double floor)
{
    if (st->n < 2)
        return INFINITY;
    double var = fmax(0.0, st->m2[w]) / (st->n - 1.0), d = fmax(st->mean[w], floor);
    return d > 0.0 ? var / (d * d) : var > 0.0 ? INFINITY : 0.0;
}

static double entry_rel_var(const entry_stat *st, int has_iim, double floor)
{
    double v = rel_var(st, 0, floor);
    return has_iim ? fmax(v, rel_var(st, 1, floor)) : v;
}

/* ---- passes ---- */

typedef struct {
    const lm_ref_ctx *c;
    const lm_ref_settings *set;
    const lm_ref_frame *frames;  /* texels, else NULL */
    const lm_ref_frame *points;  /* texels: the atlas's footprint points (lm_atlas.footprints), if any */
    const lm_atlas *atlas;       /* texels, else NULL */
    const lm_view *cam;    /* pixels, else NULL */
    uint32_t count;
    entry_stat *st;
    double *rv, *err;            /* per entry, scratch: its relative variance, its pooled error (entry_errors) */
} job;

static void sample_entry(const job *j, uint32_t i, uint32_t k, lm_ref_sample *out)
{
    lm_ref_rng r;
    lm_ref_rng_seed(&r, j->set->seed, i, k);
    if (j->frames) { /* a texel gathered over its footprint: its samples taken at its points in turn */
        const lm_texel *first;
        uint32_t m = lm_texel_footprint(j->atlas, i, &first);
        lm_ref_texel_sample(j->c, m ? &j->points[first - j->atlas->footprints + k % m] : &j->frames[i], &r, out);
    }
    else
        lm_ref_pixel_sample(j->c, j->cam, (int)(i % (uint32_t)j->cam->width), (int)(i / (uint32_t)j->cam->width), &r,
                            out);
}

/* Paths for an entry this pass: `samples`, growing to n / 4 for entries that keep sampling (a few
 * dozen passes reach max_samples), never beyond max_samples. */
static uint32_t batch_size(const lm_ref_settings *set, uint32_t n)
{
    uint32_t b = (uint32_t)set->samples, grow = n / 4, left = (uint32_t)set->max_samples - n;
    b = grow > b ? grow : b;
    return b < left ? b : left;
}

static void run_pass(const job *j, const uint32_t *active, uint32_t na)
{
#pragma omp parallel
    {
        lm_rt_thread_init();
#pragma omp for schedule(dynamic, 4)
        for (long a = 0; a < (long)na; a++) {
            entry_stat *st = &j->st[active[a]];
            uint32_t batch = batch_size(j->set, st->n);
            for (uint32_t s = 0; s < batch; s++) {
                lm_ref_sample smp;
                sample_entry(j, active[a], st->n, &smp);
                stat_add(st, &smp);
            }
        }
    }
}

/* 1% of the mean luminance of E_full over all entries (summed in entry order). */
static double dark_floor(const job *j)
{
    double s = 0.0;
    for (uint32_t i = 0; i < j->count; i++)
        s += j->st[i].mean[0];
    return j->count ? LM_REF_DARK_FLOOR * s / j->count : 0.0;
}

/* Every entry's error, j->err: the relative standard error of its mean, sqrt(v / n), where v is the larger of
 * its own samples' relative variance and the mean of those of its neighbours (pixels: the 5 x 5 around it;
 * texels: the 12 before and after it in the atlas's order, along its chart's rows). A variance from a
 * pixel's own samples alone is low wherever the rare bright paths (a lamp's hot spot on the ceiling seen
 * by a bounce) have not been met yet: such a pixel looked converged and stopped early, and at a target of
 * 0.1 the generated Cornell box's reference read 4% dark, its surfaces up to 17%. Its neighbours that did
 * meet one keep it sampling. */
static void entry_errors(const job *j, double floor)
{
    int has_iim = j->frames != NULL;
    for (uint32_t i = 0; i < j->count; i++)
        j->rv[i] = entry_rel_var(&j->st[i], has_iim, floor);
    int w = j->cam ? j->cam->width : (int)j->count, h = j->cam ? j->cam->height : 1;
    int rx = j->cam ? LM_REF_POOL_RADIUS : LM_REF_POOL_RADIUS_TEXELS, ry = j->cam ? LM_REF_POOL_RADIUS : 0;
    for (uint32_t i = 0; i < j->count; i++) {
        int x = (int)(i % (uint32_t)w), y = (int)(i / (uint32_t)w);
        double sum = 0.0, own = j->rv[i];
        int k = 0;
        for (int yy = y - ry; yy <= y + ry; yy++)
            for (int xx = x - rx; xx <= x + rx; xx++)
                if (yy >= 0 && yy < h && xx >= 0 && xx < w) {
                    sum += j->rv[(size_t)yy * (size_t)w + (size_t)xx];
                    k++;
                }
        double v = fmax(own, sum / k); /* an infinite neighbour (one sample) keeps it going too */
        j->err[i] = j->st[i].n ? sqrt(v / j->st[i].n) : INFINITY;
    }
}

/* Entries that do not meet the stopping rule under the current floor. Every entry is checked, so one
 * stopped under an earlier (higher) floor resumes, and the final report holds the same rule. */
static uint32_t still_active(const job *j, uint32_t *active, double floor)
{
    uint32_t keep = 0, min = (uint32_t)j->set->min_samples;
    entry_errors(j, floor);
    for (uint32_t i = 0; i < j->count; i++) {
        const entry_stat *st = &j->st[i];
        int done = st->n >= (uint32_t)j->set->max_samples || (st->n >= min && j->err[i] <= j->set->target_error);
        if (!done)
            active[keep++] = i;
    }
    return keep;
}

/* Seconds left, estimated: an entry's standard error falls as 1 / sqrt(samples), so one at error e over
 * the target t needs about n (e / t)^2 samples in all (within max_samples); the samples still needed at
 * the rate so far. Rough while the errors themselves are noisy, it settles after the first passes. */
static double seconds_left(const job *j, const uint32_t *active, uint32_t na, double spent)
{
    double done = 0.0, needed = 0.0, t = j->set->target_error;
    for (uint32_t i = 0; i < j->count; i++)
        done += j->st[i].n;
    for (uint32_t a = 0; a < na; a++) {
        const entry_stat *st = &j->st[active[a]];
        double e = j->err[active[a]], want = st->n * (e / t) * (e / t);
        if (!(want <= j->set->max_samples)) /* also an error not yet finite */
            want = j->set->max_samples;
        want = fmax(want, j->set->min_samples);
        needed += fmax(0.0, want - st->n);
    }
    return done > 0.0 ? needed * spent / done : 0.0;
}

static void adaptive(const job *j, uint32_t *active)
{
    uint32_t na = j->count;
    for (uint32_t i = 0; i < na; i++)
        active[i] = i;
    double t0 = lm_now(), last = t0;
    for (int pass = 1; na > 0; pass++) {
        run_pass(j, active, na);
        double floor = dark_floor(j);
        na = still_active(j, active, floor);
        if (j->set->progress && na > 0 && lm_now() - last >= LM_REF_PROGRESS_SECONDS) {
            last = lm_now();
            lm_info("reference: pass %d, %.0f s: %u of %u %s still sampling, about %.0f s left", pass, last - t0, na,
                    j->count, j->frames ? "texels" : "pixels", seconds_left(j, active, na, last - t0));
        }
    }
}

/* ---- results ---- */

/* An entry's parts: the path tracer's means, and the light tracer's caustic, which full takes in. */
static void entry_result(const job *j, uint32_t i, const float *caustic, lm_ref_result *r)
{
    const entry_stat *st = &j->st[i];
    double inv = st->n ? 1.0 / st->n : 0.0;
    size_t at = 3 * (size_t)i;
    for (int c = 0; c < 3; c++) {
        r->full[at + c] = (float)(st->full[c] * inv + (double)caustic[at + c]);
        r->caustic[at + c] = caustic[at + c];
        r->direct[at + c] = (float)(st->part[LM_REF_DIRECT][c] * inv);
        r->lost[at + c] = (float)(st->part[LM_REF_LOST][c] * inv);
        if (j->frames) {
            r->iim[at + c] = (float)(st->part[LM_REF_INDIRECT][c] * inv);
            r->radiance[at + c] = j->frames[i].albedo[c] / LM_PI_F * r->full[at + c];
        } else {
            r->emission[at + c] = (float)(st->part[LM_REF_EMISSION][c] * inv);
            r->indirect[at + c] = (float)(st->part[LM_REF_INDIRECT][c] * inv);
            r->reflections[at + c] = (float)(st->part[LM_REF_REFLECTIONS][c] * inv);
        }
    }
}

static void finish(const job *j, const float *caustic, lm_ref_result *r)
{
    double sum_err = 0.0;
    entry_errors(j, dark_floor(j));
    for (uint32_t i = 0; i < j->count; i++) {
        const entry_stat *st = &j->st[i];
        double e = j->err[i];
        entry_result(j, i, caustic, r);
        r->samples[i] = st->n;
        r->rel_se[i] = (float)e;
        r->total_samples += st->n;
        r->paths_cut += st->cut;
        r->converged += e <= j->set->target_error;
        sum_err += e;
        r->max_rel_se = fmax(r->max_rel_se, e);
    }
    r->mean_rel_se = j->count ? sum_err / j->count : 0.0;
}

static lm_status check_settings(const lm_ref_settings *set, lm_error *err)
{
    if (!(set->target_error > 0.0f) || !isfinite(set->target_error) || set->samples < 1 ||
        set->max_samples < set->samples)
        return lm_fail(err, LM_ERR_INVALID,
                       "reference: invalid settings (target error %g, %d samples per pass, at most %d)",
                       (double)set->target_error, set->samples, set->max_samples);
    if (set->caustic_photons < 1 || set->caustic_photons > (1u << 24))
        return lm_fail(err, LM_ERR_INVALID, "reference: caustic photons per pair must be 1 to 16777216, not %u",
                       set->caustic_photons);
    return LM_OK;
}

/* The light tracer's caustic part of every entry into caustic (3 per entry). */
static lm_status caustic_part(const job *j, float *caustic, lm_ref_result *r, lm_error *err)
{
    double t0 = lm_now();
    lm_status st = j->frames ? lm_ref_caustic_texels(j->c, j->atlas, j->set, caustic, &r->caustic_photons, err)
                             : lm_ref_caustic_pixels(j->c, j->cam, j->set, caustic, &r->caustic_photons, err);
    r->caustic_seconds = lm_now() - t0;
    if (st == LM_OK && r->caustic_photons && j->set->progress)
        lm_info("reference: %llu caustic photons, %.1f s", (unsigned long long)r->caustic_photons, r->caustic_seconds);
    return st;
}

/* Runs the adaptive solver for a prepared job, then the caustic part, with the cache around them. */
static lm_status solve(job *j, uint32_t kind, uint64_t key, int width, int height, lm_ref_result *out, lm_error *err)
{
    char path[1200];
    lm_ref_cache_path(path, sizeof path, j->set, kind, key);
    if (j->set->use_cache && lm_ref_cache_load(path, kind, key, j->count, width, height, out)) {
        lm_info("reference: %u %s from the cache (%s)", j->count, kind == LM_REF_KIND_TEXELS ? "texels" : "pixels", path);
        return LM_OK;
    }
    memset(out, 0, sizeof *out);
    out->width = width, out->height = height, out->key = key;
    double t0 = lm_now();
    size_t n = j->count ? j->count : 1;
    j->st = calloc(n, sizeof *j->st);
    j->rv = malloc(n * sizeof *j->rv);
    j->err = malloc(n * sizeof *j->err);
    uint32_t *active = malloc(n * sizeof *active);
    float *caustic = malloc(n * 3 * sizeof *caustic);
    lm_status st = j->st && j->rv && j->err && active && caustic && lm_ref_result_alloc(out, j->count, kind == LM_REF_KIND_TEXELS)
                       ? LM_OK
                       : lm_fail(err, LM_ERR_NOMEM, "no memory for %u reference values", j->count);
    if (st == LM_OK) {
        adaptive(j, active);
        st = caustic_part(j, caustic, out, err);
    }
    if (st == LM_OK) {
        finish(j, caustic, out);
        out->seconds = lm_now() - t0;
        if (out->paths_cut)
            lm_warn("reference: %llu of %llu paths were still going after %d bounces and were cut: their light "
                    "past that is missing, so the reference is low (light that never dies out: a surface of "
                    "albedo 1 in a closed room?)", (unsigned long long)out->paths_cut,
                    (unsigned long long)out->total_samples, j->c->max_depth);
        if (j->set->use_cache)
            lm_ref_cache_store(path, kind, out);
    } else {
        lm_ref_result_free(out);
    }
    free(caustic);
    free(active);
    free(j->st);
    free(j->rv);
    free(j->err);
    j->st = NULL, j->rv = j->err = NULL;
    return st;
}

lm_status lm_reference_texels(const lm_scene *s, const lm_atlas *atlas, const lm_rt *rt, const lm_emitters *em,
                              const lm_ref_settings *set, lm_ref_result *out, lm_error *err)
{
    memset(out, 0, sizeof *out);
    lm_ref_settings fixed = *set;
    fixed.min_samples = fixed.min_samples > fixed.samples ? fixed.min_samples : fixed.samples;
    lm_status st = check_settings(&fixed, err);
    if (st != LM_OK)
        return st;
    lm_ref_ctx c;
    if ((st = lm_ref_ctx_init(&c, s, rt, em, &fixed, err)) != LM_OK)
        return st;
    lm_ref_frame *frames = malloc((atlas->texel_count ? atlas->texel_count : 1) * sizeof *frames);
    if (!frames) {
        lm_ref_ctx_free(&c);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for %u reference texels", s->path, atlas->texel_count);
    }
    lm_ref_frame *points = malloc((atlas->footprint_count ? atlas->footprint_count : 1) * sizeof *points);
    if (!points) {
        free(frames);
        lm_ref_ctx_free(&c);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for %u reference texels", s->path, atlas->texel_count);
    }
    for (uint32_t i = 0; i < atlas->texel_count; i++)
        lm_ref_texel_frame(&c, &atlas->texels[i], &frames[i]);
    for (uint32_t i = 0; i < atlas->footprint_count; i++)
        lm_ref_texel_frame(&c, &atlas->footprints[i], &points[i]);
    job j = {&c, &fixed, frames, points, atlas, NULL, atlas->texel_count, NULL, NULL, NULL};
    st = solve(&j, LM_REF_KIND_TEXELS, lm_ref_key_texels(s, atlas, &fixed), atlas->width, atlas->height, out, err);
    free(points);
    free(frames);
    lm_ref_ctx_free(&c);
    return st;
}

static lm_status check_camera(const lm_view *cam, lm_error *err)
{
    float f2 = cam->forward[0] * cam->forward[0] + cam->forward[1] * cam->forward[1] + cam->forward[2] * cam->forward[2];
    int finite = isfinite(cam->eye[0]) && isfinite(cam->eye[1]) && isfinite(cam->eye[2]) && isfinite(f2) &&
                 isfinite(cam->up[0]) && isfinite(cam->up[1]) && isfinite(cam->up[2]);
    if (!finite || !(f2 > 0.0f) || cam->width < 1 || cam->height < 1 || !(cam->yfov > 0.0f) || !(cam->yfov < 3.1f))
        return lm_fail(err, LM_ERR_INVALID, "reference: invalid camera (%d x %d, yfov %g)", cam->width, cam->height,
                       (double)cam->yfov);
    return LM_OK;
}

lm_status lm_reference_pixels(const lm_scene *s, const lm_rt *rt, const lm_emitters *em, const lm_view *cam,
                              const lm_ref_settings *set, lm_ref_result *out, lm_error *err)
{
    memset(out, 0, sizeof *out);
    lm_ref_settings fixed = *set;
    fixed.min_samples = fixed.min_samples > fixed.samples ? fixed.min_samples : fixed.samples;
    lm_status st = check_settings(&fixed, err);
    if (st == LM_OK)
        st = check_camera(cam, err);
    if (st != LM_OK)
        return st;
    lm_ref_ctx c;
    if ((st = lm_ref_ctx_init(&c, s, rt, em, &fixed, err)) != LM_OK)
        return st;
    job j = {&c, &fixed, NULL, NULL, NULL, cam, (uint32_t)cam->width * (uint32_t)cam->height, NULL, NULL, NULL};
    st = solve(&j, LM_REF_KIND_PIXELS, lm_ref_key_pixels(s, cam, &fixed), cam->width, cam->height, out, err);
    lm_ref_ctx_free(&c);
    return st;
}

int lm_ref_result_arrays(lm_ref_result *r, int texels, float **arrays[LM_REF_MAX_ARRAYS])
{
    int n = 0;
    arrays[n++] = &r->full;
    arrays[n++] = &r->direct;
    arrays[n++] = &r->caustic;
    arrays[n++] = &r->lost;
    if (texels) {
        arrays[n++] = &r->iim;
        arrays[n++] = &r->radiance;
    } else {
        arrays[n++] = &r->emission;
        arrays[n++] = &r->indirect;
        arrays[n++] = &r->reflections;
    }
    return n;
}

int lm_ref_result_alloc(lm_ref_result *r, uint32_t count, int texels)
{
    size_t n = count ? count : 1;
    float **arrays[LM_REF_MAX_ARRAYS];
    int k = lm_ref_result_arrays(r, texels, arrays), ok = 1;
    r->count = count;
    for (int i = 0; i < k; i++)
        ok &= (*arrays[i] = malloc(n * 3 * sizeof(float))) != NULL;
    r->samples = malloc(n * sizeof(uint32_t));
    r->rel_se = malloc(n * sizeof(float));
    return ok && r->samples && r->rel_se;
}

void lm_ref_result_free(lm_ref_result *r)
{
    float **arrays[LM_REF_MAX_ARRAYS];
    for (int k = 0; k < 2; k++) { /* a result of either kind: every array it may hold */
        int n = lm_ref_result_arrays(r, k, arrays);
        for (int i = 0; i < n; i++) {
            free(*arrays[i]);
            *arrays[i] = NULL;
        }
    }
    free(r->samples);
    free(r->rel_se);
    memset(r, 0, sizeof *r);
}

void lm_ref_texels_to_image(const lm_atlas *a, const float *values, float *rgb)
{
    memset(rgb, 0, (size_t)a->width * (size_t)a->height * 3 * sizeof(float));
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        memcpy(rgb + 3 * ((size_t)t->y * (size_t)a->width + (size_t)t->x), values + 3 * (size_t)i, 3 * sizeof(float));
    }
}

double lm_ref_relative_rmse(const float *est, const float *ref, const uint8_t *mask, size_t count, int channels)
{
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < count; i++) {
        if (mask && !mask[i])
            continue;
        for (int c = 0; c < channels; c++) {
            double e = est[i * (size_t)channels + (size_t)c], r = ref[i * (size_t)channels + (size_t)c];
            num += (e - r) * (e - r);
            den += r * r;
        }
    }
    if (den > 0.0)
        return sqrt(num / den);
    return num > 0.0 ? INFINITY : 0.0;
}
