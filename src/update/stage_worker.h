/* A thread that runs the photon stage's second half (lm_photon_stage_update) while the caller renders:
 * the frame loop's overlap of CPU photon work with GL work. One job at a time: lm_stage_worker_begin
 * hands it a frame, lm_stage_worker_end waits for it. The thread and its OpenMP team persist between
 * frames. */
#ifndef LM_STAGE_WORKER_H
#define LM_STAGE_WORKER_H

#include "photon_stage.h"

typedef struct lm_stage_worker lm_stage_worker;

lm_status lm_stage_worker_start(lm_photon_stage *ps, lm_stage_worker **out, lm_error *err);
/* Stops and joins the thread (after waiting for a job in progress). NULL is ignored. */
void lm_stage_worker_stop(lm_stage_worker *w);
/* Starts lm_photon_stage_update(ps, frame) on the worker; frame must stay valid until the end. */
void lm_stage_worker_begin(lm_stage_worker *w, lm_photon_stage_frame *frame);
/* Waits for the job begun last and returns its status (its error in err). */
lm_status lm_stage_worker_end(lm_stage_worker *w, lm_error *err);

#endif
