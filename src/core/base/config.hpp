// The per-call options a context gives the core, and the debugging overrides from the
// environment.
//
// The C layer installs the calling handle's context's options for the duration of the
// call (ConfigScope, thread-local; parallel_blocks carries them into its threads), as it
// does the allocator hook and the thread count: core code asks call_config() and never
// sees a context.
//   backend : MFREE_BACKEND_OPT (default) runs the optimised paths where a method has
//             one (the shape-function fast path, the fixed-size apply kernels with their
//             AVX2 + FMA copies); MFREE_BACKEND_REF the reference path everywhere (the
//             general Eigen shape functions, one plain loop for every operator), the
//             oracle the optimised path must match to round-off.
//   pages   : MFREE_PAGES_HUGE and MFREE_PAGES_PREFAULT, OS-level tuning of the
//             allocator (alloc.hpp), off unless the host asks: it costs system calls
//             and resident memory a host may not want to pay.
//
// The environment is read here and nowhere else in src/ (docs/performance.md lists the
// variables). They only restrict, for debugging: MFREE_SIMD=baseline keeps the optimised
// path on its baseline (SSE2) copy; MFREE_HUGEPAGES=0 turns huge pages and prefaulting off
// even for a context that asked for them.
#pragma once

#include <cstdint>

#include "mfree.h"

namespace mfree {

struct CallConfig {
  int32_t backend = MFREE_BACKEND_OPT;
  int32_t pages = 0;  // MFREE_PAGES_* flags
};

// The options of the running call on this thread (defaults outside a call).
inline const CallConfig *&current_config() {
  static thread_local const CallConfig *config = nullptr;
  return config;
}
inline const CallConfig &call_config() {
  static const CallConfig defaults;
  const CallConfig *c = current_config();
  return c ? *c : defaults;
}

// Installs the options of a context for a scope; restores the previous ones.
class ConfigScope {
 public:
  explicit ConfigScope(const CallConfig *c) : prev_(current_config()) { current_config() = c; }
  ~ConfigScope() { current_config() = prev_; }
  ConfigScope(const ConfigScope &) = delete;
  ConfigScope &operator=(const ConfigScope &) = delete;

 private:
  const CallConfig *prev_;
};

// True when the running call may take the optimised paths.
inline bool optimised() { return call_config().backend == MFREE_BACKEND_OPT; }

namespace env {
// MFREE_SIMD=baseline. Read at every call (a scan of the environment, once per call, not
// per site), so that a host or a test may set it between calls.
bool simd_baseline();
// MFREE_HUGEPAGES=0, read once.
bool hugepages_off();
}  // namespace env

}  // namespace mfree
