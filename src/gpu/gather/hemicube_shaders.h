/* GLSL of the hemicube gather (hemicube_gather.c), one variant per way of putting many texels' planes
 * into one pass (lm_gather_scheme). Internal to gpu/gather/. */
#ifndef LM_HEMICUBE_SHADERS_H
#define LM_HEMICUBE_SHADERS_H

#include "../../core/error.h"
#include "hemicube.h"

/* Compiles and links the render program and the reduction program for `scheme`, with `samples` (1 or 4)
 * AIM lookups per pixel. */
lm_status lm_hemicube_programs(lm_gather_scheme scheme, int samples, unsigned *render, unsigned *reduce, lm_error *err);

#endif
