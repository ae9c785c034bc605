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

#endif
