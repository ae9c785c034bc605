/* The inside of the public lmgi_context handle, and how a public call routes its messages to it. */
#ifndef LM_LMGI_CONTEXT_H
#define LM_LMGI_CONTEXT_H

#include <lmgi.h>
#include <stdatomic.h>
#include <stdint.h>

#include "../core/log.h"
#include "../gpu/gl/gl_context.h"

struct lmgi_context {
    lmgi_context_desc desc;
    lm_gl_context *gl;
    int updaters;           /* alive: lmgi_context_free refuses to pull the GL context from under them */
    atomic_uintptr_t owner; /* the thread inside a call on this context (0: none); lm_api_claim */
    int depth;              /* the owner's nested claims */
};

/* One thread at a time per context and its updaters (docs/api.md, "Threads"): each public call that
 * uses the GL context or the updater's state claims ctx for its duration, and one from another thread
 * meanwhile is refused (LMGI_ERR_INVALID naming `fn`) instead of racing it into a crash. Reentrant on the
 * owning thread. Cost: one compare-and-swap per call. */
lmgi_status lm_api_claim(lmgi_context *ctx, const char *fn, lmgi_error *err);
void lm_api_release(lmgi_context *ctx);

/* On entry to a public call made for ctx: the calling thread's messages go to ctx's callback until
 * lm_api_leave puts the returned target back. */
lm_log_target lm_api_enter(const lmgi_context *ctx);
void lm_api_leave(lm_log_target saved);

#endif
