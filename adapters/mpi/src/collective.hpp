// Internal to libmfree_mpi: how its collective calls agree on their outcome. Each call
// runs a local step (checks, packing) that records its failure instead of returning, then
// one MPI_Allreduce of the worst status and its rank, and that rank's message broadcast,
// before any step that would make the others wait: a failure on one rank never leaves
// another blocked, and every rank returns the same status and message.
#ifndef MFREE_MPI_COLLECTIVE_HPP
#define MFREE_MPI_COLLECTIVE_HPP

#include "mfree_mpi.h"

#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <utility>

namespace mfree_mpi_detail {

// (const char *: no std::string is built outside a try on the callers' side)
inline mfree_status_t record(mfree_context_t *ctx, mfree_status_t st, const char *fn, const char *msg) noexcept {
  char text[640];
  std::snprintf(text, sizeof text, "%s: %s", fn, msg);
  return mfree_context_set_error(ctx, st, text);
}

// A local step's outcome: status and message, not yet shared with the other ranks.
struct Local {
  mfree_status_t st = MFREE_SUCCESS;
  std::string msg;
  void fail(mfree_status_t s, std::string m) {
    if (st == MFREE_SUCCESS) {
      st = s;
      msg = std::move(m);
    }
  }
};

template <class Body>
inline Local run_local(Body &&body) noexcept {
  Local l;
  try {
    body(l);
  } catch (const std::bad_alloc &) {
    l.st = MFREE_ERR_ALLOC;
    l.msg = "out of memory";
  } catch (const std::exception &e) {
    l.st = MFREE_ERR_INTERNAL;
    try {
      l.msg = std::string("internal error: ") + e.what();
    } catch (...) {
    }
  } catch (...) {
    l.st = MFREE_ERR_INTERNAL;
  }
  return l;
}

// One value of a rank in an agreement: its minimum over the ranks and the lowest rank
// holding it come back (MPI_DOUBLE_INT, MPI_MINLOC; maxima as minima of the negatives).
struct Loc {
  double v;
  int r;
};

// Every rank learns the lowest status of the ranks (the first rank holding it breaks
// ties) and that rank's message; all return the same status. The same all-reduce carries
// the nv values of vals (each rank's in, the minimum and its rank out), which the callers
// compare to find ranks that disagree on an argument that must be common. MPI failures of
// the agreement itself are internal errors.
inline mfree_status_t agree(mfree_context_t *ctx, MPI_Comm comm, int rank, const char *fn, const Local &l,
                            Loc *vals = nullptr, int nv = 0) noexcept {
  Loc buf_in[8], buf_out[8];
  if (nv > 7) return record(ctx, MFREE_ERR_INTERNAL, fn, "too many values to agree on");
  buf_in[0] = {static_cast<double>(l.st < 0 ? l.st : MFREE_SUCCESS), rank};
  for (int k = 0; k < nv; ++k) buf_in[k + 1] = {vals[k].v, rank};
  if (MPI_Allreduce(buf_in, buf_out, nv + 1, MPI_DOUBLE_INT, MPI_MINLOC, comm) != MPI_SUCCESS)
    return record(ctx, MFREE_ERR_INTERNAL, fn, "MPI_Allreduce failed");
  for (int k = 0; k < nv; ++k) vals[k] = buf_out[k + 1];
  const int worst = static_cast<int>(buf_out[0].v), who = buf_out[0].r;
  if (worst == MFREE_SUCCESS) return MFREE_SUCCESS;
  char buf[512] = {0};
  if (rank == who) std::snprintf(buf, sizeof buf, "%s", l.msg.c_str());
  if (MPI_Bcast(buf, static_cast<int>(sizeof buf), MPI_CHAR, who, comm) != MPI_SUCCESS)
    return record(ctx, MFREE_ERR_INTERNAL, fn, "MPI_Bcast failed");
  buf[sizeof buf - 1] = 0;
  const mfree_status_t st = static_cast<mfree_status_t>(worst);
  char text[560];
  std::snprintf(text, sizeof text, "rank %d: %s", who, buf);
  return record(ctx, st, fn, text);
}

// After an agreement on (v, -v): MFREE_ERR_ARG on every rank alike when the ranks passed
// different values of an argument that must be common (the message names the lowest
// ranks holding the smallest and the largest value).
inline mfree_status_t same_everywhere(mfree_context_t *ctx, const char *fn, const char *what, const Loc &lo,
                                      const Loc &neg_hi) noexcept {
  if (lo.v == -neg_hi.v) return MFREE_SUCCESS;
  char buf[256];
  std::snprintf(buf, sizeof buf, "ranks disagree on %s: rank %d passes %.17g, rank %d passes %.17g (every rank must pass the same)",
                what, lo.r, lo.v, neg_hi.r, -neg_hi.v);
  return record(ctx, MFREE_ERR_ARG, fn, buf);
}

// A failure of a core call inside a local step: its status and the message it left on
// the context it recorded it on.
inline void core_fail(Local &l, mfree_status_t st, mfree_context_t *ctx) {
  char msg[400] = {0};
  mfree_context_get_last_error(ctx, nullptr, msg, sizeof msg);
  l.fail(st, msg);
}

// An MPI call inside a local step: its failure becomes MFREE_ERR_INTERNAL.
inline void mpi_ok(Local &l, int rc, const char *what) {
  if (rc != MPI_SUCCESS) l.fail(MFREE_ERR_INTERNAL, std::string(what) + " failed");
}

// A failure a binding found on its rank before a collective call (an array too short),
// handed to that call so that the rank still takes part and every rank returns it
// (mfree_halo_set_pending_error, mfree_migration_set_pending_error).
struct Pending {
  mfree_status_t st = MFREE_SUCCESS;
  char msg[512] = {0};

  // The context's last failure becomes the pending one ("fn: reason" as
  // mfree_context_set_error got it: the collective call adds its own name).
  mfree_status_t take_from(mfree_context_t *ctx, const char *fn) noexcept {
    mfree_status_t code = MFREE_SUCCESS;
    char text[sizeof msg] = {0};
    mfree_context_get_last_error(ctx, &code, text, sizeof text);
    if (code >= 0) return record(ctx, MFREE_ERR_STATE, fn, "the context holds no failure to hand over");
    const char *colon = std::strstr(text, ": ");
    const char *reason = colon && std::strncmp(text, "mfree_", 6) == 0 ? colon + 2 : text;
    st = code;
    std::snprintf(msg, sizeof msg, "%s", reason);
    return MFREE_SUCCESS;
  }

  // A collective call's local step: the pending failure (taken: it is reported once),
  // else body's outcome.
  template <class Body>
  Local first_step(Body &&body) noexcept {
    if (st == MFREE_SUCCESS) return run_local(body);
    Local l;
    l.st = st;
    st = MFREE_SUCCESS;
    try {
      l.msg = msg;
    } catch (...) {
    }
    return l;
  }
};

// halo.cpp: a plan's pending failure, taken (MFREE_SUCCESS when none), for the
// collective calls outside halo.cpp (the all-gather of systems on ranks).
mfree_status_t take_pending(mfree_halo_t *h, std::string &msg) noexcept;
// halo.cpp: a set-up plan's global ids (owned, then ghosts), borrowed until its next setup.
const int64_t *halo_ids(const mfree_halo_t *h) noexcept;

}  // namespace mfree_mpi_detail

#endif  // MFREE_MPI_COLLECTIVE_HPP
