#include <cstring>

#include "handles.hpp"

namespace mfree {

void retain(mfree_context_t *c) { c->refs.fetch_add(1, std::memory_order_relaxed); }
void release(mfree_context_t *c) {
  if (c && c->refs.fetch_sub(1, std::memory_order_acq_rel) == 1) delete c;
}

namespace {
// Store the last error under the context's lock and pass the handler the caller's own
// copy of the message: another thread may overwrite the context's copy meanwhile.
void store_error(mfree_context_t *ctx, mfree_status_t status, const std::string *message) {
  {
    const std::lock_guard<std::mutex> lock(ctx->error_lock);
    ctx->last_code = status;
    try {
      if (message) ctx->last_message = *message;
      else ctx->last_message.clear();
    } catch (...) {  // no memory for the text: keep the code, drop the stale text
      ctx->last_message.clear();
    }
  }
  if (ctx->handler) ctx->handler(ctx->handler_user, status, message ? message->c_str() : "");
}
}  // namespace

mfree_status_t record(mfree_context_t *ctx, mfree_status_t status, const char *fn,
                      const std::string &msg) {
  if (!ctx) return status;
  std::string text;
  try {
    text = std::string(fn) + ": " + msg;
  } catch (...) {
    store_error(ctx, status, nullptr);
    return status;
  }
  store_error(ctx, status, &text);
  return status;
}

}  // namespace mfree

extern "C" {

mfree_status_t mfree_context_create(mfree_context_t **ctx) {
  if (!ctx) return MFREE_ERR_NULL;
  *ctx = nullptr;
  mfree_context_t *c = new (std::nothrow) mfree_context_t();
  if (!c) return MFREE_ERR_ALLOC;
  *ctx = c;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_context_destroy(mfree_context_t **ctx) {
  if (!ctx || !*ctx) return MFREE_SUCCESS;
  mfree::release(*ctx);
  *ctx = nullptr;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_context_get_last_error(const mfree_context_t *ctx, mfree_status_t *code,
                                            char *message, int64_t len) {
  if (!ctx) return MFREE_ERR_NULL;
  if (message && len < 1) return MFREE_ERR_ARG;
  const std::lock_guard<std::mutex> lock(ctx->error_lock);
  if (code) *code = ctx->last_code;
  if (message) {
    const size_t n = std::min<size_t>(ctx->last_message.size(), static_cast<size_t>(len - 1));
    std::memcpy(message, ctx->last_message.data(), n);
    message[n] = '\0';
  }
  return MFREE_SUCCESS;
}

mfree_status_t mfree_context_set_error(mfree_context_t *ctx, mfree_status_t code,
                                       const char *message) {
  if (!ctx) return MFREE_ERR_NULL;
  std::string text;
  try {
    text = message ? message : "";
  } catch (...) {
    return MFREE_ERR_ALLOC;
  }
  mfree::store_error(ctx, code, &text);
  return code;
}

mfree_status_t mfree_context_set_error_handler(mfree_context_t *ctx,
                                               mfree_error_handler_t handler, void *user) {
  if (!ctx) return MFREE_ERR_NULL;
  ctx->handler = handler;
  ctx->handler_user = user;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_context_set_num_threads(mfree_context_t *ctx, int32_t nthreads) {
  if (!ctx) return MFREE_ERR_NULL;
  if (nthreads < 0)
    return mfree::record(ctx, MFREE_ERR_ARG, "mfree_context_set_num_threads",
                         "thread count " + std::to_string(nthreads) + " is negative");
  ctx->nthreads = nthreads;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_context_get_num_threads(const mfree_context_t *ctx, int32_t *nthreads) {
  if (!ctx || !nthreads) return MFREE_ERR_NULL;
  *nthreads = ctx->nthreads;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_context_set_backend(mfree_context_t *ctx, int32_t backend) {
  if (!ctx) return MFREE_ERR_NULL;
  if (backend != MFREE_BACKEND_REF && backend != MFREE_BACKEND_OPT)
    return mfree::record(ctx, MFREE_ERR_ARG, "mfree_context_set_backend",
                         "unknown backend " + std::to_string(backend) +
                             " (MFREE_BACKEND_REF = 1, MFREE_BACKEND_OPT = 2)");
  ctx->config.backend = backend;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_context_get_backend(const mfree_context_t *ctx, int32_t *backend) {
  if (!ctx || !backend) return MFREE_ERR_NULL;
  *backend = ctx->config.backend;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_context_set_page_hints(mfree_context_t *ctx, int32_t flags) {
  if (!ctx) return MFREE_ERR_NULL;
  constexpr int32_t known = MFREE_PAGES_HUGE | MFREE_PAGES_PREFAULT;
  if (flags & ~known)
    return mfree::record(ctx, MFREE_ERR_ARG, "mfree_context_set_page_hints",
                         "unknown flags in " + std::to_string(flags) +
                             " (MFREE_PAGES_HUGE = 1, MFREE_PAGES_PREFAULT = 2, combined with |)");
  ctx->config.pages = flags;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_context_get_page_hints(const mfree_context_t *ctx, int32_t *flags) {
  if (!ctx || !flags) return MFREE_ERR_NULL;
  *flags = ctx->config.pages;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_context_set_allocator(mfree_context_t *ctx, mfree_alloc_fn alloc,
                                           mfree_free_fn release, void *user) {
  if (!ctx) return MFREE_ERR_NULL;
  if ((alloc == nullptr) != (release == nullptr))
    return mfree::record(ctx, MFREE_ERR_ARG, "mfree_context_set_allocator",
                         "give both an allocation and a free function, or neither");
  ctx->alloc.alloc = alloc;
  ctx->alloc.release = release;
  ctx->alloc.user = alloc ? user : nullptr;
  return MFREE_SUCCESS;
}

}  // extern "C"
