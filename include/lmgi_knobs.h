/* lmgi — the updater's tuning knobs, in one table (included by lmgi.h; not a header of its own).
 *
 * Each knob is one line of an X-macro list, per stage of the pipeline, and everything else is made from
 * those lines: the stage's struct in lmgi_updater_desc (`desc.gather.rim_samples`), the library's
 * validation of a desc and its resolved defaults (lmgi_updater_defaults, lmgi_get_updater_info), and the
 * lmgi command's options, their help and the knobs `lmgi tradeoff` sweeps. A new knob is a line here plus
 * its use (where the stage reads it).
 *
 * The line: X(stage, field, kind, ctype, def, lo, hi, off, rule, flag, arg, cli_zero, choices, sweep, help)
 *   stage, field  the desc's member `stage.field` (stage: photons, aim, gather, caustics, frame, tiled)
 *   kind          LMGI_KNOB_INT (an int in [lo, hi]), _COUNT (a uint32_t in [lo, hi]), _REAL (a float
 *                 in [lo, hi]), _CHOICE (one of `choices`' values), _SWITCH (LMGI_ON or LMGI_OFF)
 *   ctype         the member's C type
 *   def           what 0 means, the default (0: chosen per scene, see the help)
 *   lo, hi        the valid range besides 0 (and LMGI_OFF where `off` is 1)
 *   off           1: LMGI_OFF is a value, the help says what it means; 0: none
 *   rule          LMGI_RULE(test of v, "what it wants") beyond the range, or LMGI_NO_RULE
 *   flag, arg     the lmgi command's option ("--rim-samples", "K"); NULL: none (or one of its own)
 *   cli_zero      what the option's value 0 means: LMGI_CLI_ZERO_NONE (refused), _OFF (LMGI_OFF), or
 *                 _DEFAULT (the default)
 *   choices       for a CHOICE or a named SWITCH: a list Y(name, value) of the option's names (the
 *                 order of its messages), else LMGI_NO_CHOICES
 *   sweep         LMGI_SWEEP(order, "key", "label", (full values), (--quick values), when) when `lmgi
 *                 tradeoff` sweeps it (docs/tradeoff.md; when: 0 always, 1 with caustics, 2 with the
 *                 tiled gather's radius), else LMGI_NO_SWEEP
 *   help          the option's help, lines joined by '\n' (the first beside the option's name); the values
 *                 it names are the option's, whose 0 is LMGI_OFF where cli_zero says so
 *
 * 0 always means the default; "off" is LMGI_OFF, never a count of 0. Every field not in the table (the
 * frame's size and camera, callbacks, checkpoints, shards) is written out in lmgi.h. */
#ifndef LMGI_KNOBS_H
#define LMGI_KNOBS_H

#include <math.h>

/* A knob's explicit "off" (its help says what that is: none, all at once, no filter, ...), and "on" for a
 * switch. 0 is never off: it is the default. */
#define LMGI_OFF (-1)
#define LMGI_ON 1

enum { LMGI_KNOB_INT, LMGI_KNOB_COUNT, LMGI_KNOB_REAL, LMGI_KNOB_CHOICE, LMGI_KNOB_SWITCH };
enum { LMGI_CLI_ZERO_NONE, LMGI_CLI_ZERO_OFF, LMGI_CLI_ZERO_DEFAULT };

/* The rules beyond a range. */
static inline int lmgi_knob_is_2a3b(double v)
{
    long n = (long)v;
    while (n > 1 && n % 2 == 0)
        n /= 2;
    while (n > 1 && n % 3 == 0)
        n /= 3;
    return n == 1 && (double)(long)v == v;
}
static inline int lmgi_knob_is_pow2(double v)
{
    long n = (long)v;
    return n > 0 && (n & (n - 1)) == 0 && (double)n == v;
}

/* The columns that hold several values come as parenthesised lists, for a generator to take apart:
 * LMGI_RULE's test reads the value as a double named v. */
#define LMGI_RULE(test, text) (test, text)
#define LMGI_NO_RULE (1, NULL)
#define LMGI_SWEEP(order, key, label, full, quick, when) (order, key, label, full, quick, when)
#define LMGI_NO_SWEEP (0, NULL, NULL, (), (), 0)

#define LMGI_NO_CHOICES(Y)
#define LMGI_AIM_DIRECT_CHOICES(Y)                                                                                    \
    Y("suns", LMGI_AIM_DIRECT_SUNS) Y("emitters", LMGI_AIM_DIRECT_EMITTERS) Y("photons", LMGI_AIM_DIRECT_PHOTONS) Y("all", LMGI_AIM_DIRECT_ALL)
#define LMGI_GATHER_SCHEME_CHOICES(Y)                                                                                 \
    Y("viewports", LMGI_GATHER_VIEWPORTS) Y("instanced", LMGI_GATHER_INSTANCED) Y("layered", LMGI_GATHER_LAYERED)     \
    Y("rays", LMGI_GATHER_RAYS)
#define LMGI_EMITTER_LIGHT_CHOICES(Y) Y("closed", LMGI_EMITTERS_CLOSED_FORM) Y("drawn", LMGI_EMITTERS_DRAWN)
#define LMGI_ON_OFF_CHOICES(Y) Y("on", LMGI_ON) Y("off", LMGI_OFF)
#define LMGI_CAUSTIC_SPACE_CHOICES(Y) Y("screen", LMGI_OFF) Y("world", LMGI_ON)

/* photons (docs/photons.md): each light's photons, their groups and how many are re-traced */
#define LMGI_PHOTON_KNOBS(X)                                                                                          \
    /* count 0: groups x per_group a light, and at least 46,080 over the scene unless per_group is */                 \
    /* given: a scene with one light gets 640 a group (docs/tradeoff.md, "Defaults against the front") */             \
    X(photons, count, LMGI_KNOB_COUNT, uint32_t, 0, 1, 100000000, 0, LMGI_NO_RULE, "--photons", "N",                \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                          \
      "total photon budget (default: groups x per-group, at least 46,080; bake: 16 a\n"                            \
      "texel of the atlas, run and check where more: 4 a texel; up to 1,048,576)")                                 \
    X(photons, groups, LMGI_KNOB_COUNT, uint32_t, 72, 1, 1 << 20, 0,                                               \
      LMGI_RULE(lmgi_knob_is_2a3b(v), "2^a 3^b groups (1, 2, 3, 4, 6, 8, 9, 12, ..., 72, ...) up to 2^20"),       \
      "--groups", "G", LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES,                                                        \
      LMGI_SWEEP(2, "groups", "groups per light", (18, 36, 72, 144, 288), (18, 72, 288), 0),                     \
      "photon groups, 2^a 3^b (default 72)")                                                                       \
    X(photons, per_group, LMGI_KNOB_COUNT, uint32_t, 0, 1, 10000000, 0, LMGI_NO_RULE, "--per-group", "M",         \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES,                                                                         \
      LMGI_SWEEP(1, "photons_per_group", "photons per group", (40, 80, 160, 320, 640), (40, 160, 640), 0),      \
      "photons per group")                                                                                         \
    X(photons, retrace_per_group, LMGI_KNOB_COUNT, uint32_t, 1, 1, 1000000, 0, LMGI_NO_RULE, "--retrace", "K",   \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                          \
      "photons per group re-traced a frame, round robin, while anything can move\n"                               \
      "(default 1)")                                                                                               \
    X(photons, group_budget, LMGI_KNOB_INT, int, 16, 1, 10000000, 1, LMGI_NO_RULE, "--group-budget", "B",         \
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                           \
      "invalid photon groups re-traced a frame, oldest first (default 16; 0: every\n"                             \
      "one at once; a node moved after a still frame: all its groups at once)")                                  \
    X(photons, seed, LMGI_KNOB_COUNT, uint32_t, 0, 0, 4294967295.0, 0, LMGI_NO_RULE, NULL, NULL,                   \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                          \
      "another, disjoint stretch of the Halton sequence, and other sample patterns in\n"                         \
      "the gather and a light edit's factors (0: the default ones; lmgi: --seed)")                                 \
    X(photons, find_portals, LMGI_KNOB_SWITCH, int, LMGI_ON, 0, 0, 1, LMGI_NO_RULE, "--find-portals", "on|off",   \
      LMGI_CLI_ZERO_NONE, LMGI_ON_OFF_CHOICES, LMGI_NO_SWEEP,                                                      \
      "the windows a sun's or the sky's light gets in by, found where the file\n"                                 \
      "tags no portal, half their photons drawn through them (default on; off:\n"                                 \
      "the file's portals only; docs/levels.md, \"Portals\")")

/* the approximate illumination maps (docs/aim.md) */
#define LMGI_AIM_KNOBS(X)                                                                                             \
    X(aim, nearest, LMGI_KNOB_INT, int, 32, 1, 100000, 0, LMGI_NO_RULE, "--nearest", "N", LMGI_CLI_ZERO_NONE,     \
      LMGI_NO_CHOICES,                                                                                             \
      LMGI_SWEEP(3, "nearest", "photons per AIM estimate N", (16, 32, 64, 128, 256), (16, 32, 128), 0),          \
      "photons per AIM estimate (default 32; where hits are denser, the smallest\n"                               \
      "radius, which grows with sqrt(N), holds more: --min-radius)")                                              \
    X(aim, min_radius, LMGI_KNOB_REAL, float, 1, 0.01, 100, 0, LMGI_NO_RULE, "--min-radius", "T",                 \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES,                                                                         \
      LMGI_SWEEP(4, "min_radius", "AIM's smallest radius in texels", (0.25, 0.5, 1, 2), (0.25, 1), 0),           \
      "the AIM estimate's smallest radius, in texels at N = 32 and sqrt(N / 32)\n"                               \
      "times that at another N (default 1): where N hits lie closer, every hit\n"                                \
      "within it is summed; smaller makes the AIM sharper and noisier (docs/aim.md)")                             \
    X(aim, surfaces_per_frame, LMGI_KNOB_INT, int, 8, 1, 10000000, 1, LMGI_NO_RULE, "--surfaces-per-frame", "K",  \
      LMGI_CLI_ZERO_DEFAULT, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                       \
      "AIM refreshes a frame (default 8; a node moved after a still frame: all\n"                                  \
      "that its photons changed)")                                                                                 \
    X(aim, direct, LMGI_KNOB_CHOICE, lmgi_aim_direct, 0, 0, 0, 0, LMGI_NO_RULE,                                   \
      "--aim-direct", "M", LMGI_CLI_ZERO_NONE, LMGI_AIM_DIRECT_CHOICES,                                           \
      LMGI_SWEEP(10, "aim_direct", "AIM direct light (0 the scene's, 4 photons, 2 emitters)", (0, 4, 2), (0, 4), \
                 0),                                                                                             \
      "where the AIMs' direct light comes from: suns (directional lights'\n"                                      \
      "computed per texel by shadow rays, photons bring the rest), photons\n"                                    \
      "(first hits, the paper's form, blurred by the estimate's radius),\n"                                      \
      "emitters (emissive triangles' light computed per texel: sharp contact\n"                                  \
      "shadows, about 5x slower AIMs; the rays gather computes it at its near\n"                                 \
      "hits, --direct-near) or all (every light's); default: emitters and the\n"                                 \
      "rays gather where emissive triangles alone light the scene, else suns")                                    \
    X(aim, direct_parts, LMGI_KNOB_INT, int, 2, 1, 8, 0, LMGI_NO_RULE, "--direct-parts", "P", LMGI_CLI_ZERO_NONE,  \
      LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                                              \
      "the AIMs' computed direct light averaged over P x P parts of each texel\n"                                 \
      "(1 to 8; default 2, lmgi bake 4): near a lamp it falls off within a\n"                                     \
      "texel; more parts cost a direct-light evaluation each and spread a\n"                                      \
      "contact shadow over its texel (docs/aim.md, \"Averaged over the texel\")")                                 \
    X(aim, occluders, LMGI_KNOB_SWITCH, int, LMGI_OFF, 0, 0, 1, LMGI_NO_RULE, "--aim-occluders", "on|off",         \
      LMGI_CLI_ZERO_NONE, LMGI_ON_OFF_CHOICES,                                                                     \
      LMGI_SWEEP(16, "aim_occluders", "AIM hits seen from the texel (0 off, 1 on)", (0, 1), (), 0),           \
      "a photon hit counts towards an AIM texel only if the texel sees where\n"                                  \
      "the photon came from, weighed up where the estimate's disc sees it less\n"                                \
      "(shadow rays: sharper contact shadows, AIM refreshes 4-9x slower;\n"                                       \
      "default off; docs/aim.md, \"Occluders\")")                                                                 \
    X(aim, error_estimate, LMGI_KNOB_SWITCH, int, LMGI_OFF, 0, 0, 1, LMGI_NO_RULE, NULL, NULL, LMGI_CLI_ZERO_NONE, \
      LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                                              \
      "LMGI_ON: the AIMs keep their estimates' error, for LMGI_LIGHTMAP_ACCURACY (default off: it walks\n"        \
      "each estimate's photons twice; docs/gather.md, \"Error estimate\"; lmgi bake: --accuracy)")

/* the gather into the indirect illumination maps (docs/gather.md) */
#define LMGI_GATHER_KNOBS(X)                                                                                          \
    X(gather, texels_per_frame, LMGI_KNOB_INT, int, 20, 1, 100000000, 0, LMGI_NO_RULE, "--texels-per-frame", "N", \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES,                                                                         \
      LMGI_SWEEP(11, "texels_per_frame", "IIM texels gathered per update", (5, 20, 80), (), 0),                  \
      "IIM texels gathered per frame (default 20)")                                                                \
    X(gather, blend_frames, LMGI_KNOB_INT, int, 8, 1, 100000, 1, LMGI_NO_RULE, NULL, NULL, LMGI_CLI_ZERO_NONE,    \
      LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                                              \
      "updates a regathered surface takes to fade in (default 8; LMGI_OFF: at once)")                             \
    X(gather, texel_change, LMGI_KNOB_REAL, float, 0.03125, 1e-6, 1e6, 1, LMGI_NO_RULE, "--texel-change", "F",    \
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                           \
      "a texel is regathered ahead of its surface, and shown at once, when\n"                                    \
      "the estimated change of its hemisphere (moved objects, changed AIMs)\n"                                   \
      "exceeds F times the mean irradiance (default 1/32; 0: off, whole\n"                                          \
      "surfaces only, the paper's order; docs/gather.md)")                                                         \
    X(gather, spread, LMGI_KNOB_INT, int, 3, 1, 64, 1, LMGI_NO_RULE, "--texel-spread", "R", LMGI_CLI_ZERO_OFF,       \
      LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                                              \
      "a texel waiting to be regathered after a change shows, until it is,\n"                                    \
      "the changes its neighbours within R texels were gathered with (default 3;\n"                             \
      "0: off, its old value, so a changed region fills in texel by texel;\n"                                      \
      "docs/gather.md, \"Progressive refinement\")")                                                             \
    X(gather, estimate_rays, LMGI_KNOB_INT, int, 36, 1, 1024, 1, LMGI_NO_RULE, "--estimate-rays", "N",             \
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                           \
      "a texel waiting to be regathered shows, until it is, the change of\n"                                      \
      "what N rays from it see since its gather, up to 16 texels an update for\n"                                 \
      "each gathered (default 36; 0: off, its neighbours' changes alone, which\n"                                 \
      "never reach a texel gathered while a moving node stood beside it;\n"                                        \
      "docs/gather.md, \"Rays for the texels that wait\")")                                                      \
    X(gather, resolution, LMGI_KNOB_INT, int, 32, 2, 1024, 0, LMGI_NO_RULE, "--hemicube", "R", LMGI_CLI_ZERO_NONE,\
      LMGI_NO_CHOICES, LMGI_SWEEP(5, "hemicube", "hemicube resolution R", (16, 24, 32, 48, 64), (16, 32, 64), 0),\
      "hemicube plane pixels per side (default 32)")                                                               \
    X(gather, enlargement, LMGI_KNOB_REAL, float, 2, 1e-3, 1e3, 0, LMGI_NO_RULE, "--enlargement", "A",            \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES,                                                                         \
      LMGI_SWEEP(6, "enlargement", "hemicube enlargement a", (1, 1.5, 2, 3), (1, 2, 3), 0),                      \
      "hemicube plane half-side a (default 2)")                                                                    \
    X(gather, samples, LMGI_KNOB_INT, int, 4, 1, 4, 0, LMGI_RULE(v == 1 || v == 4, "1 or 4"), "--hemicube-samples",\
      "N", LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES,                                                                    \
      LMGI_SWEEP(7, "hemicube_samples", "AIM lookups per hemicube pixel", (1, 4), (1, 4), 0),                    \
      "AIM lookups per hemicube pixel, 1 or 4 (default 4: no banding)")                                           \
    /* coverage: MSAA samples; more than the GL renders into float targets is LMGI_ERR_INVALID */                     \
    X(gather, coverage, LMGI_KNOB_INT, int, 0, 1, 16, 0, LMGI_NO_RULE, "--hemicube-coverage", "N",                 \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES,                                                                         \
      LMGI_SWEEP(8, "coverage", "coverage samples per hemicube pixel", (1, 2, 4), (1, 4), 0),                    \
      "coverage samples per hemicube pixel, 1 to 16 within the GL's limit\n"                                      \
      "(llvmpipe: 4; default: 4 when emissive triangles are drawn into the\n"                                     \
      "hemicubes, whose small images alias, else 1)")                                                             \
    X(gather, rim_samples, LMGI_KNOB_INT, int, 64, 1, 65536, 1, LMGI_NO_RULE, "--rim-samples", "K",                \
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES,                                                                          \
      LMGI_SWEEP(9, "rim_samples", "rim rays per texel (0: 1 / F(a))", (0, 16, 64, 256), (0, 64), 0),            \
      "rays per texel for the light of the hemisphere's rim outside the plane\n"                                  \
      "(default 64); 0: the paper's 1 / F(a) extrapolation (surfaces 10-30% off\n"                                \
      "where a bright spot lies near their horizon)")                                                              \
    X(gather, scheme, LMGI_KNOB_CHOICE, lmgi_gather_scheme, 0, 0, 0, 0, LMGI_NO_RULE, "--gather-scheme", "S",      \
      LMGI_CLI_ZERO_NONE, LMGI_GATHER_SCHEME_CHOICES, LMGI_NO_SWEEP,                                               \
      "hemicubes by viewports, instanced or layered (layered has no\n"                                            \
      "multisampled target: coverage 1 unless given), or rays (Embree over each\n"                                \
      "texel's hemisphere, no hemicube); default: rays above 20,000 triangles on\n"                               \
      "a software GL, under a sky that is not uniform and where emissive\n"                                       \
      "triangles alone light the scene (--aim-direct not given), else viewports\n"                               \
      "(docs/gather.md, \"Rays\")")                                                                               \
    X(gather, emitter_light, LMGI_KNOB_CHOICE, lmgi_emitter_light, 0, 0, 0, 0, LMGI_NO_RULE, "--emitter-light", "M",\
      LMGI_CLI_ZERO_NONE, LMGI_EMITTER_LIGHT_CHOICES, LMGI_NO_SWEEP,                                               \
      "closed (the light of emissive triangles in closed form, visibility by\n"                                   \
      "shadow rays: no plaid, no coverage samples needed) or drawn into the\n"                                    \
      "hemicubes (default: closed when the scene has 1 to 64 emissive triangles)")                                \
    X(gather, emitter_rays, LMGI_KNOB_INT, int, 32, 1, 65536, 0, LMGI_NO_RULE, "--emitter-rays", "N",              \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES, LMGI_NO_SWEEP, "shadow rays per emissive triangle and texel (default 32)") \
    X(gather, rays, LMGI_KNOB_INT, int, 400, 1, 65536, 0, LMGI_NO_RULE, "--gather-rays", "N", LMGI_CLI_ZERO_NONE,   \
      LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                                              \
      "the rays gather: cosine-weighted strata over each texel's hemisphere,\n"                                   \
      "rounded down to a square (default 400; 1,600 takes the shared Cornell\n"                                  \
      "box's texels at the floor from 20% to 5% off for 3-4 x the solution's\n"                                 \
      "time, and with --bounce-passes 1 its faces within 2.5% over 8 seeds;\n"                                  \
      "docs/gather.md, \"Strata\")")                                                                             \
    X(gather, direct_near, LMGI_KNOB_REAL, float, 16, 0.01, 1e6, 1, LMGI_NO_RULE, "--direct-near", "K",            \
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                           \
      "with the emissive triangles' light at the rays gather's hits\n"                                             \
      "(--aim-direct emitters or all): only hits within K of their surface's\n"                                    \
      "texel widths take the direct light there, further ones read it in their\n"                                  \
      "AIM texel (default 16; 0: every hit; docs/gather.md, \"Near and far hits\")")                              \
    X(gather, adapt, LMGI_KNOB_REAL, float, LMGI_OFF, 0.001, 1, 1, LMGI_NO_RULE, "--gather-adapt", "E",            \
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                           \
      "the rays gather: a texel whose strata estimate their mean's relative\n"                                     \
      "standard error above E in some channel (beside a contact, facing a\n"                                     \
      "penumbra) traces 4 x as many strata more (default off; 0.05 doubles\n"                                    \
      "the shared Cornell box's gather; docs/gather.md, \"Adaptive strata\")")                                   \
    X(gather, bounce_passes, LMGI_KNOB_INT, int, LMGI_OFF, 1, 8, 1, LMGI_NO_RULE, "--bounce-passes", "N",          \
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                           \
      "after the first full gather, N more with the bounced light read from\n"                                     \
      "the last one's lightmap instead of the photons (rays scheme; the first\n"                                  \
      "solution only: later regathers read the photons; not in a shard: give\n"                                   \
      "it to the merge; default off, bake: 1 up to 8 lamps; docs/gather.md,\n"                                    \
      "\"Bounce passes\")")

/* caustics (docs/caustics.md): photons shot from every light towards every mirror or glass node, filtered
 * on screen */
#define LMGI_CAUSTIC_KNOBS(X)                                                                                         \
    X(caustics, photons, LMGI_KNOB_COUNT, uint32_t, 16384, 1, 1 << 24, 0, LMGI_NO_RULE, NULL, NULL,                \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES,                                                                         \
      LMGI_SWEEP(12, "caustic_photons", "caustic photons per light and node", (4096, 16384, 65536),              \
                 (4096, 16384, 65536), 1),                                                                         \
      "caustic photons per light and mirror or glass node (default 16384; lmgi: --caustic-photons)")              \
    X(caustics, retrace, LMGI_KNOB_REAL, float, 0.25, 0, 1, 0,                                                    \
      LMGI_RULE(v > 0, "a share of the caustic photons in (0, 1]"),                                                 \
      "--caustic-retrace", "F", LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                               \
      "share of the caustic photons re-traced a frame while anything moves\n"                                     \
      "(default 0.25; a moved light or mirror/glass node re-traces its own)")                                     \
    X(caustics, filter, LMGI_KNOB_INT, int, 2, 1, 8, 1, LMGI_NO_RULE, "--caustic-filter", "K", LMGI_CLI_ZERO_OFF, \
      LMGI_NO_CHOICES, LMGI_SWEEP(13, "caustic_filter", "caustic filter k", (1, 2, 3, 5), (1, 3, 5), 1),         \
      "k of the caustics' (2k+1)^2 cone filter, 0 to 8 (default 2)")                                              \
    X(caustics, filter_photons, LMGI_KNOB_INT, int, 32, 1, 65536, 1, LMGI_NO_RULE, "--caustic-filter-photons", "N",\
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES,                                                                          \
      LMGI_SWEEP(15, "caustic_filter_photons", "caustic filter photons", (8, 16, 32, 64, 128), (8, 32, 128), 1),  \
      "photons a caustic filter should hold: where its (2k+1)^2 pixels hold\n"                                    \
      "fewer it widens, up to 8 times, and where they hold more across an edge\n"                               \
      "or a focal spot it narrows to that many\n"                                                                 \
      "(default 32; 0: the paper's fixed filter)")                                                               \
    X(caustics, world_filter, LMGI_KNOB_SWITCH, int, LMGI_OFF, 0, 0, 1, LMGI_NO_RULE, "--caustic-space", "S",     \
      LMGI_CLI_ZERO_NONE, LMGI_CAUSTIC_SPACE_CHOICES, LMGI_NO_SWEEP,                                               \
      "screen (default, the paper's filter) or world (by world distance)")                                        \
    X(caustics, tile, LMGI_KNOB_INT, int, 32, 4, 256, 0, LMGI_NO_RULE, "--caustic-tile", "N", LMGI_CLI_ZERO_NONE, \
      LMGI_NO_CHOICES, LMGI_NO_SWEEP, "screen tile side of the caustics' occlusion queries (default 32)")         \
    X(caustics, thin, LMGI_KNOB_REAL, float, 0.25, 0.001, 1000, 1, LMGI_NO_RULE, "--caustic-thin", "F",       \
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                           \
      "caustic light under F x its surface's and its texel's other light,\n"                                     \
      "without sharp structure, is carried by the lightmaps and only the rest\n"                                 \
      "filtered on screen (default 0.25, measured best; 0: every photon on\n"                                   \
      "screen, the paper's; docs/caustics.md, \"Thin light in the lightmaps\")")

/* the frame each lmgi_update composites: its reflections and shadow maps */
#define LMGI_FRAME_KNOBS(X)                                                                                           \
    /* shadow maps: those of the brightest lights nearest to what moved first, the others keep their */               \
    /* last map a few updates (56 lights and a moving box: their maps over 14 updates); a light's */                  \
    /* first map, and lmgi_render's and lmgi_bake's, are drawn whatever the count */                                  \
    X(frame, shadow_maps_per_update, LMGI_KNOB_INT, int, 4, 1, 1000000, 1, LMGI_NO_RULE, "--shadow-maps-per-frame",\
      "N", LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                      \
      "stale shadow maps re-rendered a frame once something moved, brightest\n"                                   \
      "and nearest to it first (default 4; 0: all at once)")                                                       \
    X(frame, reflection_size, LMGI_KNOB_INT, int, 128, 1, 4096, 1, LMGI_NO_RULE, "--reflection-size", "N",        \
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                           \
      "texels per side of the environment cube map of each mirror, glossy or\n"                                   \
      "glass node (default 128; 0: no reflections, mirrors black)")                                               \
    X(frame, reflection_faces, LMGI_KNOB_INT, int, 1, 1, 1 << 20, 0, LMGI_NO_RULE, "--reflection-faces", "N",     \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                          \
      "most environment map faces re-rendered a frame, those whose view changed\n"                                \
      "longest ago first, after all of them at the first frame (default 1; a\n"                                   \
      "still scene renders none)")                                                                                 \
    X(frame, reflection_lod, LMGI_KNOB_REAL, float, 0.001953125, 1e-6, 0.1, 1, LMGI_NO_RULE, "--reflection-lod", "E", \
      LMGI_CLI_ZERO_OFF, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                           \
      "environment map faces draw the scene simplified to E x its size, what\n"                                    \
      "they show off by up to that much (default 1/512; 0: every triangle;\n"                                      \
      "docs/direct.md, \"Reflections\")")

/* the per-pixel photon gathers (indirect TILED, HASHGRID, BRUTEFORCE; docs/tiled.md) */
#define LMGI_TILED_KNOBS(X)                                                                                           \
    X(tiled, tile, LMGI_KNOB_INT, int, 16, 4, 32, 0, LMGI_RULE(lmgi_knob_is_pow2(v), "4, 8, 16 or 32 pixels"),     \
      "--photon-tile", "N", LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                   \
      "with --indirect tiled: tile side, 4, 8, 16 or 32 (default 16)")                                            \
    X(tiled, chunk, LMGI_KNOB_INT, int, 256, 64, 512, 0, LMGI_NO_RULE, "--photon-chunk", "N", LMGI_CLI_ZERO_NONE, \
      LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                                                              \
      "with --indirect tiled: photons per shared-memory load, 64 to 512\n"                                        \
      "(default 256)")                                                                                             \
    X(tiled, stochastic, LMGI_KNOB_INT, int, 1, 1, 4, 0, LMGI_NO_RULE, "--photon-stochastic", "K",                 \
      LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES,                                                                         \
      LMGI_SWEEP(14, "tiled_k", "tiled gather k (stochastic)", (1, 2, 4), (1, 2, 4), 2),                         \
      "with --indirect tiled: each pixel reads 1/k^2 of its tile's photons,\n"                                    \
      "then an edge-aware k x k average (1 to 4; default 1: all)")                                                \
    X(tiled, radius, LMGI_KNOB_REAL, float, 0, 0, HUGE_VAL, 0, LMGI_RULE(v > 0, "a radius in scene units, above 0"),\
      "--photon-radius", "R", LMGI_CLI_ZERO_NONE, LMGI_NO_CHOICES, LMGI_NO_SWEEP,                                 \
      "the per-pixel gathers' kernel radius (default: the disc of --nearest\n"                                    \
      "photons)")

/* Every knob, stage by stage. */
#define LMGI_UPDATER_KNOBS(X)                                                                                         \
    LMGI_PHOTON_KNOBS(X) LMGI_AIM_KNOBS(X) LMGI_GATHER_KNOBS(X) LMGI_CAUSTIC_KNOBS(X) LMGI_FRAME_KNOBS(X)           \
    LMGI_TILED_KNOBS(X)

/* A stage's struct member from its line. */
#define LMGI_KNOB_MEMBER(stage, field, kind, ctype, ...) ctype field;

#endif
