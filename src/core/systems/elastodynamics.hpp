// Linear elastodynamics (paper 001 Sect. 6.4) by strong-form collocation: rho u'' =
// Navier(u) + b at interior particles, boundary rows (tractions, displacements) kept as
// algebraic constraints, solved for the boundary unknowns at every evaluation; or by
// Galerkin: M u'' = g(t) f - K u with K and M from two assemblers (any approximant).
// Both on ranks (elastodynamics_ranks.cpp): owned particles plus ghosts, the ghosts'
// displacements exchanged and the boundary unknowns solved in global-id order on every
// rank at each evaluation; Galerkin there with the lumped mass, and the consistent mass's
// products (apply_mass: owned rows, v read at the ghosts through the exchange).
#pragma once

#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/discretize/assembler.hpp"
#include "core/systems/collective.hpp"
#include "core/systems/system.hpp"

namespace mfree {

class ElasticSystem : public System {
 public:
  // as: a set-up collocation assembler (its matrix and right-hand side define the
  // operator and the boundary data); the caller keeps it alive.
  ElasticSystem(const Assembler *as, double density);
  // Galerkin: K from a set-up Galerkin assembler (Laplace form with c = E for the 1D bar,
  // or an elasticity form), M from a set-up mass assembler (MFREE_FORM_MASS or
  // MFREE_FORM_MASS_LUMPED, coefficient = density) on the same particles.
  ElasticSystem(const Assembler *stiffness, const Assembler *mass);

  // On ranks: a set-up collocation assembler, or a Galerkin stiffness assembler on host
  // quadrature points (the lumped mass of density rho on the same points), over this
  // rank's owned particles and ghosts (global ids required). Collective: every rank
  // throws the same Error when one rank fails (as may be NULL: that rank fails) or the
  // ranks disagree on the density, the form or its coefficients.
  static std::unique_ptr<ElasticSystem> on_ranks(const Assembler *as, double density, const Collective &coll);

  void set_load_history(double (*fn)(void *, double), void *user);

  int32_t neq() const override { return 2 * nd_; }
  Report rhs(double t, const double *y, double *ydot) override;
  Report mass(const double *y, bool consistent, SparseMatrix &M) override;
  // On ranks (Galerkin): the consistent mass's product reads v's velocities at the
  // ghosts (collective); elsewhere the mass of mass() applied.
  Report apply_mass(const double *y, bool consistent, const double *v, double *Mv) override;
  Report integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                   mfree_progress_fn progress, void *user, int64_t &nsteps) override;

  int stress_components() const { return dim_ == 1 ? 1 : (dim_ == 2 ? 3 : 6); }
  int dim() const { return dim_; }
  // the owned particles (all of them off ranks)
  int32_t num_particles() const { return nc_ > 0 ? nd_ / nc_ : 0; }
  bool ranks() const { return ranks_; }
  const Collective *collective() const override { return ranks_ ? &coll_ : nullptr; }
  // Stress at the particles from the displacements of y (boundary unknowns enforced);
  // collocation systems only (the Galerkin trial tables live in the assembler). On ranks
  // collective (the ghosts' displacements), the owned particles' stresses.
  void stress(double t, const double *y, double *sigma) const;
  bool galerkin() const { return galerkin_; }
  double wave_speed() const { return c_; }
  double min_spacing() const { return dx_min_; }
  // The step limit of central differences: dx_min / c (collocation), 2 / omega_max of
  // M^-1 K (Galerkin).
  double step_limit() const { return limit_; }

 private:
  ElasticSystem(const Assembler *as, double density, const Collective &coll);  // on_ranks' local part
  double history(double t) const { return hist_ ? hist_(hist_user_, t) : 1.0; }
  void init_common();
  void init_operator();
  void init_boundary();
  void init_ranks();
  void sort_rows();  // on ranks: K_'s rows in global-id order of their columns
  int64_t key(int32_t d) const;  // on ranks: unknown d's (global id, component) as one key
  // lu_ = the factorised block K_bb of nb boundary unknowns (its entries as triplets)
  void factor_boundary(int32_t nb, const std::vector<Eigen::Triplet<double>> &trip);
  double local_spacing(int32_t nrows) const;
  // On ranks: work_ = the owned displacements u, the ghosts' from their owners and the
  // boundary unknowns of both solved; mine (this rank's outcome so far) agreed with the
  // other ranks' in the same gather. Returns the agreed outcome (work_ unfinished if bad).
  Report fill_state(double t, const double *u, const Report &mine) const;
  // An agreed outcome: thrown when it is an error (alike on every rank), else returned.
  static Report settle(const Report &agreed);
  void init_galerkin_mass(const Assembler *mass);
  // On ranks: cmass_ = the consistent mass's owned rows (state layout over the local
  // unknowns' displacements then velocities), built at the first product
  void init_consistent_ranks();
  void enforce_boundary(double t, double *u) const;
  void accel(double t, const double *u, double *a) const;
  Report check(const double *y, const std::string &when) const;

  const Assembler *as_;
  double rho_;
  int dim_, nc_;
  int32_t nd_;
  SparseMatrix K_;
  std::vector<double> f0_;
  std::vector<int32_t> bdofs_, bpos_;  // boundary dofs and each dof's position among them
  std::unique_ptr<Eigen::SparseLU<Eigen::SparseMatrix<double>>> lu_;
  double (*hist_)(void *, double) = nullptr;
  void *hist_user_ = nullptr;
  double c_ = 0.0, dx_min_ = 0.0, limit_ = 0.0;
  // Galerkin: mass on the free (non-constrained) dofs, lumped (inverse diagonal) or
  // factorised; fpos_ = position of each dof among the free ones (-1: constrained)
  bool galerkin_ = false, lumped_ = false;
  std::vector<int32_t> fdofs_, fpos_;
  std::vector<double> minv_;
  Eigen::SparseMatrix<double> Mff_;
  std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>> mfac_;
  std::vector<int64_t> mrp_;  // the state's mass matrix (constant), built at first use
  std::vector<int32_t> mci_;
  std::vector<double> mval_;
  mutable std::vector<double> rb_, work_;
  // On ranks: nl_ local unknowns (owned and ghost particles); bpos_ (nl_ entries) is then
  // each unknown's position among all ranks' boundary unknowns sorted by (global id,
  // component), gb_local_ the local unknown of each of them (-1: not here); own_b_ the
  // owned boundary unknowns in the order this rank sends their rows' data, cnt_ each
  // rank's count of them, perm_ each gathered row's sorted position, seg_ where each
  // rank's part (its status, then its rows' data) starts in the gather.
  bool ranks_ = false;
  Collective coll_;
  int32_t nl_ = 0;
  std::vector<int32_t> gb_local_, own_b_, perm_;
  std::vector<int64_t> cnt_, seg_;
  mutable std::vector<double> send_, gathered_;
  mutable Eigen::VectorXd rbe_;
  SparseMatrix cmass_;
  bool cmass_done_ = false;
  std::vector<double> cw_;  // the product's operand: owned entries and ghosts' velocities
};

}  // namespace mfree
