// Threads of the running call: the C layer sets the calling context's thread count for
// the call (ThreadScope, thread-local); core loops ask num_threads() and split their
// sites statically, so that every site is computed by the same code whatever the count
// and results are bitwise identical for any number of threads. Without OpenMP all runs
// serially. mfree never calls omp_set_*.
#pragma once

#include <cstdint>
#include <exception>

#include "core/base/alloc.hpp"
#include "core/base/config.hpp"

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

// Most blocks (and threads) a parallel region uses; per-block arrays of this size are
// always large enough.
constexpr int kMaxBlocks = 64;

// The block count parallel_blocks(count, nt, ...) splits into: nt clamped to
// [1, kMaxBlocks]. Block t is thread_block(count, t, block_count(nt)), whatever team the
// OpenMP runtime grants, so a later pass that re-derives the blocks from nt agrees with
// what an earlier one wrote per block.
inline int block_count(int nt) { return nt < 1 ? 1 : (nt > kMaxBlocks ? kMaxBlocks : nt); }

// Run body(t, begin, end) over the static blocks t = 0 .. block_count(nt) - 1 of count
// items, with the caller's allocator hook and options installed on every thread. The layout never
// depends on the team size: if the runtime grants fewer threads than asked (thread
// limit, nested region, OMP_DYNAMIC), each thread runs several whole blocks in turn
// (thread k: blocks k, k + team, ...), so `t` is always a block index below
// block_count(nt), and per-block buffers indexed by it are never shared by two threads
// at once. Exceptions are caught per block and the first (lowest block) is rethrown
// after the region.
template <class Body>
void parallel_blocks(int64_t count, int nt, Body &&body) {
  nt = block_count(nt);
  if (nt == 1) {
    body(0, int64_t{0}, count);
    return;
  }
#ifdef _OPENMP
  const AllocHook *hook = current_alloc_hook();
  const CallConfig *config = current_config();
  std::exception_ptr err[kMaxBlocks];
#pragma omp parallel num_threads(nt)
  {
    const int team = omp_get_num_threads();
    AllocScope scope(hook);
    ConfigScope config_scope(config);
    ThreadScope one(1);
    for (int t = omp_get_thread_num(); t < nt; t += team) {
      int64_t b, e;
      thread_block(count, t, nt, b, e);
      try {
        body(t, b, e);
      } catch (...) {
        err[t] = std::current_exception();
      }
    }
  }
  for (int t = 0; t < nt; ++t)
    if (err[t]) std::rethrow_exception(err[t]);
#else
  for (int t = 0; t < nt; ++t) {
    int64_t b, e;
    thread_block(count, t, nt, b, e);
    body(t, b, e);
  }
#endif
}

}  // namespace mfree
