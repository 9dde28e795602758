#include "handles.hpp"

extern "C" {

const char *mfree_version_string(void) { return MFREE_VERSION_STRING; }

mfree_status_t mfree_version_get(int32_t *major, int32_t *minor, int32_t *patch) {
  if (major) *major = MFREE_VERSION_MAJOR;
  if (minor) *minor = MFREE_VERSION_MINOR;
  if (patch) *patch = MFREE_VERSION_PATCH;
  return MFREE_SUCCESS;
}

const char *mfree_status_string(mfree_status_t s) {
  switch (s) {
    case MFREE_SUCCESS: return "success";
    case MFREE_ERR_NULL: return "NULL handle or pointer";
    case MFREE_ERR_ARG: return "argument out of range";
    case MFREE_ERR_STATE: return "call not allowed in the object's state";
    case MFREE_ERR_ALLOC: return "out of memory";
    case MFREE_ERR_MISMATCH: return "objects or sizes do not match";
    case MFREE_ERR_UNSUPPORTED: return "not supported by this method or kernel";
    case MFREE_ERR_INPUT: return "invalid values in an input array";
    case MFREE_ERR_HALO: return "a support reaches past the declared halo width";
    case MFREE_ERR_INTERNAL: return "internal error";
    case MFREE_FAIL_NONFINITE: return "non-finite value in data or result";
    case MFREE_FAIL_INVALID_DATA: return "data value out of range";
    case MFREE_FAIL_SINGULAR: return "singular or ill-conditioned local system";
    case MFREE_FAIL_NEIGHBORS: return "too few neighbours";
    case MFREE_FAIL_DOMAIN: return "a particle left the domain";
    case MFREE_FAIL_CFL: return "time step violates the CFL condition";
    case MFREE_FAIL_SUPPORT: return "kernel support exceeds the method's size limit";
    case MFREE_FAIL_CAPACITY: return "the pool of dormant particles is exhausted";
  }
  return "unknown status";
}

}  // extern "C"
