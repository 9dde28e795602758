// Open boundaries of the Galerkin-SPH fluid (fluid_inflow.hpp): the active set, inflow
// gates and outflow planes, and the evaluations and integration of a capacity system.
//
// The evaluations of a system with open boundaries run on a fluid of its active particles
// alone (`inner`, built through the public setters with this system's options), on a
// compact copy of their state: the dormant particles are then out of the nodes, the
// tables, the checks and the step control by construction, and no evaluation code needs
// to know about them. The inner fluid is rebuilt when the active set changes, i.e. once
// per injected row of a gate; its rates are scattered back, zero for dormant particles,
// the imposed ones for buffer particles.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "core/base/kernel.hpp"
#include "core/systems/fluid.hpp"

namespace mfree {

FluidOpen::FluidOpen() = default;
FluidOpen::~FluidOpen() = default;

void FluidOpen::index_active() {
  active.clear();
  for (size_t i = 0; i < state.size(); ++i)
    if (state[i] != kDormant) active.push_back(static_cast<int32_t>(i));
  slot.assign(state.size(), -1);
  for (size_t a = 0; a < active.size(); ++a) slot[active[a]] = static_cast<int32_t>(a);
  dirty = true;
  ++gen;
}

namespace {

double dot(const double *a, const double *b, int dim) {
  double s = 0.0;
  for (int c = 0; c < dim; ++c) s += a[c] * b[c];
  return s;
}

void check_finite(const double *a, int n, const char *what) {
  for (int c = 0; c < n; ++c)
    if (!std::isfinite(a[c])) throw Error(MFREE_ERR_INPUT, std::string(what) + " is not finite");
}

void check_unit(const double *nrm, int dim, const char *what) {
  const double len = std::sqrt(dot(nrm, nrm, dim));
  if (!(std::fabs(len - 1.0) < 1e-6)) throw Error(MFREE_ERR_ARG, std::string(what) + " is not a unit vector");
}

// A compact state or rate of the active particles written into the capacity's layout.
void scatter_state(const std::vector<int32_t> &active, int dim, int32_t n, const double *src, double *dst) {
  const size_t na = active.size(), nd = static_cast<size_t>(dim) * n, ndc = na * dim;
  for (size_t a = 0; a < na; ++a) {
    const size_t i = active[a];
    for (int c = 0; c < dim; ++c) {
      dst[i * dim + c] = src[a * dim + c];
      dst[nd + i * dim + c] = src[ndc + a * dim + c];
    }
    dst[2 * nd + i] = src[2 * ndc + a];
  }
}

}  // namespace

FluidOpen &FluidSystem::open() {
  if (!open_) {
    auto o = std::make_unique<FluidOpen>();
    // on ranks the per-particle fields are per global id, set up at the first collective call
    if (!on_ranks()) {
      o->state.assign(n_, kFluid);
      o->gate_of.assign(n_, -1);
      o->row_of.assign(n_, 0);
      o->base.assign(static_cast<size_t>(n_) * dim_, 0.0);
      o->index_active();
    }
    open_ = std::move(o);
  }
  return *open_;
}

void FluidSystem::set_active(int32_t nactive) {
  if (on_ranks()) {  // the capacity is every rank's items: checked at the first collective call
    if (nactive < 0) throw Error(MFREE_ERR_ARG, "active count " + std::to_string(nactive) + " is negative");
    if (open_ && open_->updated)
      throw Error(MFREE_ERR_STATE, "the active particles are set before the open boundaries' first update");
    open().pending_active = nactive;
    return;
  }
  if (nactive < 0 || nactive > n_)
    throw Error(MFREE_ERR_ARG, "active count " + std::to_string(nactive) + " outside [0, " + std::to_string(n_) + "]");
  if (open_ && open_->updated)
    throw Error(MFREE_ERR_STATE, "the active particles are set before the open boundaries' first update");
  FluidOpen &o = open();
  for (int32_t i = 0; i < n_; ++i) o.state[i] = i < nactive ? kFluid : kDormant;
  o.index_active();
}

void FluidSystem::set_inflow(int32_t gate, const double *origin, const double *edges, const double *normal,
                             double speed, double density, double spacing) {
  const int32_t ng = open_ ? static_cast<int32_t>(open_->gates.size()) : 0;
  if (gate < 0 || gate > ng)
    throw Error(MFREE_ERR_ARG, "gate " + std::to_string(gate) + ": gates are numbered 0.." + std::to_string(ng));
  if (gate < ng && open_->gates[gate].started)
    throw Error(MFREE_ERR_STATE, "gate " + std::to_string(gate) + " has started injecting");
  if (!origin || !edges || !normal) throw Error(MFREE_ERR_NULL, "gate origin, edges or normal is NULL");
  if (!(std::isfinite(speed) && speed > 0.0) || !(std::isfinite(density) && density > 0.0) ||
      !(std::isfinite(spacing) && spacing > 0.0))
    throw Error(MFREE_ERR_ARG, "a gate needs finite speed, density and spacing > 0");
  const int dim = dim_, ne = dim - 1;
  check_finite(origin, dim, "gate origin");
  check_finite(edges, dim * ne, "gate edge");
  check_finite(normal, dim, "gate normal");
  check_unit(normal, dim, "gate normal");
  InflowGate g;
  double len[2] = {0, 0};
  for (int c = 0; c < dim; ++c) {
    g.o[c] = origin[c];
    g.nrm[c] = normal[c];
  }
  for (int k = 0; k < ne; ++k) {
    for (int c = 0; c < dim; ++c) g.e[k][c] = edges[k * dim + c];
    len[k] = std::sqrt(dot(g.e[k], g.e[k], dim));
    if (!(len[k] >= 0.5 * spacing))
      throw Error(MFREE_ERR_ARG, "gate edge " + std::to_string(k) + " is shorter than half the spacing");
    if (std::fabs(dot(g.e[k], g.nrm, dim)) > 1e-6 * len[k])
      throw Error(MFREE_ERR_ARG, "gate normal is not orthogonal to edge " + std::to_string(k));
    g.m[k] = static_cast<int32_t>(std::max(1.0, std::round(len[k] / spacing)));
  }
  double area = len[0];
  if (dim == 3) {
    const double *a = g.e[0], *b = g.e[1];
    const double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2], cz = a[0] * b[1] - a[1] * b[0];
    area = std::sqrt(cx * cx + cy * cy + cz * cz);
    if (!(area > 1e-6 * len[0] * len[1])) throw Error(MFREE_ERR_ARG, "gate edges are parallel");
  }
  g.U = speed;
  g.rho = density;
  g.d = spacing;
  g.mass_each = density * spacing * area / g.per_row();
  FluidOpen &o = open();
  if (gate == ng) o.gates.push_back(g);
  else o.gates[gate] = g;
}

void FluidSystem::set_outflow(int32_t k, const double *point, const double *normal) {
  const int32_t no = open_ ? static_cast<int32_t>(open_->outflows.size()) : 0;
  if (k < 0 || k > no)
    throw Error(MFREE_ERR_ARG, "outflow " + std::to_string(k) + ": outflows are numbered 0.." + std::to_string(no));
  if (!point || !normal) throw Error(MFREE_ERR_NULL, "outflow point or normal is NULL");
  check_finite(point, dim_, "outflow point");
  check_finite(normal, dim_, "outflow normal");
  check_unit(normal, dim_, "outflow normal");
  OutflowPlane p;
  for (int c = 0; c < dim_; ++c) {
    p.p[c] = point[c];
    p.nrm[c] = normal[c];
  }
  FluidOpen &o = open();
  if (k == no) o.outflows.push_back(p);
  else o.outflows[k] = p;
}

int32_t FluidSystem::active_states(int32_t n, int32_t *state) const {
  const int32_t np = neq() / (2 * dim_ + 1);  // the state's particles (on ranks the owned ones)
  if (state && n != np)
    throw Error(MFREE_ERR_ARG, "state holds " + std::to_string(n) + " values, the system has " + std::to_string(np));
  if (!open_) {
    if (state) std::fill(state, state + np, static_cast<int32_t>(kFluid));
    return np;
  }
  if (state)
    for (int32_t i = 0; i < n_; ++i) state[i] = open_->state[i];
  return static_cast<int32_t>(open_->active.size());
}

void FluidSystem::inflow_totals(int32_t gate, int64_t &count, double &mass) const {
  const int32_t ng = open_ ? static_cast<int32_t>(open_->gates.size()) : 0;
  if (gate < 0 || gate >= ng)
    throw Error(MFREE_ERR_ARG, "gate " + std::to_string(gate) + " is not set (" + std::to_string(ng) + " gates)");
  count = open_->gates[gate].released;
  mass = open_->gates[gate].mass_in;
}

void FluidSystem::outflow_totals(int32_t k, int64_t &count, double &mass) const {
  const int32_t no = open_ ? static_cast<int32_t>(open_->outflows.size()) : 0;
  if (k < 0 || k >= no)
    throw Error(MFREE_ERR_ARG, "outflow " + std::to_string(k) + " is not set (" + std::to_string(no) + " outflows)");
  count = open_->outflows[k].removed;
  mass = open_->outflows[k].mass_out;
}

void FluidSystem::buffer_state(int32_t i, double t, double *x, double *v, double *rho) const {
  const FluidOpen &o = *open_;
  const InflowGate &g = o.gates[o.gate_of[i]];
  const double s = g.U * (t - g.t0) - (static_cast<double>(o.row_of[i]) + 0.5) * g.d;
  for (int c = 0; c < dim_; ++c) {
    x[c] = o.base[static_cast<size_t>(i) * dim_ + c] + s * g.nrm[c];
    v[c] = g.U * g.nrm[c];
  }
  *rho = g.rho;
}

void FluidSystem::place_buffer(double t, double *y, bool compact) const {
  const FluidOpen &o = *open_;
  const int dim = dim_;
  const size_t n = compact ? o.active.size() : static_cast<size_t>(n_), nd = n * dim;
  for (const InflowGate &g : o.gates)
    for (const auto &row : g.rows)
      for (int32_t i : row) {
        const size_t j = compact ? static_cast<size_t>(o.slot[i]) : static_cast<size_t>(i);
        buffer_state(i, t, y + j * dim, y + nd + j * dim, y + 2 * nd + j);
      }
}

int32_t FluidSystem::crossed_plane(const double *x) const {
  const FluidOpen &o = *open_;
  for (size_t k = 0; k < o.outflows.size(); ++k) {
    const OutflowPlane &p = o.outflows[k];
    double s = 0.0;
    for (int c = 0; c < dim_; ++c) s += (x[c] - p.p[c]) * p.nrm[c];
    if (s > 0.0) return static_cast<int32_t>(k);
  }
  return -1;
}

bool FluidSystem::open_crossed(const double *y, bool compact) const {
  const FluidOpen &o = *open_;
  if (o.outflows.empty()) return false;
  const int dim = dim_;
  for (size_t a = 0; a < o.active.size(); ++a) {
    const int32_t i = o.active[a];
    if (o.state[i] != kFluid) continue;
    if (crossed_plane(y + (compact ? a : static_cast<size_t>(i)) * dim) >= 0) return true;
  }
  return false;
}

Report FluidSystem::update_open(double t, double *y) {
  if (!std::isfinite(t)) throw Error(MFREE_ERR_ARG, "time must be finite");
  check_ready();
  FluidOpen &o = open();
  std::vector<OutflowCrossing> out;
  for (int32_t i : o.active) {
    if (o.state[i] != kFluid) continue;
    const int32_t k = crossed_plane(y + static_cast<size_t>(i) * dim_);
    if (k >= 0) out.push_back({i, k, mass_[i]});
  }
  std::vector<std::pair<int32_t, int32_t>> fresh;
  Report rep = open_plan(t, out, fresh);
  if (!rep.ok()) return rep;
  for (const auto &q : fresh) {
    rho0_[q.first] = o.gates[q.second].rho;
    mass_[q.first] = o.gates[q.second].mass_each;
  }
  place_buffer(t, y, false);
  return Report();
}

Report FluidSystem::open_plan(double t, const std::vector<OutflowCrossing> &out,
                              std::vector<std::pair<int32_t, int32_t>> &fresh) {
  FluidOpen &o = *open_;
  const int dim = dim_;
  const int64_t cap = static_cast<int64_t>(o.state.size());
  // The plan first, applied only when the pool holds every particle it needs.
  const double R = Kernel::support_radius(kernel_id_, kernel_param_) * h_;
  std::vector<InflowGate> plan = o.gates;  // the gates' counters after the update
  std::vector<int64_t> first_new(plan.size());
  int64_t dormant = cap - static_cast<int64_t>(o.active.size()) + static_cast<int64_t>(out.size());
  int64_t need = 0;
  for (size_t k = 0; k < plan.size(); ++k) {
    InflowGate &g = plan[k];
    if (!g.started) {
      g.started = true;
      g.t0 = t;
      g.nb = static_cast<int32_t>(std::max(1.0, std::ceil(R / g.d - 1e-9)));
    }
    first_new[k] = g.activated_rows;
    // row r is in the buffer from the instant row r - nb joins the fluid
    while (need <= dormant && (g.activated_rows < g.nb || g.release_time(g.activated_rows - g.nb) <= t)) {
      ++g.activated_rows;
      need += g.per_row();
    }
    if (need > dormant) {
      std::ostringstream s;
      s << "the pool of dormant particles is exhausted at t = " << t << ": gate " << k << " needs a row of "
        << g.per_row() << " particles, " << dormant - (need - g.per_row()) << " are left (capacity " << cap << ", "
        << o.active.size() << " active)";
      Report rep;
      rep.fail(MFREE_FAIL_CAPACITY, s.str());
      return rep;
    }
  }
  // apply: outflow, then the new rows from the lowest dormant indices, then releases
  for (const OutflowCrossing &q : out) {
    o.state[q.i] = kDormant;
    o.outflows[q.plane].removed += 1;
    o.outflows[q.plane].mass_out += q.mass;
  }
  int32_t cursor = 0;
  bool changed = !out.empty();
  for (size_t k = 0; k < plan.size(); ++k) {
    InflowGate &g = plan[k];
    for (int64_t r = first_new[k]; r < g.activated_rows; ++r) {
      std::vector<int32_t> row;
      row.reserve(g.per_row());
      for (int32_t j1 = 0; j1 < g.m[1]; ++j1)
        for (int32_t j0 = 0; j0 < g.m[0]; ++j0) {
          while (o.state[cursor] != kDormant) ++cursor;  // the plan guarantees one
          const int32_t i = cursor++;
          o.state[i] = kInflow;
          o.gate_of[i] = static_cast<int32_t>(k);
          o.row_of[i] = r;
          for (int c = 0; c < dim; ++c)
            o.base[static_cast<size_t>(i) * dim + c] = g.o[c] + (j0 + 0.5) / g.m[0] * g.e[0][c] +
                                                       (dim == 3 ? (j1 + 0.5) / g.m[1] * g.e[1][c] : 0.0);
          fresh.push_back({i, static_cast<int32_t>(k)});
          row.push_back(i);
        }
      g.rows.push_back(std::move(row));
      changed = true;
    }
    while (g.released_rows < g.activated_rows && g.release_time(g.released_rows) <= t) {
      for (int32_t i : g.rows.front()) {
        o.state[i] = kFluid;
        o.gate_of[i] = -1;
      }
      g.released += g.per_row();
      g.mass_in += g.per_row() * g.mass_each;
      g.rows.pop_front();
      ++g.released_rows;
      changed = true;
    }
  }
  o.gates.swap(plan);
  o.updated = true;
  if (changed) o.index_active();
  return Report();
}

FluidSystem &FluidSystem::open_inner() const {
  FluidOpen &o = *open_;
  if (o.inner && !o.dirty) return *o.inner;
  check_ready();
  const int32_t na = static_cast<int32_t>(o.active.size());
  std::vector<double> r0(na), m(na);
  for (int32_t a = 0; a < na; ++a) {
    r0[a] = rho0_[o.active[a]];
    m[a] = mass_[o.active[a]];
  }
  auto in = std::make_unique<FluidSystem>(dim_, na);
  open_options(*in, r0.data(), m.data());
  o.inner = std::move(in);
  o.dirty = false;
  return *o.inner;
}

void FluidSystem::open_options(FluidSystem &in, const double *r0, const double *m) const {
  if (in.n_ > 0) {
    in.set_fluid(r0, 1, kappa_, gamma_, mu_);
    in.set_masses(m, 1);
  } else {
    in.kappa_ = kappa_, in.gamma_ = gamma_, in.mu_ = mu_;
    in.mass_.clear();
  }
  in.set_smoothing(h_);
  in.set_gravity(g_);
  in.set_lumping(lump_);
  if (walls_) {
    const int32_t nw = walls_->size();
    std::vector<double> xw(static_cast<size_t>(nw) * dim_);
    for (int32_t w = 0; w < nw; ++w)
      for (int c = 0; c < dim_; ++c) xw[static_cast<size_t>(w) * dim_ + c] = walls_->x(w, c);
    in.set_walls(nw, xw.data(), wall_n_.data(), r0_, strength_);
  }
  if (box_) in.set_box(lo_, hi_);
  in.set_shepard_condition(shepard_cond_);
  in.set_approximation(method_, order_, kernel_id_, kernel_param_);
  if (dummy_.n > 0) in.set_dummy_particles(dummy_.n, dummy_.xd.data(), vol_.data() + n_, 1);
  in.set_density_diffusion(delta_);
  in.set_consistent_integration(vci_ ? 1 : 0);
  in.set_velocity_smoothing(vsmooth_);
  in.set_lumped_mass_step(lumped_step_ ? 1 : 0);
  in.set_acoustic_step(acoustic_step_ ? 1 : 0);
}

const double *FluidSystem::open_gather(const double *y) const {
  FluidOpen &o = *open_;
  const int dim = dim_;
  const size_t na = o.active.size(), nd = static_cast<size_t>(dim) * n_, ndc = na * dim;
  o.yc.resize(na * (2 * dim + 1));
  for (size_t a = 0; a < na; ++a) {
    const size_t i = o.active[a];
    for (int c = 0; c < dim; ++c) {
      o.yc[a * dim + c] = y[i * dim + c];
      o.yc[ndc + a * dim + c] = y[nd + i * dim + c];
    }
    o.yc[2 * ndc + a] = y[2 * nd + i];
  }
  return o.yc.data();
}

Report FluidSystem::open_result(Report r) const {
  // the inner fluid names its particles by their place among the active ones (on ranks
  // it names their global ids itself)
  if (r.ok() || on_ranks()) return r;
  const std::string key = "particle ";
  std::string msg;
  size_t pos = 0;
  for (;;) {
    const size_t k = r.message.find(key, pos);
    if (k == std::string::npos) break;
    size_t e = k + key.size();
    while (e < r.message.size() && std::isdigit(static_cast<unsigned char>(r.message[e]))) ++e;
    msg += r.message.substr(pos, k + key.size() - pos);
    const std::string num = r.message.substr(k + key.size(), e - k - key.size());
    const long a = num.empty() ? -1 : std::stol(num);
    msg += a >= 0 && static_cast<size_t>(a) < open_->active.size() ? std::to_string(open_->active[a]) : num;
    pos = e;
  }
  r.message = msg + r.message.substr(pos);
  return r;
}

Report FluidSystem::open_rhs(const double *y, double *ydot) {
  FluidSystem &in = open_inner();
  const double *yc = open_gather(y);
  FluidOpen &o = *open_;
  const int dim = dim_;
  const size_t na = o.active.size(), nd = static_cast<size_t>(dim) * n_;
  o.rc.assign(na * (2 * dim + 1), 0.0);
  Report rep = na > 0 ? in.rhs(0.0, yc, o.rc.data()) : Report();
  std::fill(ydot, ydot + static_cast<size_t>(neq()), 0.0);  // dormant: zero rates
  scatter_state(o.active, dim, n_, o.rc.data(), ydot);
  for (const InflowGate &g : o.gates)  // buffers: imposed motion
    for (const auto &row : g.rows)
      for (int32_t i : row) {
        for (int c = 0; c < dim; ++c) {
          ydot[static_cast<size_t>(i) * dim + c] = g.U * g.nrm[c];
          ydot[nd + static_cast<size_t>(i) * dim + c] = 0.0;
        }
        ydot[2 * nd + i] = 0.0;
      }
  return open_result(rep);
}

Report FluidSystem::open_velocity(const double *y, double *vhat) {
  FluidSystem &in = open_inner();
  const double *yc = open_gather(y);
  FluidOpen &o = *open_;
  const int dim = dim_;
  const size_t na = o.active.size();
  o.rc.assign(na * dim, 0.0);
  Report rep = na > 0 ? in.velocity(yc, o.rc.data()) : Report();
  std::fill(vhat, vhat + static_cast<size_t>(n_) * dim, 0.0);
  for (size_t a = 0; a < na; ++a)
    for (int c = 0; c < dim; ++c) vhat[static_cast<size_t>(o.active[a]) * dim + c] = o.rc[a * dim + c];
  for (const InflowGate &g : o.gates)
    for (const auto &row : g.rows)
      for (int32_t i : row)
        for (int c = 0; c < dim; ++c) vhat[static_cast<size_t>(i) * dim + c] = g.U * g.nrm[c];
  return open_result(rep);
}

void FluidSystem::open_pressure(const double *y, double *p) const {
  const FluidSystem &in = open_inner();
  const double *yc = open_gather(y);
  const FluidOpen &o = *open_;
  std::vector<double> pc(o.active.size());
  if (!o.active.empty()) in.pressure(yc, pc.data());
  std::fill(p, p + n_, 0.0);
  for (size_t a = 0; a < o.active.size(); ++a) p[o.active[a]] = pc[a];
}

void FluidSystem::expand(const SparseMatrix &A, const std::vector<int32_t> &map, int32_t n, int32_t ncols,
                         SparseMatrix &out) {
  std::vector<int32_t> inv(ncols, -1);
  for (size_t q = 0; q < map.size(); ++q) inv[map[q]] = static_cast<int32_t>(q);
  std::vector<int64_t> rp(static_cast<size_t>(n) + 1, 0);
  std::vector<int32_t> cols;
  std::vector<double> vals;
  const auto &arp = A.rowptr();
  const auto &acol = A.colidx();
  const auto &aval = A.values();
  for (int32_t r = 0; r < n; ++r) {
    if (inv[r] < 0) {
      cols.push_back(r);
      vals.push_back(1.0);
    } else {
      for (int64_t e = arp[inv[r]]; e < arp[inv[r] + 1]; ++e) {
        cols.push_back(map[acol[e]]);  // map increases: columns stay sorted
        vals.push_back(aval[e]);
      }
    }
    rp[r + 1] = static_cast<int64_t>(cols.size());
  }
  out.set_pattern(n, ncols, std::move(rp), std::move(cols));
  std::copy(vals.begin(), vals.end(), out.values_mut().begin());
}

Report FluidSystem::open_interpolation(const double *y, SparseMatrix &S) {
  FluidSystem &in = open_inner();
  const double *yc = open_gather(y);
  SparseMatrix Sc;
  Report rep = open_->active.empty() ? Report() : in.interpolation(yc, Sc);
  if (!rep.ok()) return open_result(rep);
  if (open_->active.empty()) Sc.set_pattern(0, 0, std::vector<int64_t>(1, 0), {});
  expand(Sc, open_->active, n_, n_, S);
  return rep;
}

Report FluidSystem::open_mass(const double *y, bool consistent, SparseMatrix &M) {
  FluidSystem &in = open_inner();
  const double *yc = open_gather(y);
  const FluidOpen &o = *open_;
  SparseMatrix Mc;
  Report rep = o.active.empty() ? Report() : in.mass(yc, consistent, Mc);
  if (!rep.ok()) return open_result(rep);
  open_expand(Mc, o.active.data(), o.active.size(), n_, M);
  return rep;
}

void FluidSystem::open_expand(SparseMatrix &Mc, const int32_t *item, size_t na, int32_t n, SparseMatrix &M) const {
  if (na == 0) Mc.set_pattern(0, 0, std::vector<int64_t>(1, 0), {});
  const int dim = dim_;
  std::vector<int32_t> map((2 * dim + 1) * na);  // compact unknown -> the state's unknown
  for (size_t a = 0; a < na; ++a) {
    const int32_t i = item[a];
    for (int c = 0; c < dim; ++c) {
      map[a * dim + c] = i * dim + c;
      map[na * dim + a * dim + c] = dim * n + i * dim + c;
    }
    map[2 * na * dim + a] = 2 * dim * n + i;
  }
  expand(Mc, map, (2 * dim + 1) * n, (2 * dim + 1) * n, M);
}

Report FluidSystem::open_wall_force(const double *y, double *total, int32_t nwall, double *per_wall) {
  FluidSystem &in = open_inner();
  const double *yc = open_gather(y);
  return open_result(in.wall_force(yc, total, nwall, per_wall));
}

int32_t FluidSystem::open_progress(void *u, int64_t step, double t, double dt) {
  auto &p = *static_cast<OpenProgress *>(u);
  // the buffers move as imposed, whatever the step did to them
  p.sys->place_buffer(t, p.yc, true);
  const bool crossed = p.sys->open_crossed(p.yc, true);
  if (p.fn && p.fn(p.user, p.base + step, t, dt)) p.user_stop = true;
  return p.user_stop || crossed;
}

FluidSystem &FluidSystem::open_stage(const double *y) {
  FluidSystem &in = open_inner();
  open_gather(y);
  return in;
}

void FluidSystem::open_unstage(const double *yc, double *y) const { scatter_state(open_->active, dim_, n_, yc, y); }

Report FluidSystem::open_integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                                   mfree_progress_fn progress, void *user, int64_t &nsteps) {
  nsteps = 0;
  if (!(std::isfinite(t_end) && std::isfinite(t))) throw Error(MFREE_ERR_ARG, "times must be finite");
  {  // the integrator's own argument checks, before the update changes the state
    FluidSystem &in = open_inner();
    double t0 = t;
    int64_t k = 0;
    open_gather(y);
    in.integrate(scheme, open_->yc.data(), t0, t0, cfl, dt_max, nullptr, nullptr, k);
  }
  return open_windows(scheme, y, t, t_end, cfl, dt_max, progress, user, nsteps);
}

Report FluidSystem::open_windows(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                                 mfree_progress_fn progress, void *user, int64_t &nsteps) {
  nsteps = 0;
  Report rep = update_open(t, y);
  if (!rep.ok()) return rep;
  FluidOpen &o = *open_;
  while (t < t_end) {
    double t_stop = t_end;
    for (const InflowGate &g : o.gates) t_stop = std::min(t_stop, g.release_time(g.released_rows));
    FluidSystem &in = open_stage(y);
    OpenProgress p{this, o.yc.data(), progress, user, nsteps};
    int64_t k = 0;
    if (!o.active.empty()) {
      rep = in.integrate(scheme, o.yc.data(), t, t_stop, cfl, dt_max, open_stepper(), &p, k);
    } else {
      t = t_stop;  // nothing to integrate until a gate injects
    }
    nsteps += k;
    open_unstage(o.yc.data(), y);
    if (!rep.ok()) return open_result(rep);
    if (p.user_stop) break;
    rep = update_open(t, y);
    if (!rep.ok()) return rep;
  }
  return rep;
}

}  // namespace mfree
