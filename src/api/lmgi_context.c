/* The public API's context: the GL context its updaters render with and the log callback. */
#include "lmgi_context.h"

#include <stdlib.h>
#include <string.h>

#include "api_error.h"

static void to_callback(void *user, lm_log_level level, const char *message)
{
    const lmgi_context *ctx = user;
    ctx->desc.log(ctx->desc.log_user, (lmgi_log_level)(level + 1), message);
}

lm_log_target lm_api_enter(const lmgi_context *ctx)
{
    lm_log_target t = lm_log_get_target();
    if (ctx && ctx->desc.log)
        t = (lm_log_target){to_callback, (void *)ctx, (lm_log_level)(ctx->desc.log_level - 1)};
    return lm_log_swap_target(t);
}

void lm_api_leave(lm_log_target saved) { lm_log_swap_target(saved); }

/* A per-thread address: the thread's identity, never 0. */
static uintptr_t this_thread(void)
{
    static _Thread_local char me;
    return (uintptr_t)&me;
}

lmgi_status lm_api_claim(lmgi_context *ctx, const char *fn, lmgi_error *err)
{
    uintptr_t me = this_thread(), none = 0;
    if (atomic_load(&ctx->owner) == me || atomic_compare_exchange_strong(&ctx->owner, &none, me)) {
        ctx->depth++;
        lm_gl_guest_enter(); /* the host's GL context is given back when the call returns */
        return LMGI_OK;
    }
    return lm_api_refuse(err, "%s: the context is in use by another thread (a context and its updaters are for one "
                         "thread at a time; docs/api.md, \"Threads\")", fn);
}

void lm_api_release(lmgi_context *ctx)
{
    lm_gl_guest_leave();
    if (--ctx->depth == 0)
        atomic_store(&ctx->owner, 0);
}

lmgi_status lmgi_context_create(const lmgi_context_desc *desc, lmgi_context **out, lmgi_error *err)
{
    lm_error e;
    if (!out)
        return lm_export_error(err, &(lm_error){LM_ERR_INVALID, "lmgi_context_create: out is NULL"});
    *out = NULL;
    lmgi_context_desc d;
    memset(&d, 0, sizeof d);
    if (desc)
        d = *desc;
    if (d.log_level == 0)
        d.log_level = LMGI_LOG_WARN;
    if (d.log_level < LMGI_LOG_ERROR || d.log_level > LMGI_LOG_DEBUG) {
        lm_fail(&e, LM_ERR_INVALID, "lmgi_context_create: log level %d is not one of 1 (errors) to 4 (debug)",
                (int)d.log_level);
        return lm_export_error(err, &e);
    }
    if (d.share_display && !d.share_context) {
        lm_fail(&e, LM_ERR_INVALID, "lmgi_context_create: share_display is set but share_context is NULL");
        return lm_export_error(err, &e);
    }
    lmgi_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return lm_export_error(err, &(lm_error){LM_ERR_NOMEM, "no memory for a context"});
    ctx->desc = d;
    ctx->desc.gl_backend = NULL; /* the caller's string need not outlive the call */
    lm_log_target saved = lm_api_enter(ctx);
    lm_gl_guest_enter();
    lm_gl_share share = {d.share_display, d.share_context};
    lm_status st = lm_gl_context_create_backend(d.gl_backend, d.share_context ? &share : NULL, &ctx->gl, &e);
    lm_gl_guest_leave();
    lm_api_leave(saved);
    if (st != LM_OK) {
        free(ctx);
        return lm_export_error(err, &e);
    }
    *out = ctx;
    return LMGI_OK;
}

void lmgi_context_free(lmgi_context *ctx)
{
    if (!ctx)
        return;
    if (ctx->updaters > 0) { /* freeing the GL context would break them: leak it rather than crash later */
        lm_log_target saved = lm_api_enter(ctx);
        lm_log(LM_LOG_ERROR, "lmgi_context_free: %d updater%s still alive; free them first (context kept)",
               ctx->updaters, ctx->updaters > 1 ? "s" : "");
        lm_api_leave(saved);
        return;
    }
    lm_gl_guest_enter();
    lm_gl_context_destroy(ctx->gl);
    lm_gl_guest_leave();
    free(ctx);
}

const char *lmgi_context_gl_description(const lmgi_context *ctx)
{
    return ctx ? lm_gl_context_description(ctx->gl) : "";
}
