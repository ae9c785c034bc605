/* The frame's error per visible surface from a check (lmgi_check, lmgi_check_updater): what the tradeoff
 * study and the frame lag of edit scripts judge a frame by. */
#ifndef LM_CLI_SURFACE_ERROR_H
#define LM_CLI_SURFACE_ERROR_H

#include <lmgi_tools.h>

/* Per visible surface (not emitters), |frame mean / reference mean - 1| on the sum of the channels: the
 * pixel-weighted RMS over surfaces of 20 or more compared pixels (returned; NAN when there is none), and
 * into *worst the largest of those with 100 or more (issue 17's bound). Means over a surface's pixels
 * average the reference's own noise away, which the per-pixel RMSE keeps (about its target error). */
double lm_cli_surface_error(const lmgi_scene *sc, const lmgi_check_result *c, double *worst);

/* The per-channel criterion (issue 33): over the visible surfaces of 100 or more compared pixels (not
 * emitters), each channel's |frame - reference| / max(reference, 5% of the surface's brightest reference
 * channel) (the floor keeps a channel the surface barely reflects, a green wall's red, from reading its
 * noise as error): how many surfaces there are, how many are within tol in every channel, and the
 * surface (-1: none) and channel furthest off, with its signed frame / reference - 1. */
typedef struct {
    int surfaces, within;
    int worst_surface, worst_channel;
    double worst;       /* the largest of the per-channel errors above */
    double worst_ratio; /* that channel's frame / reference - 1 */
} lm_cli_channel_check;
void lm_cli_surface_channels(const lmgi_scene *sc, const lmgi_check_result *c, double tol, lm_cli_channel_check *out);
/* That criterion for one surface's frame and reference means (rgb): the largest of its per-channel errors, and
 * into *channel (may be NULL) the first channel that has it; -1 (and channel -1) for a black reference, which
 * is not judged. What lm_cli_surface_channels reads each surface by, and tests/test_frame_check.c too. */
double lm_cli_channel_off(const double frame[3], const double ref[3], int *channel);

#endif
