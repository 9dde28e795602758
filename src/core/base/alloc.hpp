// The context's allocator hook (mfree_context_set_allocator) as a C++ allocator.
//
// The C layer installs the hook of the calling handle's context for the duration of the
// call (AllocScope, thread-local, also inside OpenMP regions); HostAllocator takes every
// block from the hook in force when it is allocated and records in a small header which
// function pair made it, so that a block goes back to its own allocator even when it is
// freed in a later call, on another context, or after the host changed the hook. Without
// a hook, blocks come from malloc; when the call's context asks for huge pages
// (config.hpp, MFREE_PAGES_HUGE), big ones (>= 2 MiB) on Linux come from their own
// mapping with transparent huge pages requested (madvise), see huge_map, unless a
// SmallPages scope asks for malloc's small pages (blocks whose first touch matters most);
// with MFREE_PAGES_PREFAULT, prefault faults a block in with one system call. The big per-object arrays (neighbour
// lists, shape function tables, per-site scratch) are HVec; small bookkeeping uses
// std::allocator.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#endif

#include "core/base/config.hpp"
#include "mfree.h"

namespace mfree {

struct AllocHook {
  mfree_alloc_fn alloc = nullptr;
  mfree_free_fn release = nullptr;
  void *user = nullptr;
};

// The hook of the running call on this thread (nullptr: malloc).
inline const AllocHook *&current_alloc_hook() {
  static thread_local const AllocHook *hook = nullptr;
  return hook;
}

// Installs a hook for a scope; restores the previous one (calls may nest).
class AllocScope {
 public:
  explicit AllocScope(const AllocHook *h) : prev_(current_alloc_hook()) {
    current_alloc_hook() = (h && h->alloc) ? h : nullptr;
  }
  ~AllocScope() { current_alloc_hook() = prev_; }
  AllocScope(const AllocScope &) = delete;
  AllocScope &operator=(const AllocScope &) = delete;

 private:
  const AllocHook *prev_;
};

namespace detail {
// Header in front of every block; 32 bytes keep malloc's 16-byte alignment.
struct alignas(16) BlockHeader {
  mfree_free_fn release;
  void *user;
  int64_t bytes;
};
static_assert(sizeof(BlockHeader) % 16 == 0, "header keeps 16-byte alignment");

// Huge-page blocks (no hook installed, Linux). On a virtual machine every first touch of
// a 4 KiB page is a fault plus, often, a fill of the host's page tables (a large share of
// the first neighbour search of a set); a 2 MiB transparent huge page costs one fault and
// a clear, less than its 512 small pages. So a block of at least kHugeMin bytes gets a
// mapping of its own, aligned to 2 MiB and advised MADV_HUGEPAGE; its header records the
// mapping (user == huge_tag(), bytes = mapped length) and freeing it unmaps it. The
// length is rounded up to whole huge pages when that adds at most an eighth (a touched
// huge page is resident whole), else to small pages (the tail then takes small pages).
// Only when the call's context asks for it (MFREE_PAGES_HUGE); off when the kernel's THP
// mode is "never", when the small page is not 4 KiB (the PMD huge page is then not
// 2 MiB), and with MFREE_HUGEPAGES=0 in the environment (config.hpp); a failing mmap
// falls back to malloc. With a hook installed, every block is the
// host's (the hook sees every byte).
constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kHugeMin = std::size_t{2} << 20;

inline void *huge_tag() {
  static char tag;
  return &tag;
}

#if defined(__linux__) && defined(MADV_HUGEPAGE)
inline bool huge_pages_enabled() {
  if (!(call_config().pages & MFREE_PAGES_HUGE)) return false;
  static const bool on = [] {
    if (env::hugepages_off()) return false;
    if (sysconf(_SC_PAGESIZE) != 4096) return false;
    bool never = false;
    if (std::FILE *f = std::fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r")) {
      char line[128] = {0};
      if (std::fgets(line, sizeof line, f)) never = std::strstr(line, "[never]") != nullptr;
      std::fclose(f);
    } else {
      never = true;  // no THP support in this kernel
    }
    return !never;
  }();
  return on;
}

// A mapping of at least `total` bytes starting on a 2 MiB boundary (nullptr: failed);
// *mapped = its length.
inline void *huge_map(std::size_t total, std::size_t *mapped) noexcept {
  const std::size_t small = 4096;
  std::size_t len = (total + small - 1) / small * small;
  const std::size_t whole = (total + kHugePage - 1) / kHugePage * kHugePage;
  if (whole - total <= total / 8) len = whole;
  void *raw = mmap(nullptr, len + kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) return nullptr;
  const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t b = (a + kHugePage - 1) & ~static_cast<std::uintptr_t>(kHugePage - 1);
  const std::uintptr_t end = a + len + kHugePage;
  if (b > a) munmap(raw, b - a);
  if (end > b + len) munmap(reinterpret_cast<void *>(b + len), end - (b + len));
  madvise(reinterpret_cast<void *>(b), len, MADV_HUGEPAGE);  // advice: failure is harmless
  *mapped = len;
  return reinterpret_cast<void *>(b);
}
inline void huge_unmap(void *p, std::size_t len) noexcept { munmap(p, len); }
#else
inline bool huge_pages_enabled() { return false; }
inline void *huge_map(std::size_t, std::size_t *) noexcept { return nullptr; }
inline void huge_unmap(void *, std::size_t) noexcept {}
#endif

// Depth of the SmallPages scopes alive on this thread (see below).
inline int &small_pages_depth() {
  static thread_local int depth = 0;
  return depth;
}

inline void *hook_allocate(std::size_t bytes) {
  const AllocHook *h = current_alloc_hook();
  const std::size_t total = bytes + sizeof(BlockHeader);
  if (total < bytes || total > static_cast<std::size_t>(INT64_MAX) - kHugePage) throw std::bad_alloc();
  void *raw = nullptr;
  void *user = h ? h->user : nullptr;
  if (h) {
    raw = h->alloc(h->user, static_cast<int64_t>(total));
  } else {
    std::size_t len = total;
    if (total >= kHugeMin && small_pages_depth() == 0 && huge_pages_enabled()) raw = huge_map(total, &len);
    if (raw) user = huge_tag();
    else raw = std::malloc(total);
    if (raw) {
      auto *hdr = static_cast<BlockHeader *>(raw);
      hdr->release = nullptr;
      hdr->user = user;
      hdr->bytes = static_cast<int64_t>(len);
      return hdr + 1;
    }
  }
  if (!raw) throw std::bad_alloc();
  auto *hdr = static_cast<BlockHeader *>(raw);
  hdr->release = h->release;
  hdr->user = user;
  hdr->bytes = static_cast<int64_t>(total);
  return hdr + 1;
}

inline void hook_deallocate(void *p) noexcept {
  if (!p) return;
  BlockHeader *hdr = static_cast<BlockHeader *>(p) - 1;
  if (hdr->release) hdr->release(hdr->user, hdr, hdr->bytes);
  else if (hdr->user == huge_tag()) huge_unmap(hdr, static_cast<std::size_t>(hdr->bytes));
  else std::free(hdr);
}
}  // namespace detail

// When the call's context asks for it (MFREE_PAGES_PREFAULT; not with MFREE_HUGEPAGES=0):
// faults in the whole pages of [p, p + bytes) in one system call (MADV_POPULATE_WRITE,
// Linux 5.14), for a block about to be written front to back for the first time: the
// kernel fills the page tables in one pass instead of one trap per 4 KiB page (cheaper
// per page than the traps, on a virtual machine also when the host must
// back them anew). Only without a hook (a host's memory is the host's business) and for
// at least 64 KiB; a kernel without it (EINVAL) is remembered. Contents are unchanged
// (pages already present stay as they are; new ones are zero).
inline void prefault(void *p, std::size_t bytes) noexcept {
#if defined(__linux__)
#ifndef MADV_POPULATE_WRITE
#define MFREE_MADV_POPULATE_WRITE 23
#else
#define MFREE_MADV_POPULATE_WRITE MADV_POPULATE_WRITE
#endif
  static std::atomic<bool> unsupported{false};
  if (current_alloc_hook() || bytes < (std::size_t{64} << 10) || unsupported.load(std::memory_order_relaxed)) return;
  if (!(call_config().pages & MFREE_PAGES_PREFAULT) || env::hugepages_off()) return;
  const std::uintptr_t a = (reinterpret_cast<std::uintptr_t>(p) + 4095) & ~static_cast<std::uintptr_t>(4095);
  const std::uintptr_t b = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~static_cast<std::uintptr_t>(4095);
  if (b <= a) return;
  if (madvise(reinterpret_cast<void *>(a), b - a, MFREE_MADV_POPULATE_WRITE) != 0 && errno == EINVAL)
    unsupported.store(true, std::memory_order_relaxed);
#undef MFREE_MADV_POPULATE_WRITE
#else
  (void)p;
  (void)bytes;
#endif
}

// Blocks allocated on this thread while a SmallPages scope is alive take small pages
// (malloc) however big they are; with a hook installed nothing changes (every block is
// the host's). For blocks whose first touch matters more than the TLB reach of later
// reads: on a virtual machine with free-page reporting a huge page comes from memory the
// host has taken back (order-9 blocks are what the guest reports) and costs several
// times more to fault than small pages, which mostly come from memory the host still
// backs; only huge pages freed within the last seconds are cheaper.
class SmallPages {
 public:
  SmallPages() { ++detail::small_pages_depth(); }
  ~SmallPages() { --detail::small_pages_depth(); }
  SmallPages(const SmallPages &) = delete;
  SmallPages &operator=(const SmallPages &) = delete;
};

// The machine's physical memory in bytes (0: unknown), read once.
inline double physical_memory() {
#if defined(__linux__)
  static const double bytes = [] {
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? static_cast<double>(pages) * static_cast<double>(size) : 0.0;
  }();
  return bytes;
#else
  return 0.0;
#endif
}

// Whether a request of `bytes` must be refused up front: more than `limit` (default: the
// physical memory), without a hook installed (with one the host's allocator decides).
// The kernel's overcommit would otherwise grant it and kill the host when the pages are
// touched, instead of the call failing with MFREE_ERR_ALLOC.
inline bool request_too_large(double bytes, double limit = physical_memory()) {
  return current_alloc_hook() == nullptr && limit > 0.0 && bytes > limit;
}

template <class T>
struct HostAllocator {
  using value_type = T;
  HostAllocator() noexcept = default;
  template <class U>
  HostAllocator(const HostAllocator<U> &) noexcept {}
  T *allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T) / 2) throw std::bad_alloc();
    return static_cast<T *>(detail::hook_allocate(n * sizeof(T)));
  }
  void deallocate(T *p, std::size_t) noexcept { detail::hook_deallocate(p); }
  template <class U>
  bool operator==(const HostAllocator<U> &) const noexcept { return true; }
  template <class U>
  bool operator!=(const HostAllocator<U> &) const noexcept { return false; }
};

// A vector whose storage comes from the context's hook. It converts to a std::vector
// copy, so that code holding plain vectors can take a table by assignment.
template <class T>
class HVec : public std::vector<T, HostAllocator<T>> {
 public:
  using Base = std::vector<T, HostAllocator<T>>;
  using Base::Base;
  operator std::vector<T>() const { return std::vector<T>(this->begin(), this->end()); }
};

// Element-wise comparison with plain vectors (code that keeps copies of a table).
template <class T>
bool operator==(const HVec<T> &a, const std::vector<T> &b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
}
template <class T>
bool operator==(const std::vector<T> &b, const HVec<T> &a) { return a == b; }
template <class T>
bool operator!=(const HVec<T> &a, const std::vector<T> &b) { return !(a == b); }
template <class T>
bool operator!=(const std::vector<T> &b, const HVec<T> &a) { return !(a == b); }

}  // namespace mfree
