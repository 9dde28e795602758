#include <algorithm>

#include "handles.hpp"

namespace mfree {
void retain(mfree_particles_t *p) { p->refs.fetch_add(1, std::memory_order_relaxed); }
void release(mfree_particles_t *p) {
  if (p && p->refs.fetch_sub(1, std::memory_order_acq_rel) == 1) {
    mfree_context_t *c = p->ctx;
    delete p;
    release(c);
  }
}
}  // namespace mfree

namespace {

// Common prologue of every particle-set call: a NULL handle cannot carry a message.

}  // namespace

extern "C" {

mfree_status_t mfree_particles_create(mfree_context_t *ctx, int32_t dim, int32_t n,
                                      mfree_particles_t **ps) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_particles_create", [&]() {
    MFREE_REQUIRE(ps, MFREE_ERR_NULL, "output pointer is NULL");
    *ps = nullptr;
    auto *p = new mfree_particles_t(ctx, dim, n);
    mfree::retain(ctx);
    *ps = p;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_destroy(mfree_particles_t **ps) {
  if (!ps || !*ps) return MFREE_SUCCESS;
  mfree::release(*ps);
  *ps = nullptr;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_particles_set_num_ghost(mfree_particles_t *ps, int32_t n_ghost) {
  return mfree::with_handle(ps, "mfree_particles_set_num_ghost", [&](mfree::ParticleSet &s) {
    s.set_num_ghost(n_ghost);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_set_positions(mfree_particles_t *ps, const double *x,
                                             mfree_layout_t layout, int64_t ld,
                                             mfree_mem_t mem) {
  return mfree::with_handle(ps, "mfree_particles_set_positions", [&](mfree::ParticleSet &s) {
    s.set_positions(x, layout, ld, mem);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_set_volumes(mfree_particles_t *ps, const double *v,
                                           int64_t stride, mfree_mem_t mem) {
  return mfree::with_handle(ps, "mfree_particles_set_volumes", [&](mfree::ParticleSet &s) {
    s.set_volumes(v, stride, mem);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_set_masses(mfree_particles_t *ps, const double *m,
                                          int64_t stride, mfree_mem_t mem) {
  return mfree::with_handle(ps, "mfree_particles_set_masses", [&](mfree::ParticleSet &s) {
    s.set_masses(m, stride, mem);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_set_densities(mfree_particles_t *ps, const double *rho,
                                             int64_t stride, mfree_mem_t mem) {
  return mfree::with_handle(ps, "mfree_particles_set_densities", [&](mfree::ParticleSet &s) {
    s.set_densities(rho, stride, mem);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_set_support(mfree_particles_t *ps, const double *h,
                                           int64_t stride, mfree_mem_t mem) {
  return mfree::with_handle(ps, "mfree_particles_set_support", [&](mfree::ParticleSet &s) {
    s.set_support(h, stride, mem);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_set_search(mfree_particles_t *ps, mfree_search_t convention,
                                          double kappa) {
  return mfree::with_handle(ps, "mfree_particles_set_search", [&](mfree::ParticleSet &s) {
    s.set_search(convention, kappa);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_set_search_skin(mfree_particles_t *ps, double skin) {
  return mfree::with_handle(ps, "mfree_particles_set_search_skin", [&](mfree::ParticleSet &s) {
    s.set_search_skin(skin);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_get_search_count(const mfree_particles_t *ps, int64_t *count) {
  return mfree::with_handle(ps, "mfree_particles_get_search_count", [&](const mfree::ParticleSet &s) {
    MFREE_REQUIRE(count, MFREE_ERR_NULL, "output pointer is NULL");
    *count = s.search_count();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_set_periodic(mfree_particles_t *ps, const double *lo,
                                            const double *hi, const int32_t *periodic) {
  return mfree::with_handle(ps, "mfree_particles_set_periodic", [&](mfree::ParticleSet &s) {
    s.set_periodic(lo, hi, periodic);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_set_neighbors(mfree_particles_t *ps, const int64_t *rowptr,
                                             const int32_t *cols, int32_t index_base,
                                             mfree_mem_t mem) {
  return mfree::with_handle(ps, "mfree_particles_set_neighbors", [&](mfree::ParticleSet &s) {
    s.set_neighbors(rowptr, cols, index_base, mem);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_setup(mfree_particles_t *ps) {
  return mfree::with_handle(ps, "mfree_particles_setup", [&](mfree::ParticleSet &s) {
    return mfree::finish(ps->ctx, "mfree_particles_setup", s.setup());
  });
}

mfree_status_t mfree_particles_update(mfree_particles_t *ps) {
  return mfree::with_handle(ps, "mfree_particles_update", [&](mfree::ParticleSet &s) {
    return mfree::finish(ps->ctx, "mfree_particles_update", s.update());
  });
}

mfree_status_t mfree_particles_set_global_ids(mfree_particles_t *ps, const int64_t *ids,
                                              mfree_mem_t mem) {
  return mfree::with_handle(ps, "mfree_particles_set_global_ids", [&](mfree::ParticleSet &s) {
    s.set_global_ids(ids, mem);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_get_global_ids(const mfree_particles_t *ps, int64_t *ids) {
  return mfree::with_handle(ps, "mfree_particles_get_global_ids", [&](const mfree::ParticleSet &s) {
    MFREE_REQUIRE(ids || s.size() == 0, MFREE_ERR_NULL, "output pointer is NULL");
    MFREE_REQUIRE(s.has_global_ids(), MFREE_ERR_STATE, "the particle set has no global ids");
    std::copy(s.global_ids(), s.global_ids() + s.size(), ids);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_set_halo_width(mfree_particles_t *ps, double w) {
  return mfree::with_handle(ps, "mfree_particles_set_halo_width", [&](mfree::ParticleSet &s) {
    s.set_halo_width(w);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_get_dimension(const mfree_particles_t *ps, int32_t *dim) {
  return mfree::with_handle(ps, "mfree_particles_get_dimension", [&](const mfree::ParticleSet &s) {
    MFREE_REQUIRE(dim, MFREE_ERR_NULL, "output pointer is NULL");
    *dim = s.dim();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_get_size(const mfree_particles_t *ps, int32_t *n,
                                        int32_t *n_ghost) {
  return mfree::with_handle(ps, "mfree_particles_get_size", [&](const mfree::ParticleSet &s) {
    if (n) *n = s.size();
    if (n_ghost) *n_ghost = s.num_ghost();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_get_neighbor_nnz(const mfree_particles_t *ps, int64_t *nnz) {
  return mfree::with_handle(ps, "mfree_particles_get_neighbor_nnz", [&](const mfree::ParticleSet &s) {
    MFREE_REQUIRE(nnz, MFREE_ERR_NULL, "output pointer is NULL");
    MFREE_REQUIRE(s.is_setup(), MFREE_ERR_STATE, "the particle set is not set up");
    *nnz = s.neighbors().nnz();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_get_neighbors(const mfree_particles_t *ps, int64_t *rowptr,
                                             int32_t *cols) {
  return mfree::with_handle(ps, "mfree_particles_get_neighbors", [&](const mfree::ParticleSet &s) {
    MFREE_REQUIRE(s.is_setup(), MFREE_ERR_STATE, "the particle set is not set up");
    const mfree::Csr &g = s.neighbors();
    MFREE_REQUIRE(rowptr, MFREE_ERR_NULL, "rowptr is NULL");
    MFREE_REQUIRE(cols || g.nnz() == 0, MFREE_ERR_NULL, "cols is NULL");
    std::copy(g.rowptr.begin(), g.rowptr.end(), rowptr);
    std::copy(g.cols.begin(), g.cols.end(), cols);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_get_volumes(const mfree_particles_t *ps, double *v) {
  return mfree::with_handle(ps, "mfree_particles_get_volumes", [&](const mfree::ParticleSet &s) {
    MFREE_REQUIRE(v || s.size() == 0, MFREE_ERR_NULL, "output pointer is NULL");
    MFREE_REQUIRE(s.has_volumes(), MFREE_ERR_STATE,
                  "neither volumes nor both masses and densities are set");
    for (int32_t i = 0; i < s.size(); ++i) v[i] = s.volume(i);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_particles_get_site_status(const mfree_particles_t *ps, int32_t *status,
                                               int32_t *nfailed) {
  return mfree::with_handle(ps, "mfree_particles_get_site_status", [&](const mfree::ParticleSet &s) {
    MFREE_REQUIRE(status || nfailed, MFREE_ERR_NULL, "both outputs are NULL");
    MFREE_REQUIRE(s.is_setup(), MFREE_ERR_STATE, "the particle set is not set up");
    const auto &st = s.site_status();
    if (status) std::copy(st.begin(), st.end(), status);
    if (nfailed)
      *nfailed = static_cast<int32_t>(std::count_if(st.begin(), st.end(), [](int32_t v) { return v != 0; }));
    return MFREE_SUCCESS;
  });
}

}  // extern "C"
