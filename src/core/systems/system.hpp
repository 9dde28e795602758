// Semi-discrete particle systems y' = f(t, y): the interface shared by the fluid of
// paper 003 and the elastodynamic collocation system of paper 001.
#pragma once

#include <cstdint>

#include "core/base/error.hpp"
#include "core/discretize/matrix.hpp"
#include "core/systems/collective.hpp"
#include "mfree.h"

namespace mfree {

class System {
 public:
  virtual ~System() = default;
  virtual int32_t neq() const = 0;
  virtual Report rhs(double t, const double *y, double *ydot) = 0;
  virtual Report mass(const double *y, bool consistent, SparseMatrix &M) = 0;
  // M(y) v: the mass assembled and applied (the fluid keeps it between products).
  virtual Report apply_mass(const double *y, bool consistent, const double *v, double *Mv) {
    SparseMatrix M;
    Report r = mass(y, consistent, M);
    if (r.ok()) M.apply(v, Mv);
    return r;
  }
  virtual Report integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                           mfree_progress_fn progress, void *user, int64_t &nsteps) = 0;
  // A system on ranks: its collective operations (a pending fault of a call's arguments
  // is agreed through them); nullptr for a system in one process.
  virtual const Collective *collective() const { return nullptr; }
};

}  // namespace mfree
