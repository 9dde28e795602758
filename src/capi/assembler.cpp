#include "core/discretize/assembler.hpp"
#include "handles.hpp"

void mfree::release(mfree_assembler_t *a) {
  if (a && a->refs.fetch_sub(1, std::memory_order_acq_rel) == 1) {
    mfree_particles_t *p = a->ps;
    mfree_context_t *c = a->ctx;
    delete a;
    mfree::release(p);
    mfree::release(c);
  }
}


extern "C" {

mfree_status_t mfree_assembler_create(mfree_context_t *ctx, const mfree_approximant_t *trial,
                                      const mfree_approximant_t *test, mfree_form_t form,
                                      mfree_assembler_t **as) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_assembler_create", [&]() {
    MFREE_REQUIRE(as, MFREE_ERR_NULL, "output pointer is NULL");
    *as = nullptr;
    MFREE_REQUIRE(trial, MFREE_ERR_NULL, "trial approximant is NULL");
    MFREE_REQUIRE(!test || test->ps == trial->ps, MFREE_ERR_MISMATCH,
                  "trial and test approximants are on different particle sets");
    const mfree::ApproxConfig tc = trial->a.config();
    const mfree::ApproxConfig sc = test ? test->a.config() : tc;
    auto *a = new mfree_assembler_t(ctx, trial->ps, tc, sc, test == nullptr, form);
    mfree::retain(ctx);
    mfree::retain(trial->ps);
    *as = a;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_assembler_destroy(mfree_assembler_t **as) {
  if (!as || !*as) return MFREE_SUCCESS;
  mfree::release(*as);
  *as = nullptr;
  return MFREE_SUCCESS;
}

#define MFREE_AS_SETTER(name, call)                                             \
  return mfree::with_handle(as, name, [&](mfree::Assembler &a) {                           \
    call;                                                                       \
    return MFREE_SUCCESS;                                                       \
  })

mfree_status_t mfree_assembler_set_material(mfree_assembler_t *as, double young, double poisson) {
  MFREE_AS_SETTER("mfree_assembler_set_material", a.set_material(young, poisson));
}
mfree_status_t mfree_assembler_set_coefficient(mfree_assembler_t *as, double c) {
  MFREE_AS_SETTER("mfree_assembler_set_coefficient", a.set_coefficient(c));
}
mfree_status_t mfree_assembler_set_quadrature_nodal(mfree_assembler_t *as) {
  MFREE_AS_SETTER("mfree_assembler_set_quadrature_nodal", a.set_quadrature_nodal());
}
mfree_status_t mfree_assembler_set_quadrature_cells(mfree_assembler_t *as, const double *lo,
                                                    const double *hi, const int32_t *ncells,
                                                    int32_t ngauss, mfree_inside_fn inside,
                                                    void *user) {
  MFREE_AS_SETTER("mfree_assembler_set_quadrature_cells",
                  a.set_quadrature_cells(lo, hi, ncells, ngauss, inside, user));
}
mfree_status_t mfree_assembler_set_quadrature_points(mfree_assembler_t *as, int32_t npts,
                                                     const double *x, mfree_layout_t layout,
                                                     int64_t ld, const double *w) {
  MFREE_AS_SETTER("mfree_assembler_set_quadrature_points", a.set_quadrature_points(npts, x, layout, ld, w));
}
mfree_status_t mfree_assembler_set_body_force(mfree_assembler_t *as, mfree_field_fn f, void *user) {
  MFREE_AS_SETTER("mfree_assembler_set_body_force", a.set_body_force(f, user));
}
mfree_status_t mfree_assembler_add_traction(mfree_assembler_t *as, int32_t npts, const double *x,
                                            mfree_layout_t layout, int64_t ld, const double *w,
                                            mfree_field_fn t, void *user) {
  MFREE_AS_SETTER("mfree_assembler_add_traction", a.add_traction(npts, x, layout, ld, w, t, user));
}
mfree_status_t mfree_assembler_add_traction_segments(mfree_assembler_t *as, int32_t nseg,
                                                     const double *x, int32_t ngauss,
                                                     mfree_field_fn t, void *user) {
  MFREE_AS_SETTER("mfree_assembler_add_traction_segments", a.add_traction_segments(nseg, x, ngauss, t, user));
}
mfree_status_t mfree_assembler_add_traction_facets(mfree_assembler_t *as, int32_t nfacet,
                                                   const double *x, int32_t ngauss,
                                                   mfree_field_fn t, void *user) {
  MFREE_AS_SETTER("mfree_assembler_add_traction_facets", a.add_traction_facets(nfacet, x, ngauss, t, user));
}
mfree_status_t mfree_assembler_add_dirichlet(mfree_assembler_t *as, mfree_bc_t method, int32_t npts,
                                             const double *x, mfree_layout_t layout, int64_t ld,
                                             const double *w, const double *normals,
                                             int32_t component_mask, mfree_field_fn g, void *user) {
  MFREE_AS_SETTER("mfree_assembler_add_dirichlet",
                  a.add_dirichlet(method, npts, x, layout, ld, w, normals, component_mask, g, user));
}
mfree_status_t mfree_assembler_add_dirichlet_nodes(mfree_assembler_t *as, int32_t nnodes,
                                                   const int32_t *nodes, int32_t component_mask,
                                                   mfree_field_fn g, void *user) {
  MFREE_AS_SETTER("mfree_assembler_add_dirichlet_nodes",
                  a.add_dirichlet_nodes(nnodes, nodes, component_mask, g, user));
}
mfree_status_t mfree_assembler_add_traction_nodes(mfree_assembler_t *as, int32_t nnodes,
                                                  const int32_t *nodes, const double *normals,
                                                  mfree_field_fn t, void *user) {
  MFREE_AS_SETTER("mfree_assembler_add_traction_nodes", a.add_traction_nodes(nnodes, nodes, normals, t, user));
}
mfree_status_t mfree_assembler_set_fe_layer(mfree_assembler_t *as, int32_t nelem, int32_t nodes_per_element,
                                            const int32_t *connectivity, int32_t ngu, const int32_t *gu,
                                            int32_t component_mask, mfree_field_fn g, void *user) {
  MFREE_AS_SETTER("mfree_assembler_set_fe_layer",
                  a.set_fe_layer(nelem, nodes_per_element, connectivity, ngu, gu, component_mask, g, user));
}
mfree_status_t mfree_assembler_set_penalty(mfree_assembler_t *as, double alpha) {
  MFREE_AS_SETTER("mfree_assembler_set_penalty", a.set_penalty(alpha));
}
mfree_status_t mfree_assembler_set_consistent_integration(mfree_assembler_t *as, int32_t npts, const double *x,
                                                         mfree_layout_t layout, int64_t ld, const double *w,
                                                         const double *normals) {
  MFREE_AS_SETTER("mfree_assembler_set_consistent_integration",
                  a.set_consistent_integration(npts, x, layout, ld, w, normals));
}

mfree_status_t mfree_assembler_setup(mfree_assembler_t *as) { return mfree::setup_on_set(as, "mfree_assembler_setup"); }

mfree_status_t mfree_assembler_update(mfree_assembler_t *as) {
  return mfree::with_handle(as, "mfree_assembler_update", [&](mfree::Assembler &a) {
    return mfree::finish(as->ctx, "mfree_assembler_update", a.update());
  });
}

mfree_status_t mfree_assembler_get_size(const mfree_assembler_t *as, int32_t *ndofs, int32_t *nquad) {
  return mfree::with_handle(as, "mfree_assembler_get_size", [&](const mfree::Assembler &a) {
    MFREE_REQUIRE(a.is_setup(), MFREE_ERR_STATE, "the assembler is not set up");
    if (ndofs) *ndofs = a.ndofs();
    if (nquad) *nquad = a.nquad();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_assembler_assemble_matrix(mfree_assembler_t *as, mfree_matrix_t **K) {
  return mfree::with_handle(as, "mfree_assembler_assemble_matrix", [&](mfree::Assembler &a) {
    MFREE_REQUIRE(K, MFREE_ERR_NULL, "output pointer is NULL");
    MFREE_REQUIRE(a.is_setup(), MFREE_ERR_STATE, "the assembler is not set up");
    mfree_matrix_t *m = *K;
    bool fresh = false;
    if (!m) {
      m = new mfree_matrix_t(as->ctx);
      mfree::retain(as->ctx);
      fresh = true;
    }
    try {
      a.assemble_matrix(m->m);
    } catch (...) {
      if (fresh) mfree::release(m);
      throw;
    }
    *K = m;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_assembler_assemble_rhs(mfree_assembler_t *as, double *f) {
  return mfree::with_handle(as, "mfree_assembler_assemble_rhs", [&](mfree::Assembler &a) {
    MFREE_REQUIRE(a.is_setup(), MFREE_ERR_STATE, "the assembler is not set up");
    MFREE_REQUIRE(f || a.ndofs() == 0, MFREE_ERR_NULL, "output pointer is NULL");
    a.assemble_rhs(f);
    return MFREE_SUCCESS;
  });
}

}  // extern "C"
