#include "args.h"
#include "progress.h"
#include "scene_load.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static int bad(const char *opt, const char *value, const char *want)
{
    fprintf(stderr, "lmgi: %s %s: expected %s\n", opt, value ? value : "(missing)", want);
    return 2;
}

static int parse_float(const char *opt, const char *v, float lo, float *out)
{
    char *end = NULL;
    if (!v)
        return bad(opt, v, "a number");
    errno = 0;
    double d = strtod(v, &end);
    if (errno || end == v || *end || !isfinite(d) || d < lo)
        return bad(opt, v, "a finite number");
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
        return bad(opt, v, want);
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
            return bad(opt, v, want);
        lm_cli_set_sky(LM_CLI_SKY_GRADIENT, zenith, horizon, NULL);
        return 0;
    }
    if (!end || *end)
        return bad(opt, v, want);
    lm_cli_set_sky(LM_CLI_SKY_UNIFORM, zenith, NULL, NULL);
    return 0;
}

static int parse_int(const char *opt, const char *v, int lo, int hi, int *out)
{
    char *end = NULL;
    if (!v)
        return bad(opt, v, "an integer");
    errno = 0;
    long l = strtol(v, &end, 10);
    if (errno || end == v || *end || l < lo || l > hi) {
        char want[64];
        snprintf(want, sizeof want, "an integer in [%d, %d]", lo, hi);
        return bad(opt, v, want);
    }
    *out = (int)l;
    return 0;
}

static int parse_size(const char *opt, const char *v, int *w, int *h)
{
    int used = -1;
    if (!v || sscanf(v, "%dx%d%n", w, h, &used) != 2 || used < 0 || v[used] || *w < 16 || *h < 16 || *w > 16384 ||
        *h > 16384)
        return bad(opt, v, "WxH with 16 <= W, H <= 16384");
    return 0;
}

/* Photon groups: 2^a 3^b (their Halton strata, docs/photons.md), checked here so that a bad value is a bad
 * command line (exit 2), not a scene that failed. */
static int parse_groups(const char *opt, const char *v, int *out)
{
    int rc = parse_int(opt, v, 1, 1 << 20, out);
    if (rc)
        return rc;
    int n = *out;
    while (n % 2 == 0)
        n /= 2;
    while (n % 3 == 0)
        n /= 3;
    return n == 1 ? 0 : bad(opt, v, "2^a 3^b groups (1, 2, 3, 4, 6, 8, 9, 12, ..., 72, ...) up to 2^20");
}

/* The word after an option that takes a value, or NULL when there is none or it is another option ("-q",
 * "--out"; a negative number is a value): `--out -q` must not make a directory named -q. */
static const char *value_after(int argc, char **argv, int i)
{
    const char *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (v && v[0] == '-' && v[1] && !(v[1] >= '0' && v[1] <= '9') && v[1] != '.')
        return NULL;
    return v;
}

static int add_file(const char **list, int *count, const char *f)
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
    return bad(o, v, "closed or drawn");
}

static int parse_tonemap(const char *o, const char *v, int *out)
{
    if (v && !strcmp(v, "neutral"))
        return *out = LMGI_TONEMAP_NEUTRAL, 0;
    if (v && !strcmp(v, "clamp"))
        return *out = LMGI_TONEMAP_CLAMP, 0;
    return bad(o, v, "neutral or clamp");
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
            return bad(o, v, "a list such as -shadows,-caustics,+reflections (each of shadows, indirect, "
                             "reflections, caustics with - to leave it out or + to keep it)");
        *off = *p == '-' ? *off | bits[k] : *off & ~bits[k];
        p += n + (p[n] == ',');
    }
    return v && *v ? 0 : bad(o, v, "a list such as -shadows,-indirect");
}

static int parse_caustic_space(const char *o, const char *v, int *out)
{
    if (v && !strcmp(v, "screen"))
        return *out = 0, 0;
    if (v && !strcmp(v, "world"))
        return *out = 1, 0;
    return bad(o, v, "screen or world");
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
    return bad(o, v, "lightmap, tiled, hashgrid or bruteforce");
}

static int parse_aim_direct(const char *o, const char *v, int *out)
{
    if (v && !strcmp(v, "emitters"))
        return *out = LMGI_AIM_DIRECT_EMITTERS, 0;
    if (v && !strcmp(v, "photons"))
        return *out = LMGI_AIM_DIRECT_PHOTONS, 0;
    if (v && !strcmp(v, "all"))
        return *out = LMGI_AIM_DIRECT_ALL, 0;
    return bad(o, v, "emitters, photons or all");
}

static int parse_scheme(const char *o, const char *v, int *out)
{
    static const char *names[] = {"viewports", "instanced", "layered", "rays"};
    for (int k = 0; v && k < 4; k++)
        if (!strcmp(v, names[k]))
            return *out = k, 0;
    return bad(o, v, "viewports, instanced, layered or rays");
}

int lm_cli_parse(int argc, char **argv, int first, lm_cli_args *a)
{
    memset(a, 0, sizeof *a);
    lmgi_options_init(&a->options);
    a->repeats = 3;
    a->camera = -1;
    a->gather_scheme = -1;
    a->emitter_light = -1;
    a->rim_samples = -1;
    a->reflection_size = -1;
    a->caustic_filter = -1;
    int rc = 0;
    for (int i = first; i < argc && rc == 0; i++) {
        const char *o = argv[i], *v = value_after(argc, argv, i);
        int takes = 1;
        if (!strcmp(o, "--texel-size"))
            rc = parse_float(o, v, 0.0f, &a->options.texel_size);
        else if (!strcmp(o, "--texels"))
            rc = parse_int(o, v, 16, 1 << 28, &a->options.target_texels);
        else if (!strcmp(o, "--gutter"))
            rc = parse_int(o, v, 0, 64, &a->options.gutter);
        else if (!strcmp(o, "--cone"))
            rc = parse_float(o, v, 0.0f, &a->options.surface_cone_deg);
        else if (!strcmp(o, "--max-atlas"))
            rc = parse_int(o, v, 64, 32768, &a->options.max_atlas_size);
        else if (!strcmp(o, "--out") || !strcmp(o, "-o"))
            rc = v ? (a->out_dir = v, 0) : bad(o, v, "a directory");
        else if (!strcmp(o, "--json"))
            rc = v ? (a->json_path = v, 0) : bad(o, v, "a file name");
        else if (!strcmp(o, "--size"))
            rc = parse_size(o, v, &a->width, &a->height);
        else if (!strcmp(o, "--repeats"))
            rc = parse_int(o, v, 1, 100, &a->repeats);
        else if (!strcmp(o, "--frames"))
            rc = parse_int(o, v, 1, 1000000, &a->frames);
        else if (!strcmp(o, "--seed"))
            rc = parse_int(o, v, 0, 2147483647, (int *)&a->seed);
        else if (!strcmp(o, "--photons"))
            rc = parse_int(o, v, 1, 100000000, &a->photons);
        else if (!strcmp(o, "--groups"))
            rc = parse_groups(o, v, &a->groups);
        else if (!strcmp(o, "--per-group"))
            rc = parse_int(o, v, 1, 10000000, &a->per_group);
        else if (!strcmp(o, "--retrace"))
            rc = parse_int(o, v, 1, 1000000, &a->retrace);
        else if (!strcmp(o, "--group-budget"))
            rc = parse_int(o, v, 0, 10000000, &a->group_budget);
        else if (!strcmp(o, "--nearest"))
            rc = parse_int(o, v, 1, 100000, &a->nearest);
        else if (!strcmp(o, "--surfaces-per-frame"))
            rc = parse_int(o, v, 0, 10000000, &a->surface_budget);
        else if (!strcmp(o, "--target-error"))
            rc = parse_float(o, v, 1e-6f, &a->target_error);
        else if (!strcmp(o, "--samples"))
            rc = parse_int(o, v, 1, 100000000, &a->samples);
        else if (!strcmp(o, "--caustic-photons"))
            rc = parse_int(o, v, 1, 1 << 24, &a->caustic_photons);
        else if (!strcmp(o, "--reference-caustic-photons"))
            rc = parse_int(o, v, 1, 1 << 24, &a->ref_caustic_photons);
        else if (!strcmp(o, "--sky"))
            rc = parse_sky(o, v);
        else if (!strcmp(o, "--checkpoint-seconds"))
            rc = parse_float(o, v, 0.0f, &a->checkpoint_seconds);
        else if (!strcmp(o, "--caustic-retrace"))
            rc = parse_float(o, v, 0.0f, &a->caustic_retrace) ? 2 : a->caustic_retrace > 0.0f && a->caustic_retrace <= 1.0f
                     ? 0 : bad(o, v, "a share of the caustic photons in (0, 1]");
        else if (!strcmp(o, "--caustic-filter"))
            rc = parse_int(o, v, 0, 8, &a->caustic_filter);
        else if (!strcmp(o, "--caustic-space"))
            rc = parse_caustic_space(o, v, &a->caustic_world);
        else if (!strcmp(o, "--caustic-tile"))
            rc = parse_int(o, v, 4, 256, &a->caustic_tile);
        else if (!strcmp(o, "--photon-tile"))
            rc = parse_int(o, v, 4, 32, &a->photon_tile) ? 2 : (a->photon_tile & (a->photon_tile - 1)) == 0
                     ? 0 : bad(o, v, "4, 8, 16 or 32 pixels");
        else if (!strcmp(o, "--photon-chunk"))
            rc = parse_int(o, v, 64, 512, &a->photon_chunk);
        else if (!strcmp(o, "--photon-stochastic"))
            rc = parse_int(o, v, 1, 4, &a->photon_stochastic);
        else if (!strcmp(o, "--photon-radius"))
            rc = parse_float(o, v, 0.0f, &a->photon_radius) ? 2 : a->photon_radius > 0.0f
                     ? 0 : bad(o, v, "a radius in scene units, above 0");
        else if (!strcmp(o, "--cache"))
            rc = v ? (a->cache_dir = v, 0) : bad(o, v, "a directory");
        else if (!strcmp(o, "--camera"))
            rc = parse_int(o, v, 0, 1000000, &a->camera);
        else if (!strcmp(o, "--texels-per-frame"))
            rc = parse_int(o, v, 1, 100000000, &a->texels_per_frame);
        else if (!strcmp(o, "--exr-every"))
            rc = parse_int(o, v, 1, 1000000, &a->exr_every);
        else if (!strcmp(o, "--hemicube"))
            rc = parse_int(o, v, 2, 1024, &a->hemicube);
        else if (!strcmp(o, "--hemicube-samples"))
            rc = parse_int(o, v, 1, 4, &a->hemicube_samples) ? 2 : (a->hemicube_samples == 2 || a->hemicube_samples == 3
                                                                       ? bad(o, v, "1 or 4") : 0);
        else if (!strcmp(o, "--hemicube-coverage"))
            rc = parse_int(o, v, 1, 16, &a->hemicube_coverage);
        else if (!strcmp(o, "--rim-samples"))
            rc = parse_int(o, v, 0, 65536, &a->rim_samples);
        else if (!strcmp(o, "--reflection-size"))
            rc = parse_int(o, v, 0, 4096, &a->reflection_size);
        else if (!strcmp(o, "--reflection-faces"))
            rc = parse_int(o, v, 1, 1 << 20, &a->reflection_faces);
        else if (!strcmp(o, "--enlargement"))
            rc = parse_float(o, v, 1e-3f, &a->enlargement);
        else if (!strcmp(o, "--gather-scheme"))
            rc = parse_scheme(o, v, &a->gather_scheme);
        else if (!strcmp(o, "--emitter-light"))
            rc = parse_emitter_light(o, v, &a->emitter_light);
        else if (!strcmp(o, "--effects")) /* its list starts with - or +: the word after it, whatever it is */
            rc = parse_effects(o, i + 1 < argc ? argv[i + 1] : NULL, &a->effects_off);
        else if (!strcmp(o, "--indirect"))
            rc = parse_indirect(o, v, &a->indirect);
        else if (!strcmp(o, "--aim-direct"))
            rc = parse_aim_direct(o, v, &a->aim_direct);
        else if (!strcmp(o, "--tonemap"))
            rc = parse_tonemap(o, v, &a->tonemap);
        else if (!strcmp(o, "--emitter-rays"))
            rc = parse_int(o, v, 1, 65536, &a->emitter_rays);
        else if (!strcmp(o, "--soak"))
            rc = parse_int(o, v, 1, 100000000, &a->soak);
        else if (!strcmp(o, "--knobs"))
            rc = v ? (a->knobs = v, 0) : bad(o, v, "a comma-separated list of knobs");
        else if (!strcmp(o, "--edits"))
            rc = v ? (a->edits_path = v, 0) : bad(o, v, "an edit script (JSON)");
        else if (!strcmp(o, "--gather-scene"))
            rc = v ? (a->gather_scene = v, 0) : bad(o, v, "a scene file");
        else if (!strcmp(o, "--scaling"))
            rc = v ? add_file(a->scaling, &a->scaling_count, v) : bad(o, v, "a scene file");
        else {
            takes = 0;
            if (!strcmp(o, "--use-uv1"))
                a->options.use_file_uv1 = 1;
            else if (!strcmp(o, "--strict"))
                a->options.strict = 1;
            else if (!strcmp(o, "--untrusted"))
                a->options.untrusted = 1;
            else if (!strcmp(o, "--in-order"))
                a->in_order = 1;
            else if (!strcmp(o, "--half"))
                a->half = 1;
            else if (!strcmp(o, "--gltf"))
                a->gltf = 1;
            else if (!strcmp(o, "--accuracy"))
                a->accuracy = 1;
            else if (!strcmp(o, "--resume"))
                a->resume = 1;
            else if (!strcmp(o, "--frame-lag"))
                a->frame_lag = 1;
            else if (!strcmp(o, "--force"))
                a->force = 1;
            else if (!strcmp(o, "--quick"))
                a->quick = 1;
            else if (!strcmp(o, "--no-cache"))
                a->no_cache = 1;
            else if (!strcmp(o, "-v") || !strcmp(o, "--verbose"))
                a->verbose = 1;
            else if (!strcmp(o, "-q") || !strcmp(o, "--quiet"))
                a->quiet = 1;
            else if (o[0] == '-' && o[1]) {
                fprintf(stderr, "lmgi: unknown option '%s' (see 'lmgi help')\n", o);
                rc = 2;
            } else
                rc = add_file(a->files, &a->file_count, o);
        }
        i += takes;
    }
    return rc;
}

int lm_cli_start(int argc, char **argv, void (*usage)(FILE *), lm_cli_args *a)
{
    if (argc < 2 || !strcmp(argv[1], "help") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    if (lm_cli_parse(argc, argv, 2, a))
        return 2;
    lmgi_set_verbosity(a->quiet ? 0 : a->verbose ? 2 : 1);
    lm_progress_quiet(a->quiet);
    return -1;
}
