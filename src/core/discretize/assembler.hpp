// Galerkin (Bubnov and Petrov) and collocation assembly of sparse systems. The class is
// defined across files by concern (assembler.cpp: construction, tables, pattern;
// assembler_forms.cpp, assembler_quadrature.cpp, assembler_essential.cpp,
// assembler_tractions.cpp) and delegates to components with narrow inputs: the FE layer
// (fe_layer.hpp), consistent integration (consistent_integration.hpp), small-strain
// kinematics (strain.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/base/alloc.hpp"
#include "core/shape/approximant.hpp"
#include "core/base/error.hpp"
#include "core/discretize/fe_layer.hpp"
#include "core/discretize/matrix.hpp"
#include "core/discretize/qtable.hpp"
#include "mfree.h"
#include "core/particles/particles.hpp"

namespace mfree {

// Methods defined at the particles only (their derivatives correct SPH's at the
// particles; they have no values between them).
inline bool is_particles_only(int m) {
  return m == MFREE_METHOD_SPH_SYMMETRIC || m == MFREE_METHOD_JOHNSON_BEISSEL ||
         m == MFREE_METHOD_RANDLES_LIBERSKY;
}

class Assembler {
 public:
  Assembler(const ParticleSet *ps, const ApproxConfig &trial, const ApproxConfig &test, bool bubnov,
            int form);

  void set_material(double young, double poisson);
  void set_coefficient(double c);
  void set_quadrature_nodal();
  void set_quadrature_cells(const double *lo, const double *hi, const int32_t *ncells, int ngauss,
                            mfree_inside_fn inside, void *user);
  void set_quadrature_points(int32_t npts, const double *x, int layout, int64_t ld, const double *w);
  void set_body_force(mfree_field_fn f, void *user);
  void add_traction(int32_t npts, const double *x, int layout, int64_t ld, const double *w,
                    mfree_field_fn t, void *user);
  void add_traction_segments(int32_t nseg, const double *x, int ngauss, mfree_field_fn t, void *user);
  void add_traction_facets(int32_t nfacet, const double *x, int ngauss, mfree_field_fn t, void *user);
  void add_dirichlet(int method, int32_t npts, const double *x, int layout, int64_t ld,
                     const double *w, const double *normals, int32_t mask, mfree_field_fn g,
                     void *user);
  void add_dirichlet_nodes(int32_t n, const int32_t *nodes, int32_t mask, mfree_field_fn g, void *user);
  void add_traction_nodes(int32_t n, const int32_t *nodes, const double *normals, mfree_field_fn t,
                          void *user);
  void set_penalty(double alpha);
  // Variationally consistent integration (Chen, Hillman, Rueter 2013), second order
  // (constant and linear corrections of the test gradients): the whole boundary as
  // points, weights and outward normals; npts = 0 switches it off.
  void set_consistent_integration(int32_t npts, const double *x, int layout, int64_t ld, const double *w,
                                  const double *normals);
  void set_fe_layer(int32_t nelem, int32_t npe, const int32_t *conn, int32_t ngu, const int32_t *gu,
                    int32_t mask, mfree_field_fn g, void *user);

  Report setup();
  Report update();
  bool is_setup() const { return setup_done_; }
  int32_t ndofs() const { return ndofs_; }
  int32_t nquad() const { return static_cast<int32_t>(qw_.size()); }

  // Fill K (reusing its pattern when unchanged).
  void assemble_matrix(SparseMatrix &K) const;
  void assemble_rhs(double *f) const;

  // For systems built on a collocation assembler: the form, components per particle,
  // which rows the boundary conditions replaced, and the trial tables at the particles.
  int form() const { return form_; }
  int ncomp() const { return ncomp_; }
  bool is_collocation() const { return collocation(); }
  const std::vector<int32_t> &row_kinds() const { return row_kind_; }
  const Approximant *collocation_tables() const { return collocation() ? trial_q_.get() : nullptr; }
  double young() const { return young_; }
  double poisson() const { return poisson_; }
  double coefficient() const { return coef_; }
  const ParticleSet &particles() const { return *ps_; }
  // For a Galerkin system on ranks: why its owned rows would not be those of one rank
  // (nullptr when they are): nodal quadrature (its points are the set's non-ghosts, which
  // on ranks must include the ghosts within a support radius), the FE layer, consistent
  // integration. And the mass of the same approximants on the same quadrature points
  // (form MFREE_FORM_MASS or _LUMPED, coefficient coef), set up.
  const char *ranks_obstacle() const;
  std::unique_ptr<Assembler> mass_on_same_points(int form, double coef) const;

 private:
  struct PointSet {  // boundary points with weights
    int kind = 0;    // 1 traction, 2 penalty, 3 Lagrange, 4 Nitsche, 5 boundary for VCI
    HVec<double> x, w, normals;  // (copies of host data come from the context's hook)
    int32_t mask = 0;
    mfree_field_fn fn = nullptr;
    void *user = nullptr;
    std::unique_ptr<Approximant> test, trial;  // values at the points
    int32_t first_multiplier = 0;
  };
  struct BlendedSet;  // per point set: blended test/trial tables (defined below)
  struct NodeSet {
    int kind = 0;  // 1 Dirichlet rows, 2 traction rows, 3 identity rows (FE layer nodes)
    HVec<int32_t> nodes;
    HVec<double> normals;
    int32_t mask = 0;
    mfree_field_fn fn = nullptr;
    void *user = nullptr;
  };

  // Essential values at nodes: the function g and a mask of valid components.
  void check_values(mfree_field_fn g, int32_t mask) const;
  static NodeSet node_set(int kind, int32_t n, const int32_t *nodes, int32_t mask, mfree_field_fn fn, void *user);
  void build_qtables();
  // The test table of the assembly: its own when the test functions differ from the
  // trial functions or their gradients were corrected, else the trial table.
  const QTable &test_table() const { return own_test_table_ ? qtest_ : qtrial_; }
  // Copy an approximant's rows; weights w (NULL: the particle volumes).
  // Positions pts (NULL: the particles).
  void fill_qtable(const Approximant &a, QTable &t, const HVec<double> *w,
                   const HVec<double> *pts = nullptr) const;

  bool collocation() const { return form_ >= MFREE_FORM_COLLOCATION_LAPLACE; }
  bool elasticity() const;
  bool mass() const { return form_ == MFREE_FORM_MASS || form_ == MFREE_FORM_MASS_LUMPED; }
  std::unique_ptr<Approximant> make(const ApproxConfig &cfg, const HVec<double> *pts) const;
  // Support of each point (AoS): the particles' supports averaged with their scatter
  // weights around it; one value when the particles' supports are all equal.
  std::vector<double> point_supports(const HVec<double> &pts) const;
  ApproxConfig values_config(const ApproxConfig &c) const;
  void check_points(int32_t npts, const double *x, const double *w, const char *what) const;
  // Every normal (dim per point) a finite unit vector; what prefixes the message.
  void check_unit_normals(int32_t npts, const double *normals, const char *what) const;
  void read_points(int32_t npts, const double *x, int layout, int64_t ld, HVec<double> &out) const;
  Report build_tables();
  void build_pattern();
  // The order in which the quadrature points' contributions are summed (qorder_): the
  // host's order of background or host points; for nodal quadrature the particles in
  // the set's canonical (global-id) order, so that a rank's rows of its owned nodes equal
  // the one-rank rows bit for bit.
  void quadrature_order();
  void material_matrix(double *D, int &nv) const;
  // Entry (r, c) of a matrix being assembled, which must lie in its pattern.
  struct Entries {
    SparseMatrix &K;
    std::vector<double> &v;
    double &operator()(int32_t r, int32_t c) const {
      const int64_t k = K.find(r, c);
      if (k < 0) throw Error(MFREE_ERR_INTERNAL, "assembly entry outside the pattern");
      return v[k];
    }
  };
  // The parts of assemble_matrix and assemble_rhs, by concern: the form's rows
  // (assembler_forms.cpp), the boundary terms and the replaced rows
  // (assembler_essential.cpp).
  void assemble_collocation(const Entries &at) const;
  void assemble_mass(const Entries &at) const;
  void assemble_stiffness(std::vector<double> &v) const;
  void assemble_boundary_terms(const Entries &at) const;
  void assemble_replaced_rows(const Entries &at) const;
  void body_loads(double *f) const;
  void boundary_loads(double *f) const;
  void replaced_row_loads(double *f) const;
  // Traction operator: (sigma(u) n)_c = sum_e T[c][e] u_e for the field u = phi e_e with
  // gradient g (elasticity), or c n.g (Laplace, T[0][0]).
  void traction_row(const double *g, const double *n, double T[3][3]) const;
  double mean_h() const;

  const ParticleSet *ps_;
  ApproxConfig trial_cfg_, test_cfg_;
  bool bubnov_;
  int form_;
  int dim_, ncomp_;
  double young_ = 1.0, poisson_ = 0.0, coef_ = 1.0, penalty_ = 0.0, nitsche_ = 0.0;
  bool penalty_set_ = false;

  int quad_kind_ = 0;  // 0 nodal, 1 cells or points (qx_/qw_)
  HVec<double> qx_, qw_;
  mfree_field_fn body_ = nullptr;
  void *body_user_ = nullptr;
  std::vector<std::unique_ptr<PointSet>> psets_;
  std::vector<NodeSet> nsets_;

  bool setup_done_ = false;
  int32_t ndofs_ = 0, nmult_ = 0;
  std::unique_ptr<Approximant> trial_q_, test_q_, load_q_, trial_nodes_;
  // Johnson-Beissel under an elasticity form: symmetrised SPH derivatives at the particles
  // for the shear strains of the trial and test sides (paper 000 eqs 48-52)
  std::unique_ptr<Approximant> trial_shear_, test_shear_;
  // dof pattern
  std::vector<int64_t> rowptr_;
  std::vector<int32_t> cols_;
  std::vector<int32_t> node_deg_;  // per node: node columns in each of its rows (every
                                   // component row of a node holds the same node columns,
                                   // ncomp per node, sorted, multipliers after them)
  std::vector<int32_t> row_kind_;  // per dof: 0 form, 1 Dirichlet row, 2 traction row
  std::vector<int32_t> row_set_, row_node_;  // which node set / position replaces the row
  FeLayer fe_;
  QTable qtrial_, qtest_;
  std::vector<int32_t> qorder_;  // quadrature points in summation order
  bool own_test_table_ = false;
  std::vector<QTable> ps_test_, ps_trial_;  // per point set (same order as psets_)
};

}  // namespace mfree
