// Essential conditions: penalty, Lagrange multipliers, Nitsche (boundary points) and
// replaced rows (Dirichlet nodes).
#include "core/discretize/assembler.hpp"

#include <cmath>
#include <string>

namespace mfree {

void Assembler::set_penalty(double alpha) {
  if (!(std::isfinite(alpha) && alpha > 0.0)) throw Error(MFREE_ERR_ARG, "penalty must be finite and > 0");
  penalty_ = alpha;
  penalty_set_ = true;
}

void Assembler::add_dirichlet(int method, int32_t npts, const double *x, int layout, int64_t ld,
                              const double *w, const double *normals, int32_t mask, mfree_field_fn g,
                              void *user) {
  if (method != MFREE_BC_PENALTY && method != MFREE_BC_LAGRANGE && method != MFREE_BC_NITSCHE)
    throw Error(MFREE_ERR_ARG, "add_dirichlet takes MFREE_BC_PENALTY, MFREE_BC_LAGRANGE or MFREE_BC_NITSCHE "
                               "(row replacement: add_dirichlet_nodes)");
  if (mass()) throw Error(MFREE_ERR_UNSUPPORTED, "mass forms take no boundary conditions");
  if (method == MFREE_BC_NITSCHE) {
    if (npts > 0 && !normals) throw Error(MFREE_ERR_NULL, "Nitsche needs the boundary normals");
    if (npts > 0 && !w) throw Error(MFREE_ERR_NULL, "Nitsche weights are NULL");
    if (is_particles_only(trial_cfg_.method) || is_particles_only(test_cfg_.method))
      throw Error(MFREE_ERR_UNSUPPORTED, "Nitsche needs derivatives at boundary points, which particles-only "
                                         "methods do not define");
    for (int32_t p = 0; p < npts; ++p) {
      double len = 0.0;
      for (int c = 0; c < dim_; ++c) len += normals[p * dim_ + c] * normals[p * dim_ + c];
      if (!(std::isfinite(len) && std::fabs(len - 1.0) < 1e-6))
        throw Error(MFREE_ERR_INPUT, "normal " + std::to_string(p) + " is not a finite unit vector");
    }
  }
  if (collocation()) throw Error(MFREE_ERR_UNSUPPORTED, "collocation forms take Dirichlet nodes");
  if (mask <= 0 || mask >= (1 << ncomp_)) throw Error(MFREE_ERR_ARG, "component mask selects no valid component");
  if (!g) throw Error(MFREE_ERR_NULL, "boundary value function is NULL");
  check_points(npts, x, w, "dirichlet");
  if (method == MFREE_BC_PENALTY && npts > 0 && !w) throw Error(MFREE_ERR_NULL, "penalty weights are NULL");
  auto s = std::make_unique<PointSet>();
  s->kind = method == MFREE_BC_PENALTY ? 2 : method == MFREE_BC_LAGRANGE ? 3 : 4;
  read_points(npts, x, layout, ld, s->x);
  if (method == MFREE_BC_NITSCHE) s->normals.assign(normals, normals + static_cast<size_t>(npts) * dim_);
  if (w) s->w.assign(w, w + npts);
  else s->w.assign(npts, 1.0);
  s->mask = mask;
  s->fn = g;
  s->user = user;
  psets_.push_back(std::move(s));
  setup_done_ = false;
}

void Assembler::add_dirichlet_nodes(int32_t n, const int32_t *nodes, int32_t mask, mfree_field_fn g, void *user) {
  if (n < 0) throw Error(MFREE_ERR_ARG, "negative node count");
  if (n > 0 && !nodes) throw Error(MFREE_ERR_NULL, "nodes are NULL");
  if (!g) throw Error(MFREE_ERR_NULL, "boundary value function is NULL");
  if (mask <= 0 || mask >= (1 << ncomp_)) throw Error(MFREE_ERR_ARG, "component mask selects no valid component");
  for (int32_t k = 0; k < n; ++k)
    if (nodes[k] < 0 || nodes[k] >= ps_->num_owned())
      throw Error(MFREE_ERR_INPUT, "node " + std::to_string(nodes[k]) + " is not an owned particle");
  NodeSet s;
  s.kind = 1;
  s.nodes.assign(nodes, nodes + n);
  s.mask = mask;
  s.fn = g;
  s.user = user;
  nsets_.push_back(std::move(s));
  setup_done_ = false;
}

}  // namespace mfree
