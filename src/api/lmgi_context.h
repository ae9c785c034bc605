/* The inside of the public lmgi_context handle, and how a public call routes its messages to it. */
#ifndef LM_LMGI_CONTEXT_H
#define LM_LMGI_CONTEXT_H

#include <lmgi.h>

#include "../core/log.h"
#include "../gpu/gl_context.h"

struct lmgi_context {
    lmgi_context_desc desc;
    lm_gl_context *gl;
    int updaters;           /* alive: lmgi_context_free refuses to pull the GL context from under them */
};

/* On entry to a public call made for ctx: the calling thread's messages go to ctx's callback until
 * lm_api_leave puts the returned target back. */
lm_log_target lm_api_enter(const lmgi_context *ctx);
void lm_api_leave(lm_log_target saved);

#endif
