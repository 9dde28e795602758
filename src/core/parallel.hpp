// Threads of the running call: the C layer sets the calling context's thread count for
// the call (ThreadScope, thread-local); core loops ask num_threads() and split their
// sites statically, so that every site is computed by the same code whatever the count
// and results are bitwise identical for any number of threads. Without OpenMP all runs
// serially. mfree never calls omp_set_*.
#pragma once

#include <cstdint>
#include <exception>

#include "alloc.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mfree {

inline int32_t &requested_threads() {
  static thread_local int32_t n = 1;
  return n;
}

class ThreadScope {
 public:
  explicit ThreadScope(int32_t n) : prev_(requested_threads()) { requested_threads() = n; }
  ~ThreadScope() { requested_threads() = prev_; }
  ThreadScope(const ThreadScope &) = delete;
  ThreadScope &operator=(const ThreadScope &) = delete;

 private:
  int32_t prev_;
};

// Threads to use for `work` independent items (0 requested: all processors); one thread
// for small batches, where starting a team costs more than it saves.
inline int num_threads(int64_t work) {
#ifdef _OPENMP
  int n = requested_threads();
  if (n <= 0) n = omp_get_num_procs();
  if (work < 2048) n = 1;
  return n < 1 ? 1 : n;
#else
  (void)work;
  return 1;
#endif
}

// Contiguous block [begin, end) of `count` items for thread t of nt (static split).
inline void thread_block(int64_t count, int t, int nt, int64_t &begin, int64_t &end) {
  const int64_t q = count / nt, r = count % nt;
  begin = t * q + (t < r ? t : r);
  end = begin + q + (t < r ? 1 : 0);
}

// Run body(t, begin, end) on nt threads over static blocks of count items, with the
// caller's allocator hook installed on every thread. Exceptions are caught per thread
// and the first (lowest thread) is rethrown after the region.
template <class Body>
void parallel_blocks(int64_t count, int nt, Body &&body) {
  if (nt <= 1) {
    body(0, int64_t{0}, count);
    return;
  }
#ifdef _OPENMP
  const AllocHook *hook = current_alloc_hook();
  std::exception_ptr err[64];
  if (nt > 64) nt = 64;
#pragma omp parallel num_threads(nt)
  {
    const int t = omp_get_thread_num(), team = omp_get_num_threads();
    AllocScope scope(hook);
    ThreadScope one(1);
    int64_t b, e;
    thread_block(count, t, team, b, e);
    try {
      body(t, b, e);
    } catch (...) {
      err[t] = std::current_exception();
    }
  }
  for (int t = 0; t < nt; ++t)
    if (err[t]) std::rethrow_exception(err[t]);
#else
  body(0, int64_t{0}, count);
#endif
}

}  // namespace mfree
