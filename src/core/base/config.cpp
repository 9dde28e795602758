// The debugging overrides from the environment (config.hpp): the only getenv in src/.
#include "core/base/config.hpp"

#include <cstdlib>
#include <cstring>

namespace mfree {
namespace env {

bool simd_baseline() {
  const char *v = std::getenv("MFREE_SIMD");
  return v && std::strcmp(v, "baseline") == 0;
}

bool hugepages_off() {
  static const bool off = [] {
    const char *v = std::getenv("MFREE_HUGEPAGES");
    return v && v[0] == '0';
  }();
  return off;
}

}  // namespace env
}  // namespace mfree
