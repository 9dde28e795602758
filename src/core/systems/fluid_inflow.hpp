// Open boundaries of the Galerkin-SPH fluid (fluid.hpp): a fixed capacity of particles
// of which only the active ones are fluid, inflow gates that inject particles and outflow
// planes that return them to the dormant pool. The state vector keeps its size (SUNDIALS
// integrators need a fixed neq): dormant particles stay in it with zero rates and are left
// out of the nodes, the tables, the checks and the step control. The FluidSystem members
// that use this data are defined in fluid_inflow.cpp.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "mfree.h"

namespace mfree {

class FluidSystem;

// Particle states, as mfree_system_get_active reports them.
enum : int8_t { kDormant = 0, kFluid = 1, kInflow = 2 };

// An inflow gate: a segment (2D) or parallelogram (3D) origin + s e1 (+ u e2), s, u in
// [0, 1], with unit inward normal nrm. A lattice of m1 (x m2) points (j + 1/2) / m of the
// edges carries rows of particles at spacing d along nrm; row k sits at signed distance
// U (t - t0) - (k + 1/2) d from the gate plane. Rows upstream of the plane within nb
// spacings (the support radius) are the buffer: active, moving at U nrm with density rho,
// their rates imposed. A row that reaches the plane joins the fluid; the row nb behind it
// is activated at the same instant t0 + (k + 1/2) d / U.
struct InflowGate {
  double o[3] = {0, 0, 0}, e[2][3] = {{0, 0, 0}, {0, 0, 0}}, nrm[3] = {0, 0, 0};
  double U = 0, rho = 0, d = 0;
  int32_t m[2] = {1, 1};
  int32_t nb = 0;                  // buffer rows (set when the gate starts)
  double mass_each = 0;            // rho d A / (m1 m2)
  bool started = false;
  double t0 = 0;
  int64_t activated_rows = 0;      // rows 0 .. activated_rows - 1 were activated
  int64_t released_rows = 0;       // rows 0 .. released_rows - 1 joined the fluid
  std::deque<std::vector<int32_t>> rows;  // the buffer's particles, front row first
  int64_t released = 0;            // particles that joined the fluid
  double mass_in = 0;              // their mass
  int32_t per_row() const { return m[0] * m[1]; }
  // The instant row k reaches the gate plane (one formula for every decision about it).
  double release_time(int64_t k) const { return t0 + (static_cast<double>(k) + 0.5) * d / U; }
};

// An outflow plane through p with unit outward normal nrm: an active fluid particle with
// (x - p).nrm > 0 returns to the dormant pool.
struct OutflowPlane {
  double p[3] = {0, 0, 0}, nrm[3] = {0, 0, 0};
  int64_t removed = 0;
  double mass_out = 0;
};

struct FluidOpen {
  FluidOpen();
  ~FluidOpen();  // in fluid_inflow.cpp, where FluidSystem is complete
  void index_active();  // the active list and slot from the states (the inner fluid then dirty)
  std::vector<int8_t> state;       // per particle of the capacity
  std::vector<int32_t> active;     // the active particles in increasing order: the inner fluid's
  std::vector<int32_t> slot;       // per particle: its place in active, -1 if dormant
  std::vector<int32_t> gate_of;    // buffer particle: its gate; else -1
  std::vector<int64_t> row_of;     // buffer particle: its row
  std::vector<double> base;        // buffer particle: its lattice point on the gate (dim)
  std::vector<InflowGate> gates;
  std::vector<OutflowPlane> outflows;
  bool updated = false;            // an update ran (the active set is then fixed by it)
  // The fluid of the active particles, with the capacity system's options; rebuilt when
  // the active set or an option changes.
  std::unique_ptr<FluidSystem> inner;
  bool dirty = true;
  std::vector<double> yc, rc, vc;  // compact state, rates and (mass products on ranks) vector
  int64_t gen = 0;                 // bumped by index_active: the states changed
  // On ranks (fluid_ranks_open.cpp) the fields above are per global id over every rank's
  // items, ids 0 .. N - 1, and the same on every rank: set up by the first collective
  // call (`global`); set_active's count waits for it in pending_active (-1: none).
  bool global = false;
  int32_t pending_active = -1;
};

// The integration's progress callback's data, per window (sys's open_stepper()): yc the
// inner fluid's state, fn and user the host's callback, base the steps of earlier windows.
struct OpenProgress {
  const FluidSystem *sys;
  double *yc;
  mfree_progress_fn fn;
  void *user;
  int64_t base;
  bool user_stop = false;
};

// An active fluid particle past an outflow plane: its index in the capacity (on ranks its
// global id), the plane, its mass.
struct OutflowCrossing {
  int32_t i = 0, plane = 0;
  double mass = 0.0;
};

}  // namespace mfree
