// The up-front size check of the big allocations (alloc.hpp, request_too_large): a
// neighbour search or shape-function table that would need more than the machine's
// memory fails with MFREE_ERR_ALLOC before allocating, instead of being granted by the
// kernel's overcommit and killing the host when touched. Requests that large cannot be
// made in a test, so this checks the decision itself (linked with the static library):
//  - above the limit without a hook: refused; at or below it: allowed;
//  - with the context's allocator hook installed: never refused here (the host's
//    allocator sees the request and decides);
//  - the default limit is the machine's physical memory, read from the system.
#include <cstdio>
#include <cstdlib>

#include "core/base/alloc.hpp"

namespace {
int failures = 0;
void expect(bool ok, const char *what) {
  if (!ok) {
    std::fprintf(stderr, "FAILED: %s\n", what);
    ++failures;
  }
}
void *host_alloc(void *, int64_t bytes) { return std::malloc(static_cast<size_t>(bytes)); }
void host_free(void *, void *p, int64_t) { std::free(p); }
}  // namespace

int main() {
  using mfree::request_too_large;
  expect(request_too_large(2e9, 1e9), "2 GB against a 1 GB limit is refused");
  expect(!request_too_large(1e9, 1e9), "1 GB against a 1 GB limit is allowed");
  expect(!request_too_large(1e9, 0.0), "an unknown limit (0) refuses nothing");
  const double phys = mfree::physical_memory();
  expect(phys > 1e8, "the physical memory is known (Linux)");
  expect(request_too_large(2.0 * phys), "twice the physical memory is refused by default");
  expect(!request_too_large(0.01 * phys), "a hundredth of it is allowed");
  {
    mfree::AllocHook hook;
    hook.alloc = host_alloc;
    hook.release = host_free;
    const mfree::AllocScope scope(&hook);
    expect(!request_too_large(2e9, 1e9), "with a hook the host's allocator decides");
  }
  expect(request_too_large(2e9, 1e9), "the hook's scope ended");
  if (failures == 0) std::printf("t066: all checks passed\n");
  return failures == 0 ? 0 : 1;
}
