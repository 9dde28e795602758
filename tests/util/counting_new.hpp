// Replaces the global operator new/delete of a C++ test program and counts the
// allocations made while g_counting is set (std::vector, std::string and every other
// allocation of the C++ standard library inside libmfree, which the context's allocator
// hook cannot see). Include it in exactly one translation unit of the test program (t433,
// t707); the test links with -Wno-mismatched-new-delete under GCC, which pairs the
// replaced delete (free) with the malloc inside the replaced new after inlining.
#ifndef MFREE_TESTS_COUNTING_NEW_HPP
#define MFREE_TESTS_COUNTING_NEW_HPP

#include <atomic>
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

#endif
