// The collective operations of a system spread over ranks, through the host's two
// callbacks (a forward halo exchange and an all-gather): the core never calls MPI. The
// agreement on an outcome (every rank returns the same status and the failing rank's
// message, so that no rank goes on alone into a collective call) is built on the
// all-gather.
#pragma once

#include <cstdint>
#include <new>
#include <string>
#include <vector>

#include "core/base/error.hpp"
#include "mfree.h"

namespace mfree {

class ExactSum;

// The outcome of local work as a report: a rank must reach the next agreement even when
// its own part failed.
template <class F>
Report guarded(F &&f) {
  Report r;
  try {
    r = f();
  } catch (const Error &e) {
    r.status = e.status();
    r.message = e.what();
  } catch (const std::bad_alloc &) {
    r.status = MFREE_ERR_ALLOC;
    r.message = "out of memory";
  }
  return r;
}

class Collective {
 public:
  Collective() = default;
  Collective(mfree_exchange_fn ex, mfree_allgather_fn ag, void *user) : ex_(ex), ag_(ag), user_(user) {}

  // Owners' values into the ghost items. A failing callback throws, alike on every rank
  // (the callbacks' contract).
  void exchange(int32_t ncomp, double *field, int64_t ld) const;
  // Every rank's n values in rank order, when the total is not known (two calls).
  std::vector<double> allgather(const double *in, int64_t n) const;
  // The same into out, whose size (the total) the caller knows to be total.
  void allgather(const double *in, int64_t n, double *out, int64_t total) const;
  // The number of ranks (one gather, the first time).
  int size() const;
  // The pointer the host gave with the callbacks (for its other callbacks).
  void *user() const { return user_; }
  // The host's all-gather (a system over a subset of the items relays it unchanged).
  mfree_allgather_fn allgather_fn() const { return ag_; }
  // The agreed outcome: the lowest rank holding an error (negative status) or, without
  // one, the lowest rank holding a failure (positive status); its status and "rank R:
  // <its message>". statuses: every rank's status, in rank order; mine: this rank's.
  Report agree_from(const std::vector<double> &statuses, const Report &mine) const;
  // agree_from after one gather of the statuses.
  Report agree(const Report &mine) const;

  // A fault of a collective call's arguments found on this rank before the call (a NULL
  // or short array): the call still takes part, on stand-in buffers, and the local step
  // before its first agreement (local) returns the fault instead of running, so that
  // every rank returns it and none waits for a rank that left. The caller clears it
  // after the call (a call that reached no agreement leaves it untaken).
  void set_pending(const Report &fault) const { pending_ = fault; }
  bool take_pending(Report &fault) const;
  // The local step before an agreement: the pending fault (taken) if there is one, the
  // step skipped; else f's outcome (guarded).
  template <class F>
  Report local(F &&f) const {
    Report r;
    if (take_pending(r)) return r;
    return guarded(f);
  }

  // The totals over every rank of n exact sums (each rank's s[k], normalised here, added
  // limb by limb): out[k] the exact total of every rank's terms, rounded once, so the
  // same bits on every rank whatever the partition. One all-gather.
  void exact_totals(ExactSum *s, int n, double *out) const;

  // Integers travel through the all-gather as the bits of a double.
  static double pack(int64_t v);
  static int64_t unpack(double d);

 private:
  mfree_exchange_fn ex_ = nullptr;
  mfree_allgather_fn ag_ = nullptr;
  void *user_ = nullptr;
  mutable int size_ = 0;
  mutable Report pending_;
};

}  // namespace mfree
