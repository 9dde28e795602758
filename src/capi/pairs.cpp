// Pair lists in, per-pair gradients and per-particle correction data out.
#include <string>

#include "handles.hpp"

namespace {

// A caller buffer of `capacity` doubles holding `count` records of `ncomp` values every
// `ld` doubles: checked before anything is written.
void check_records(const double *buf, int64_t count, int ncomp, int64_t ld, int64_t capacity,
                   const char *what) {
  if (ld < ncomp)
    throw mfree::Error(MFREE_ERR_ARG, std::string("leading dimension of ") + what + " is " +
                                          std::to_string(ld) + ", below " + std::to_string(ncomp));
  if (capacity < 0)
    throw mfree::Error(MFREE_ERR_ARG, std::string("capacity of ") + what + " is negative");
  if (count == 0) return;
  if (!buf) throw mfree::Error(MFREE_ERR_NULL, std::string(what) + " is NULL");
  const int64_t need = (count - 1) * ld + ncomp;
  if (capacity < need)
    throw mfree::Error(MFREE_ERR_ARG, std::string(what) + " holds " + std::to_string(capacity) +
                                          " doubles, " + std::to_string(need) + " are needed (" +
                                          std::to_string(count) + " records, leading dimension " +
                                          std::to_string(ld) + ")");
}

int64_t checked_pairs(const mfree::Approximant &ap) {
  const mfree::ParticleSet &ps = ap.particles();
  MFREE_REQUIRE(ps.has_pairs(), MFREE_ERR_STATE,
                "the particle set has no pair list (mfree_particles_set_pairs)");
  MFREE_REQUIRE(ps.is_setup(), MFREE_ERR_STATE, "the particle set is not set up");
  return ps.num_pairs();
}

}  // namespace

extern "C" {

mfree_status_t mfree_particles_set_pairs(mfree_particles_t *ps, int64_t npairs,
                                         const int32_t *pair_i, const int32_t *pair_j,
                                         int32_t index_base, mfree_mem_t mem) {
  return mfree::with_handle(ps, "mfree_particles_set_pairs", [&](mfree::ParticleSet &s) {
    s.set_pairs(npairs, pair_i, pair_j, index_base, mem);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_get_num_pairs(const mfree_particles_t *ps, int64_t *npairs) {
  return mfree::with_handle(ps, "mfree_particles_get_num_pairs", [&](const mfree::ParticleSet &s) {
    MFREE_REQUIRE(npairs, MFREE_ERR_NULL, "output pointer is NULL");
    MFREE_REQUIRE(s.has_pairs(), MFREE_ERR_STATE,
                  "the particle set has no pair list (mfree_particles_set_pairs)");
    *npairs = s.num_pairs();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_get_pair_gradients(const mfree_approximant_t *a, double *gi,
                                                    double *gj, int64_t ld, int64_t capacity) {
  return mfree::with_handle(a, "mfree_approximant_get_pair_gradients", [&](const mfree::Approximant &ap) {
    MFREE_REQUIRE(ap.is_setup(), MFREE_ERR_STATE, "the approximant is not set up");
    const int64_t np = checked_pairs(ap);
    check_records(gi, np, ap.dim(), ld, capacity, "gi");
    if (gj) check_records(gj, np, ap.dim(), ld, capacity, "gj");
    ap.pair_gradients(gi, gj, ld, false);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_get_pair_gradients_antisymmetric(const mfree_approximant_t *a,
                                                                  double *g, int64_t ld,
                                                                  int64_t capacity) {
  return mfree::with_handle(
      a, "mfree_approximant_get_pair_gradients_antisymmetric", [&](const mfree::Approximant &ap) {
        MFREE_REQUIRE(ap.is_setup(), MFREE_ERR_STATE, "the approximant is not set up");
        const int64_t np = checked_pairs(ap);
        check_records(g, np, ap.dim(), ld, capacity, "g");
        ap.pair_gradients(g, nullptr, ld, true);
        return MFREE_SUCCESS;
      });
}

mfree_status_t mfree_approximant_get_correction_size(const mfree_approximant_t *a,
                                                     int32_t *ncoef) {
  return mfree::with_handle(a, "mfree_approximant_get_correction_size", [&](const mfree::Approximant &ap) {
    MFREE_REQUIRE(ncoef, MFREE_ERR_NULL, "output pointer is NULL");
    *ncoef = ap.correction_size();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_get_correction(const mfree_approximant_t *a, double *c,
                                                int64_t ld, int64_t capacity) {
  return mfree::with_handle(a, "mfree_approximant_get_correction", [&](const mfree::Approximant &ap) {
    const int m = ap.correction_size();
    MFREE_REQUIRE(ap.is_setup(), MFREE_ERR_STATE, "the approximant is not set up");
    check_records(c, ap.num_sites(), m, ld, capacity, "c");
    ap.correction(c, ld);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_set_ghost_correction(mfree_approximant_t *a, const double *c,
                                                     int64_t ld, int64_t capacity) {
  return mfree::with_handle(a, "mfree_approximant_set_ghost_correction", [&](mfree::Approximant &ap) {
    MFREE_REQUIRE(ap.is_setup(), MFREE_ERR_STATE, "the approximant is not set up");
    const int m = ap.correction_size();
    const mfree::ParticleSet &ps = ap.particles();
    check_records(c, ps.size() - ps.num_owned(), m, ld, capacity, "c");
    ap.set_ghost_correction(c, ld);
    return MFREE_SUCCESS;
  });
}

}  // extern "C"
