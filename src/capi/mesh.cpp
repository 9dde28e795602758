// Meshes over particle sets and the MPFEM options of approximants (paper 004).
#include "handles.hpp"

namespace {

void release_mesh(mfree_mesh_t *m) {
  if (m && m->refs.fetch_sub(1, std::memory_order_acq_rel) == 1) {
    mfree_particles_t *p = m->ps;
    mfree_context_t *c = m->ctx;
    delete m;
    mfree::release(p);
    mfree::release(c);
  }
}

}  // namespace

extern "C" {

mfree_status_t mfree_mesh_create(mfree_context_t *ctx, mfree_particles_t *ps, mfree_mesh_t **mesh) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_mesh_create", [&]() {
    MFREE_REQUIRE(mesh, MFREE_ERR_NULL, "output pointer is NULL");
    *mesh = nullptr;
    MFREE_REQUIRE(ps, MFREE_ERR_NULL, "particle set is NULL");
    auto *m = new mfree_mesh_t(ctx, ps);
    mfree::retain(ctx);
    mfree::retain(ps);
    *mesh = m;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_mesh_destroy(mfree_mesh_t **mesh) {
  if (!mesh || !*mesh) return MFREE_SUCCESS;
  release_mesh(*mesh);
  *mesh = nullptr;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_mesh_add_elements(mfree_mesh_t *mesh, mfree_element_t type, int32_t nelem,
                                       const int32_t *conn, int32_t index_base, mfree_mem_t mem) {
  return mfree::with_handle(mesh, "mfree_mesh_add_elements", [&](mfree::Mesh &m) {
    m.add_elements(type, nelem, conn, index_base, mem);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_mesh_setup(mfree_mesh_t *mesh) {
  return mfree::with_handle(mesh, "mfree_mesh_setup", [&](mfree::Mesh &m) {
    mfree::MeshGeometry g;
    g.build(m);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_mesh_get_size(const mfree_mesh_t *mesh, int32_t *nelem) {
  return mfree::with_handle(mesh, "mfree_mesh_get_size", [&](const mfree::Mesh &m) {
    MFREE_REQUIRE(nelem, MFREE_ERR_NULL, "output pointer is NULL");
    *nelem = m.num_elements();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_mesh_get_quadrature(mfree_mesh_t *mesh, int32_t ngauss, int32_t *npts,
                                         double *x, double *w) {
  return mfree::with_handle(mesh, "mfree_mesh_get_quadrature", [&](mfree::Mesh &m) {
    MFREE_REQUIRE(npts, MFREE_ERR_NULL, "npts pointer is NULL");
    MFREE_REQUIRE(ngauss >= 1 && ngauss <= 10, MFREE_ERR_ARG,
                  "ngauss = " + std::to_string(ngauss) + " is outside 1..10");
    mfree::MeshGeometry g;
    g.build(m);
    std::vector<double> xs, ws;
    g.quadrature(m.particles(), ngauss, xs, ws);
    *npts = static_cast<int32_t>(ws.size());
    if (x) std::copy(xs.begin(), xs.end(), x);
    if (w) std::copy(ws.begin(), ws.end(), w);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_set_mesh(mfree_approximant_t *a, mfree_mesh_t *mesh) {
  return mfree::with_handle(a, "mfree_approximant_set_mesh", [&](mfree::Approximant &ap) {
    MFREE_REQUIRE(mesh, MFREE_ERR_NULL, "mesh is NULL");
    MFREE_REQUIRE(mesh->ps == a->ps, MFREE_ERR_MISMATCH,
                  "the mesh is built on another particle set than the approximant");
    ap.set_mesh(mesh->m);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_approximant_set_mpfem(mfree_approximant_t *a, mfree_mpfem_deriv_t deriv,
                                           int32_t ngauss) {
  return mfree::with_handle(a, "mfree_approximant_set_mpfem", [&](mfree::Approximant &ap) {
    ap.set_mpfem(deriv, ngauss);
    return MFREE_SUCCESS;
  });
}

}  // extern "C"
