// Handle structs behind the opaque C types, reference counting and the exception guard
// that every extern "C" body runs inside.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <new>
#include <string>

#include "core/base/alloc.hpp"
#include "core/base/config.hpp"
#include "core/shape/approximant.hpp"
#include "core/discretize/assembler.hpp"
#include "core/base/error.hpp"
#include "core/base/parallel.hpp"
#include "core/discretize/matrix.hpp"
#include "core/shape/mpfem.hpp"
#include "core/particles/particles.hpp"
#include "mfree.h"

struct mfree_context {
  std::atomic<int> refs{1};
  // Objects sharing a context may fail on several threads at once (apply is reentrant):
  // the last error is written and read under this lock.
  mutable std::mutex error_lock;
  mfree_status_t last_code = MFREE_SUCCESS;
  std::string last_message;
  mfree_error_handler_t handler = nullptr;
  void *handler_user = nullptr;
  int32_t nthreads = 1;
  mfree::AllocHook alloc;  // empty: malloc
  mfree::CallConfig config;  // backend and page hints
};

struct mfree_particles {
  std::atomic<int> refs{1};
  mfree_context_t *ctx = nullptr;
  mfree::ParticleSet set;
  mfree_particles(mfree_context_t *c, int dim, int32_t n) : ctx(c), set(dim, n) {}
  mfree::ParticleSet &core() { return set; }
  const mfree::ParticleSet &core() const { return set; }
};

struct mfree_approximant {
  std::atomic<int> refs{1};
  mfree_context_t *ctx = nullptr;
  mfree_particles_t *ps = nullptr;  // retained
  mfree::Approximant a;
  mfree_approximant(mfree_context_t *c, mfree_particles_t *p, int method)
      : ctx(c), ps(p), a(&p->set, method) {}
  mfree::Approximant &core() { return a; }
  const mfree::Approximant &core() const { return a; }
};

struct mfree_mesh {
  std::atomic<int> refs{1};
  mfree_context_t *ctx = nullptr;
  mfree_particles_t *ps = nullptr;  // retained
  std::shared_ptr<mfree::Mesh> m;   // shared with the approximants that use it
  mfree_mesh(mfree_context_t *c, mfree_particles_t *p)
      : ctx(c), ps(p), m(std::make_shared<mfree::Mesh>(&p->set)) {}
  mfree::Mesh &core() { return *m; }
  const mfree::Mesh &core() const { return *m; }
};

struct mfree_matrix {
  std::atomic<int> refs{1};
  mfree_context_t *ctx = nullptr;
  mfree::SparseMatrix m;
  explicit mfree_matrix(mfree_context_t *c) : ctx(c) {}
  mfree::SparseMatrix &core() { return m; }
  const mfree::SparseMatrix &core() const { return m; }
};

struct mfree_assembler {
  std::atomic<int> refs{1};
  mfree_context_t *ctx = nullptr;
  mfree_particles_t *ps = nullptr;  // retained
  mfree::Assembler as;
  mfree_assembler(mfree_context_t *c, mfree_particles_t *p, const mfree::ApproxConfig &trial,
                  const mfree::ApproxConfig &test, bool bubnov, int form)
      : ctx(c), ps(p), as(&p->set, trial, test, bubnov, form) {}
  mfree::Assembler &core() { return as; }
  const mfree::Assembler &core() const { return as; }
};

namespace mfree {

void retain(mfree_context_t *c);
void release(mfree_context_t *c);
void retain(mfree_particles_t *p);
void release(mfree_particles_t *p);
void release(mfree_matrix_t *m);
void release(mfree_assembler_t *a);

// Record a failure (or a positive report) on the context; returns status unchanged.
mfree_status_t record(mfree_context_t *ctx, mfree_status_t status, const char *fn,
                      const std::string &msg);

// Run body() and turn every exception into a status and a message on ctx.
template <class Body>
mfree_status_t guard(mfree_context_t *ctx, const char *fn, Body &&body) noexcept {
  // the context's allocator and thread count hold for everything the call runs
  const AllocScope alloc_scope(ctx ? &ctx->alloc : nullptr);
  const ThreadScope thread_scope(ctx ? ctx->nthreads : 1);
  const ConfigScope config_scope(ctx ? &ctx->config : nullptr);
  try {
    return body();
  } catch (const Error &e) {
    return record(ctx, e.status(), fn, e.what());
  } catch (const std::bad_alloc &) {
    return record(ctx, MFREE_ERR_ALLOC, fn, "out of memory");
  } catch (const std::exception &e) {
    return record(ctx, MFREE_ERR_INTERNAL, fn, std::string("internal error: ") + e.what());
  } catch (...) {
    return record(ctx, MFREE_ERR_INTERNAL, fn, "internal error: unknown exception");
  }
}

// Run body(core object) of a handle inside the guard; a NULL handle has no context to
// record a message on, so it only returns MFREE_ERR_NULL. H::core() gives the object.
template <class H, class Body>
mfree_status_t with_handle(H *h, const char *fn, Body &&body) noexcept {
  if (!h) return MFREE_ERR_NULL;
  return guard(h->ctx, fn, [&]() { return body(h->core()); });
}

// Report a data-dependent outcome: record its message if it failed, return its status.
inline mfree_status_t finish(mfree_context_t *ctx, const char *fn, const Report &r) {
  if (r.status != MFREE_SUCCESS) return record(ctx, r.status, fn, r.message);
  return MFREE_SUCCESS;
}

// setup() of an object built on a particle set (approximant, assembler): sets the
// particle set up first if it is not, then the object; the object's failure wins, else
// the set's (positive) outcome is reported.
template <class H>
mfree_status_t setup_on_set(H *h, const char *fn) noexcept {
  return with_handle(h, fn, [&](auto &obj) {
    ParticleSet &set = h->ps->set;
    Report pre;
    if (!set.is_setup()) pre = set.setup();
    Report rep = obj.setup();
    if (!rep.ok()) return finish(h->ctx, fn, rep);
    return finish(h->ctx, fn, pre);
  });
}

}  // namespace mfree

#define MFREE_REQUIRE(cond, status, msg)          \
  do {                                            \
    if (!(cond)) throw ::mfree::Error(status, msg); \
  } while (0)
