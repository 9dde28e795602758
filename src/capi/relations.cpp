// An object's context and particle set, for host wrappers (the Fortran module) that
// check arguments themselves: they size the caller's arrays from the particle set and
// record their failures on the context, where mfree records its own. (Systems: in
// system.cpp, where their handle is defined.)
#include "handles.hpp"

namespace {

template <class H>
mfree_status_t context_of(const H *h, mfree_context_t **ctx) noexcept {
  if (!h || !ctx) return MFREE_ERR_NULL;
  *ctx = h->ctx;
  return MFREE_SUCCESS;
}

}  // namespace

extern "C" {

mfree_status_t mfree_particles_get_context(const mfree_particles_t *ps, mfree_context_t **ctx) {
  return context_of(ps, ctx);
}
mfree_status_t mfree_approximant_get_context(const mfree_approximant_t *a, mfree_context_t **ctx) {
  return context_of(a, ctx);
}
mfree_status_t mfree_mesh_get_context(const mfree_mesh_t *mesh, mfree_context_t **ctx) {
  return context_of(mesh, ctx);
}
mfree_status_t mfree_matrix_get_context(const mfree_matrix_t *A, mfree_context_t **ctx) {
  return context_of(A, ctx);
}
mfree_status_t mfree_assembler_get_context(const mfree_assembler_t *as, mfree_context_t **ctx) {
  return context_of(as, ctx);
}


mfree_status_t mfree_approximant_get_particles(const mfree_approximant_t *a,
                                               mfree_particles_t **ps) {
  if (!a || !ps) return MFREE_ERR_NULL;
  *ps = a->ps;
  return MFREE_SUCCESS;
}
mfree_status_t mfree_mesh_get_particles(const mfree_mesh_t *mesh, mfree_particles_t **ps) {
  if (!mesh || !ps) return MFREE_ERR_NULL;
  *ps = mesh->ps;
  return MFREE_SUCCESS;
}

}  // extern "C"
