/* The values options take (option_values.h): numbers in range, sizes, skies, lists and names. */
#include "option_values.h"

#include "scene_load.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

int lm_cli_bad(const char *opt, const char *value, const char *want)
{
    fprintf(stderr, "lmgi: %s %s: expected %s\n", opt, value ? value : "(missing)", want);
    return 2;
}

int lm_cli_parse_float(const char *opt, const char *v, float lo, float *out)
{
    char *end = NULL;
    if (!v)
        return lm_cli_bad(opt, v, "a number");
    errno = 0;
    double d = strtod(v, &end);
    if (errno || end == v || *end || !isfinite(d) || d < lo)
        return lm_cli_bad(opt, v, "a finite number");
    *out = (float)d;
    return 0;
}

/* One radiance, L or R,G,B (finite, in [0, 1e20]), from p into rgb; the end of what it read in *end, NULL if
 * it is not one. */
static const char *parse_radiance(const char *p, float rgb[3])
{
    int n = 0;
    char *end = NULL;
    for (;; n++) {
        errno = 0;
        double d = strtod(p, &end);
        if (errno || end == p || !isfinite(d) || d < 0.0 || d > 1e20 || n > 2)
            return NULL;
        rgb[n] = (float)d;
        if (*end != ',')
            break;
        p = end + 1;
    }
    if (n != 0 && n != 2)
        return NULL;
    if (n == 0)
        rgb[1] = rgb[2] = rgb[0];
    return end;
}

/* --sky L | R,G,B (uniform) | R,G,B/R,G,B (zenith/horizon: a gradient) | FILE.hdr or FILE.exr (an
 * equirectangular HDR image). */
static int parse_sky(const char *opt, const char *v)
{
    static const char want[] = "a radiance L or R,G,B, a gradient ZENITH/HORIZON of two, or an HDR image "
                               "(.hdr, .exr); radiances finite numbers in [0, 1e20]";
    if (!v)
        return lm_cli_bad(opt, v, want);
    size_t len = strlen(v);
    if (len > 4 && (!strcasecmp(v + len - 4, ".hdr") || !strcasecmp(v + len - 4, ".exr"))) {
        lm_cli_set_sky(LM_CLI_SKY_IMAGE, NULL, NULL, v);
        return 0;
    }
    float zenith[3], horizon[3];
    const char *end = parse_radiance(v, zenith);
    if (end && *end == '/') {
        end = parse_radiance(end + 1, horizon);
        if (!end || *end)
            return lm_cli_bad(opt, v, want);
        lm_cli_set_sky(LM_CLI_SKY_GRADIENT, zenith, horizon, NULL);
        return 0;
    }
    if (!end || *end)
        return lm_cli_bad(opt, v, want);
    lm_cli_set_sky(LM_CLI_SKY_UNIFORM, zenith, NULL, NULL);
    return 0;
}

int lm_cli_parse_int(const char *opt, const char *v, int lo, int hi, int *out)
{
    char *end = NULL;
    if (!v)
        return lm_cli_bad(opt, v, "an integer");
    errno = 0;
    long l = strtol(v, &end, 10);
    if (errno || end == v || *end || l < lo || l > hi) {
        char want[64];
        snprintf(want, sizeof want, "an integer in [%d, %d]", lo, hi);
        return lm_cli_bad(opt, v, want);
    }
    *out = (int)l;
    return 0;
}

static int parse_size(const char *opt, const char *v, int *w, int *h)
{
    int used = -1;
    if (!v || sscanf(v, "%dx%d%n", w, h, &used) != 2 || used < 0 || v[used] || *w < 16 || *h < 16 || *w > 16384 ||
        *h > 16384)
        return lm_cli_bad(opt, v, "WxH with 16 <= W, H <= 16384");
    return 0;
}

/* Photon groups: 2^a 3^b (their Halton strata, docs/photons.md), checked here so that a bad value is a bad
 * command line (exit 2), not a scene that failed. */
static int parse_groups(const char *opt, const char *v, int *out)
{
    int rc = lm_cli_parse_int(opt, v, 1, 1 << 20, out);
    if (rc)
        return rc;
    int n = *out;
    while (n % 2 == 0)
        n /= 2;
    while (n % 3 == 0)
        n /= 3;
    return n == 1 ? 0 : lm_cli_bad(opt, v, "2^a 3^b groups (1, 2, 3, 4, 6, 8, 9, 12, ..., 72, ...) up to 2^20");
}

int lm_cli_add_file(const char **list, int *count, const char *f)
{
    if (*count >= LM_CLI_MAX_FILES) {
        fprintf(stderr, "lmgi: too many files (at most %d)\n", LM_CLI_MAX_FILES);
        return 2;
    }
    list[(*count)++] = f;
    return 0;
}

/* --emitter-light closed|drawn: 1 or 0 (unset: -1, the frame loop's choice per scene). */
static int parse_emitter_light(const char *o, const char *v, int *out)
{
    if (v && !strcmp(v, "closed"))
        return *out = 1, 0;
    if (v && !strcmp(v, "drawn"))
        return *out = 0, 0;
    return lm_cli_bad(o, v, "closed or drawn");
}

static int parse_tonemap(const char *o, const char *v, int *out)
{
    if (v && !strcmp(v, "neutral"))
        return *out = LMGI_TONEMAP_NEUTRAL, 0;
    if (v && !strcmp(v, "clamp"))
        return *out = LMGI_TONEMAP_CLAMP, 0;
    return lm_cli_bad(o, v, "neutral or clamp");
}

/* A comma-separated list of -effect (left out) or +effect (kept), effect one of shadows, indirect,
 * reflections, caustics: the effects_off bits of lmgi_updater_desc. */
static int parse_effects(const char *o, const char *v, unsigned *off)
{
    static const char *names[4] = {"shadows", "indirect", "reflections", "caustics"};
    static const unsigned bits[4] = {LMGI_EFFECT_SHADOWS, LMGI_EFFECT_INDIRECT, LMGI_EFFECT_REFLECTIONS,
                                     LMGI_EFFECT_CAUSTICS};
    const char *p = v;
    while (p && *p) {
        size_t n = strcspn(p, ",");
        int k = 0;
        while (k < 4 && !(n == strlen(names[k]) + 1 && !strncmp(p + 1, names[k], n - 1)))
            k++;
        if (k == 4 || (*p != '-' && *p != '+'))
            return lm_cli_bad(o, v, "a list such as -shadows,-caustics,+reflections (each of shadows, indirect, "
                             "reflections, caustics with - to leave it out or + to keep it)");
        *off = *p == '-' ? *off | bits[k] : *off & ~bits[k];
        p += n + (p[n] == ',');
    }
    return v && *v ? 0 : lm_cli_bad(o, v, "a list such as -shadows,-indirect");
}

static int parse_caustic_space(const char *o, const char *v, int *out)
{
    if (v && !strcmp(v, "screen"))
        return *out = 0, 0;
    if (v && !strcmp(v, "world"))
        return *out = 1, 0;
    return lm_cli_bad(o, v, "screen or world");
}

static int parse_indirect(const char *o, const char *v, int *out)
{
    if (v && !strcmp(v, "lightmap"))
        return *out = LMGI_INDIRECT_LIGHTMAP, 0;
    if (v && !strcmp(v, "bruteforce"))
        return *out = LMGI_INDIRECT_BRUTEFORCE, 0;
    if (v && !strcmp(v, "tiled"))
        return *out = LMGI_INDIRECT_TILED, 0;
    if (v && !strcmp(v, "hashgrid"))
        return *out = LMGI_INDIRECT_HASHGRID, 0;
    return lm_cli_bad(o, v, "lightmap, tiled, hashgrid or bruteforce");
}

static int parse_aim_direct(const char *o, const char *v, int *out)
{
    if (v && !strcmp(v, "emitters"))
        return *out = LMGI_AIM_DIRECT_EMITTERS, 0;
    if (v && !strcmp(v, "photons"))
        return *out = LMGI_AIM_DIRECT_PHOTONS, 0;
    if (v && !strcmp(v, "all"))
        return *out = LMGI_AIM_DIRECT_ALL, 0;
    return lm_cli_bad(o, v, "emitters, photons or all");
}

static int parse_scheme(const char *o, const char *v, int *out)
{
    static const char *names[] = {"viewports", "instanced", "layered", "rays"};
    for (int k = 0; v && k < 4; k++)
        if (!strcmp(v, names[k]))
            return *out = k, 0;
    return lm_cli_bad(o, v, "viewports, instanced, layered or rays");
}


/* ---- the table's custom parsers (options.c): each takes the option, its value and the arguments ---- */

int lm_cli_opt_sky(const char *o, const char *v, lm_cli_args *a) { (void)a; return parse_sky(o, v); }
int lm_cli_opt_size(const char *o, const char *v, lm_cli_args *a) { return parse_size(o, v, &a->width, &a->height); }
int lm_cli_opt_groups(const char *o, const char *v, lm_cli_args *a) { return parse_groups(o, v, &a->groups); }
int lm_cli_opt_emitter_light(const char *o, const char *v, lm_cli_args *a)
{
    return parse_emitter_light(o, v, &a->emitter_light);
}
int lm_cli_opt_tonemap(const char *o, const char *v, lm_cli_args *a) { return parse_tonemap(o, v, &a->tonemap); }
int lm_cli_opt_effects(const char *o, const char *v, lm_cli_args *a) { return parse_effects(o, v, &a->effects_off); }
int lm_cli_opt_caustic_space(const char *o, const char *v, lm_cli_args *a)
{
    return parse_caustic_space(o, v, &a->caustic_world);
}
int lm_cli_opt_indirect(const char *o, const char *v, lm_cli_args *a) { return parse_indirect(o, v, &a->indirect); }
int lm_cli_opt_aim_direct(const char *o, const char *v, lm_cli_args *a) { return parse_aim_direct(o, v, &a->aim_direct); }
int lm_cli_opt_scheme(const char *o, const char *v, lm_cli_args *a) { return parse_scheme(o, v, &a->gather_scheme); }

int lm_cli_opt_scaling(const char *o, const char *v, lm_cli_args *a)
{
    return v ? lm_cli_add_file(a->scaling, &a->scaling_count, v) : lm_cli_bad(o, v, "a scene file");
}

int lm_cli_opt_seed(const char *o, const char *v, lm_cli_args *a)
{
    int seed = 0, rc = lm_cli_parse_int(o, v, 0, 2147483647, &seed);
    a->seed = (unsigned)seed;
    return rc;
}

int lm_cli_opt_caustic_retrace(const char *o, const char *v, lm_cli_args *a)
{
    if (lm_cli_parse_float(o, v, 0.0f, &a->caustic_retrace))
        return 2;
    return a->caustic_retrace > 0.0f && a->caustic_retrace <= 1.0f
               ? 0 : lm_cli_bad(o, v, "a share of the caustic photons in (0, 1]");
}

int lm_cli_opt_photon_tile(const char *o, const char *v, lm_cli_args *a)
{
    if (lm_cli_parse_int(o, v, 4, 32, &a->photon_tile))
        return 2;
    return (a->photon_tile & (a->photon_tile - 1)) == 0 ? 0 : lm_cli_bad(o, v, "4, 8, 16 or 32 pixels");
}

int lm_cli_opt_hemicube_samples(const char *o, const char *v, lm_cli_args *a)
{
    if (lm_cli_parse_int(o, v, 1, 4, &a->hemicube_samples))
        return 2;
    return a->hemicube_samples == 2 || a->hemicube_samples == 3 ? lm_cli_bad(o, v, "1 or 4") : 0;
}

int lm_cli_opt_photon_radius(const char *o, const char *v, lm_cli_args *a)
{
    if (lm_cli_parse_float(o, v, 0.0f, &a->photon_radius))
        return 2;
    return a->photon_radius > 0.0f ? 0 : lm_cli_bad(o, v, "a radius in scene units, above 0");
}
