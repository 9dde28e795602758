// Internal to the adapter libraries (not installed): the message of a failure, recorded on
// the host's context through libmfree's public mfree_context_set_error (an adapter sees no
// core internals), and the guard that keeps every exception from crossing the C ABI.
// Header-only: each adapter compiles its own hidden copy, so that no adapter depends on
// another.
#ifndef MFREE_ADAPTERS_GUARD_HPP
#define MFREE_ADAPTERS_GUARD_HPP

#include "mfree.h"

#include <exception>
#include <new>
#include <string>

namespace mfree_adapter {

// "fn: msg" on ctx with status st; returns st.
inline mfree_status_t record(mfree_context_t *ctx, mfree_status_t st, const char *fn,
                             const std::string &msg) noexcept {
  try {
    const std::string text = std::string(fn) + ": " + msg;
    mfree_context_set_error(ctx, st, text.c_str());
  } catch (...) {  // no memory for the message: keep at least the code and the function
    mfree_context_set_error(ctx, st, fn);
  }
  return st;
}

// Run an mfree_status_t body: no exception leaves the C ABI.
template <class Body>
mfree_status_t guarded(mfree_context_t *ctx, const char *fn, Body &&body) noexcept {
  try {
    return body();
  } catch (const std::bad_alloc &) {
    return record(ctx, MFREE_ERR_ALLOC, fn, "out of memory");
  } catch (const std::exception &e) {
    try {
      return record(ctx, MFREE_ERR_INTERNAL, fn, std::string("internal error: ") + e.what());
    } catch (...) {
      return MFREE_ERR_INTERNAL;
    }
  } catch (...) {
    return MFREE_ERR_INTERNAL;
  }
}

}  // namespace mfree_adapter

#endif
