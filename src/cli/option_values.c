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
    if (errno || end == v || *end || !isfinite(d))
        return lm_cli_bad(opt, v, "a finite number");
    if (d < lo) { /* "-1" is a number: say which it must be (the range, where a knob has one, is checked later) */
        char want[48];
        snprintf(want, sizeof want, "a number of at least %g", (double)lo);
        return lm_cli_bad(opt, v, want);
    }
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
int lm_cli_opt_sky(const char *opt, const char *v, lm_cli_args *a)
{
    (void)a; /* the sky goes to the scene loader (lm_cli_set_sky) */
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

int lm_cli_opt_size(const char *opt, const char *v, lm_cli_args *a)
{
    int used = -1, *w = &a->width, *h = &a->height;
    if (!v || sscanf(v, "%dx%d%n", w, h, &used) != 2 || used < 0 || v[used] || *w < 16 || *h < 16 || *w > 16384 ||
        *h > 16384)
        return lm_cli_bad(opt, v, "WxH with 16 <= W, H <= 16384");
    return 0;
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

int lm_cli_choose(const char *o, const char *v, const char *const names[], const int values[], int n, int *out)
{
    for (int k = 0; v && k < n; k++)
        if (!strcmp(v, names[k]))
            return *out = values[k], 0;
    char want[160];
    size_t used = 0;
    for (int k = 0; k < n && used < sizeof want; k++) {
        int w = snprintf(want + used, sizeof want - used, "%s%s", k == 0 ? "" : k == n - 1 ? " or " : ", ", names[k]);
        used += w > 0 ? (size_t)w : 0;
    }
    return lm_cli_bad(o, v, want);
}

int lm_cli_opt_tonemap(const char *o, const char *v, lm_cli_args *a)
{
    static const char *const names[] = {"neutral", "clamp"};
    static const int values[] = {LMGI_TONEMAP_NEUTRAL, LMGI_TONEMAP_CLAMP};
    return lm_cli_choose(o, v, names, values, 2, &a->tonemap);
}

/* A comma-separated list of -effect (left out) or +effect (kept), effect one of shadows, indirect,
 * reflections, caustics: the effects_off bits of lmgi_updater_desc. */
int lm_cli_opt_effects(const char *o, const char *v, lm_cli_args *a)
{
    unsigned *off = &a->desc.effects_off;
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

int lm_cli_opt_indirect(const char *o, const char *v, lm_cli_args *a)
{
    static const char *const names[] = {"lightmap", "tiled", "hashgrid", "bruteforce"};
    static const int values[] = {LMGI_INDIRECT_LIGHTMAP, LMGI_INDIRECT_TILED, LMGI_INDIRECT_HASHGRID,
                                 LMGI_INDIRECT_BRUTEFORCE};
    return lm_cli_choose(o, v, names, values, 4, (int *)&a->desc.indirect);
}

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

int lm_cli_opt_shard(const char *o, const char *v, lm_cli_args *a)
{
    int k = 0, n = 0, used = 0;
    if (!v || sscanf(v, "%d/%d%n", &k, &n, &used) != 2 || v[used] != '\0' || n < 1 || n > 4096 || k < 1 || k > n)
        return lm_cli_bad(o, v, "K/N: share K of N, 1 <= K <= N <= 4096 (e.g. 2/8)");
    a->shard = k;
    a->shards = n;
    return 0;
}

/* "off" (LMGI_OFF) or a number in (0, most] into *out; else refused with `want` as what was wanted. */
static int number_or_off(const char *o, const char *v, double most, const char *want, float *out)
{
    if (v && !strcmp(v, "off")) {
        *out = (float)LMGI_OFF;
        return 0;
    }
    char *end = NULL;
    double d = v ? strtod(v, &end) : 0.0;
    if (!v || end == v || *end || !(d > 0.0 && d <= most))
        return lm_cli_bad(o, v, want);
    *out = (float)d;
    return 0;
}

int lm_cli_opt_open_need(const char *o, const char *v, lm_cli_args *a)
{
    return number_or_off(o, v, 1.0, "a fraction in (0, 1], or off", &a->options.open_need);
}

int lm_cli_opt_bend(const char *o, const char *v, lm_cli_args *a)
{
    return number_or_off(o, v, 180.0, "degrees in (0, 180], or off", &a->options.bend_deg);
}
