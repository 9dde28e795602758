// Weakly compressible free-surface flow by Galerkin SPH with MLS shape functions
// (paper 003): the semi-discrete right-hand side, mass matrices and the native
// leap-frog and predictor-corrector integrators.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "approximant.hpp"
#include "error.hpp"
#include "matrix.hpp"
#include "mfree.h"
#include "particles.hpp"
#include "system.hpp"

namespace mfree {

class FluidSystem : public System {
 public:
  FluidSystem(int dim, int32_t n);

  void set_fluid(const double *rho0, int64_t stride, double kappa, double gamma, double mu);
  void set_masses(const double *m, int64_t stride);
  void set_smoothing(double h);
  void set_gravity(const double *g);
  void set_lumping(int lump);
  void set_walls(int32_t nwall, const double *x, const double *normals, double r0, double strength);
  void set_box(const double *lo, const double *hi);
  // Sites whose moment-matrix condition estimate exceeds max_cond use Shepard functions.
  void set_shepard_condition(double max_cond);

  int dim() const { return dim_; }
  int32_t size() const { return n_; }
  int32_t neq() const override { return (2 * dim_ + 1) * n_; }

  Report rhs(double t, const double *y, double *ydot) override;
  Report mass(const double *y, bool consistent, SparseMatrix &M) override;
  Report interpolation(const double *y, SparseMatrix &S);
  void pressure(const double *y, double *p) const;
  Report velocity(const double *y, double *vhat);
  Report integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                   mfree_progress_fn progress, void *user, int64_t &nsteps) override;

 private:
  void check_ready() const;
  // Validate the state, point the particle set at it and build the MLS tables.
  Report prepare(const double *y);
  // Acceleration parameters a (dim per particle) from the prepared tables and v, rho.
  Report accel(const double *v, const double *rho, double *a);
  // Copies the approximant's tables into N_, G_ and replaces the rows of ill-conditioned
  // sites by Shepard functions (003 Sect. 6).
  void shepard_ill_conditioned();
  // Interpolated velocities and density rates for velocity parameters v.
  void kinematics(const double *v, const double *rho, double *vhat, double *drho) const;
  double stable_dt(const double *y) const;  // h / max(c_i + |v_i|)
  Report check_state(const double *y, const char *when) const;

  int dim_;
  int32_t n_;
  std::vector<double> rho0_, mass_;
  double kappa_ = 1.0, gamma_ = 7.0, mu_ = 0.0, h_ = 0.0;
  double g_[3] = {0, 0, 0};
  int lump_ = MFREE_LUMP_GALERKIN;
  std::unique_ptr<ParticleSet> walls_;
  std::vector<double> wall_n_;
  double r0_ = 0.0, strength_ = 0.0;
  double shepard_cond_ = 100.0;
  bool box_ = false;
  double lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};

  ParticleSet ps_;
  std::vector<double> vol_;
  std::vector<double> N_, G_;  // shape-function values and gradients used by the model
  std::unique_ptr<Approximant> approx_;
  Csr wall_nbr_;
  // scratch (reused, sized once)
  std::vector<double> force_, lumped_, fb_, vhat_, work_state_, stage_;
};

}  // namespace mfree
