#include "stage_worker.h"

#include <pthread.h>
#include <stdlib.h>

#include "../core/log.h"

struct lm_stage_worker {
    lm_photon_stage *ps;
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t wake, done_cond;
    lm_photon_stage_frame *frame; /* the job; NULL when none is waiting */
    lm_log_target log;            /* the job's caller's message target, used for the job's messages */
    int busy, quit;
    lm_status status;
    lm_error err;
};

static void *run(void *arg)
{
    lm_stage_worker *w = arg;
    pthread_mutex_lock(&w->lock);
    for (;;) {
        while (!w->frame && !w->quit)
            pthread_cond_wait(&w->wake, &w->lock);
        if (!w->frame)
            break;
        lm_photon_stage_frame *f = w->frame;
        lm_log_swap_target(w->log);
        pthread_mutex_unlock(&w->lock);
        lm_error err;
        lm_status st = lm_photon_stage_update(w->ps, f, &err);
        pthread_mutex_lock(&w->lock);
        w->status = st;
        w->err = err;
        w->frame = NULL;
        w->busy = 0;
        pthread_cond_signal(&w->done_cond);
    }
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

lm_status lm_stage_worker_start(lm_photon_stage *ps, lm_stage_worker **out, lm_error *err)
{
    *out = NULL;
    lm_stage_worker *w = calloc(1, sizeof *w);
    if (!w)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the photon stage's thread");
    w->ps = ps;
    pthread_mutex_init(&w->lock, NULL);
    pthread_cond_init(&w->wake, NULL);
    pthread_cond_init(&w->done_cond, NULL);
    if (pthread_create(&w->thread, NULL, run, w) != 0) {
        pthread_cond_destroy(&w->done_cond);
        pthread_cond_destroy(&w->wake);
        pthread_mutex_destroy(&w->lock);
        free(w);
        return lm_fail(err, LM_ERR_BACKEND, "cannot start the photon stage's thread");
    }
    *out = w;
    return LM_OK;
}

void lm_stage_worker_begin(lm_stage_worker *w, lm_photon_stage_frame *frame)
{
    pthread_mutex_lock(&w->lock);
    w->frame = frame;
    w->log = lm_log_get_target();
    w->busy = 1;
    pthread_cond_signal(&w->wake);
    pthread_mutex_unlock(&w->lock);
}

lm_status lm_stage_worker_end(lm_stage_worker *w, lm_error *err)
{
    pthread_mutex_lock(&w->lock);
    while (w->busy)
        pthread_cond_wait(&w->done_cond, &w->lock);
    lm_status st = w->status;
    if (st != LM_OK && err)
        *err = w->err;
    w->status = LM_OK;
    pthread_mutex_unlock(&w->lock);
    return st;
}

void lm_stage_worker_stop(lm_stage_worker *w)
{
    if (!w)
        return;
    lm_stage_worker_end(w, NULL);
    pthread_mutex_lock(&w->lock);
    w->quit = 1;
    pthread_cond_signal(&w->wake);
    pthread_mutex_unlock(&w->lock);
    pthread_join(w->thread, NULL);
    pthread_cond_destroy(&w->done_cond);
    pthread_cond_destroy(&w->wake);
    pthread_mutex_destroy(&w->lock);
    free(w);
}
