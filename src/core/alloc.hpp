// The context's allocator hook (mfree_context_set_allocator) as a C++ allocator.
//
// The C layer installs the hook of the calling handle's context for the duration of the
// call (AllocScope, thread-local, also inside OpenMP regions); HostAllocator takes every
// block from the hook in force when it is allocated and records in a small header which
// function pair made it, so that a block goes back to its own allocator even when it is
// freed in a later call, on another context, or after the host changed the hook. Without
// a hook, blocks come from malloc. The big per-object arrays (neighbour lists, shape
// function tables, per-site scratch) are HVec; small bookkeeping uses std::allocator.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <vector>

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

inline void *hook_allocate(std::size_t bytes) {
  const AllocHook *h = current_alloc_hook();
  const std::size_t total = bytes + sizeof(BlockHeader);
  if (total < bytes) throw std::bad_alloc();
  void *raw = h ? h->alloc(h->user, static_cast<int64_t>(total)) : std::malloc(total);
  if (!raw) throw std::bad_alloc();
  auto *hdr = static_cast<BlockHeader *>(raw);
  hdr->release = h ? h->release : nullptr;
  hdr->user = h ? h->user : nullptr;
  hdr->bytes = static_cast<int64_t>(total);
  return hdr + 1;
}

inline void hook_deallocate(void *p) noexcept {
  if (!p) return;
  BlockHeader *hdr = static_cast<BlockHeader *>(p) - 1;
  if (hdr->release) hdr->release(hdr->user, hdr, hdr->bytes);
  else std::free(hdr);
}
}  // namespace detail

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
