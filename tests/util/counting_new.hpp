// Heap counting for the C++ no-allocation tests (t433, t707): replaces the global
// operator new/delete of the test program and counts the allocations made while
// g_counting is set (std::vector, std::string and every other allocation of the C++
// standard library inside libmfree, which the context's allocator hook cannot see);
// hook_alloc/hook_free, for mfree_context_set_allocator, count the hook's allocations in
// g_hook; CHECK/OK count failed checks in `failures` (the program's exit status). Include it in exactly one translation unit of the test program (t433,
// t707); the test links with -Wno-mismatched-new-delete under GCC, which pairs the
// replaced delete (free) with the malloc inside the replaced new after inlining.
#ifndef MFREE_TESTS_COUNTING_NEW_HPP
#define MFREE_TESTS_COUNTING_NEW_HPP

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_new{0};  // allocations counted so far
bool g_counting = false;     // count while true
}  // namespace

void *operator new(std::size_t n) {
  if (g_counting) ++g_new;
  if (void *p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void *operator new[](std::size_t n) { return operator new(n); }
void *operator new(std::size_t n, const std::nothrow_t &) noexcept {
  if (g_counting) ++g_new;
  return std::malloc(n ? n : 1);
}
void *operator new[](std::size_t n, const std::nothrow_t &t) noexcept { return operator new(n, t); }
void operator delete(void *p) noexcept { std::free(p); }
void operator delete[](void *p) noexcept { std::free(p); }
void operator delete(void *p, std::size_t) noexcept { std::free(p); }
void operator delete[](void *p, std::size_t) noexcept { std::free(p); }

namespace {
std::atomic<long> g_hook{0};  // allocations through the context's allocator hook
void *hook_alloc(void *, int64_t bytes) {
  ++g_hook;
  return std::malloc(static_cast<size_t>(bytes));
}
void hook_free(void *, void *p, int64_t) { std::free(p); }

int failures = 0;
#define CHECK(cond, ...)                 \
  do {                                   \
    if (!(cond)) {                       \
      std::fprintf(stderr, __VA_ARGS__); \
      std::fprintf(stderr, "\n");        \
      ++failures;                        \
    }                                    \
  } while (0)
#define OK(call) CHECK((call) == MFREE_SUCCESS, "%s failed at line %d", #call, __LINE__)
}  // namespace

#endif
