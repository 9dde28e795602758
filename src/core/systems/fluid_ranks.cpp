// The fluid on ranks. A particle's acceleration sums the terms of the quadrature points
// (the nodes) whose rows hold it, and each such row needs its own neighbours: the rows a
// rank needs are its owned nodes' and those of the ghosts within one support radius of
// them, and these are complete when the ghosts reach two radii. The nodes are numbered
// by global id (owned and ghosts merged), so that every row, every sum over a row and
// the scatter of the rows' terms (one colour, rows in node order) run in global-id
// order: an owned particle's results then depend only on its neighbourhood, as on one
// rank. The rows of ghosts further out are incomplete: they are dropped after each
// prepare (rows_done), and their nodes' accelerations are never used. The step limit is
// a minimum over ranks (exact); statuses are agreed through the all-gather, so that
// every rank returns the same outcome and none waits alone in a collective call.
#include "core/systems/fluid_ranks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <sstream>

#include "core/base/exact_sum.hpp"

namespace mfree {

namespace {

int32_t local_count(int32_t n_owned, int32_t n_ghost) {
  if (n_owned < 0 || n_ghost < 0)
    throw Error(MFREE_ERR_ARG, "negative particle count (" + std::to_string(n_owned) + " owned, " +
                                   std::to_string(n_ghost) + " ghosts)");
  if (n_owned > INT32_MAX - n_ghost) throw Error(MFREE_ERR_ARG, "more than 2^31 - 1 particles on a rank");
  return n_owned + n_ghost;
}

}  // namespace

FluidRanks::FluidRanks(int dim, int32_t n_owned, int32_t n_ghost, const int64_t *ids, double width,
                       const Collective &coll)
    : FluidSystem(dim, local_count(n_owned, n_ghost)), coll_(coll), n_own_(n_owned), n_ghost_(n_ghost),
      width_(width) {
  if (!(std::isfinite(width) && width > 0.0))
    throw Error(MFREE_ERR_ARG, "the halo width must be finite and > 0, not " + std::to_string(width));
  number(ids);
}

void FluidRanks::number(const int64_t *ids) {
  const int32_t n = size();
  if (n > 0 && !ids) throw Error(MFREE_ERR_NULL, "global ids are NULL");
  std::vector<int32_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) { return ids[a] < ids[b]; });
  for (int32_t q = 0; q < n; ++q) {
    if (ids[order[q]] < 0)
      throw Error(MFREE_ERR_INPUT, "global id " + std::to_string(ids[order[q]]) + " of item " +
                                       std::to_string(order[q]) + " is negative");
    if (q > 0 && ids[order[q]] == ids[order[q - 1]])
      throw Error(MFREE_ERR_INPUT, "global id " + std::to_string(ids[order[q]]) + " is given twice (items " +
                                       std::to_string(std::min(order[q], order[q - 1])) + " and " +
                                       std::to_string(std::max(order[q], order[q - 1])) + ")");
  }
  node_.resize(n);
  gid_.resize(n);
  is_owned_.assign(n, 0);
  for (int32_t q = 0; q < n; ++q) {
    node_[order[q]] = q;
    gid_[q] = ids[order[q]];
  }
  owned_.resize(n_own_);
  for (int32_t p = 0; p < n_own_; ++p) {
    owned_[p] = node_[p];
    is_owned_[node_[p]] = 1;
  }
}

std::unique_ptr<FluidRanks> FluidRanks::create(int dim, int32_t n_owned, int32_t n_ghost, const int64_t *ids,
                                               double width, const Collective &coll) {
  std::unique_ptr<FluidRanks> sys;
  const Report mine = coll.local([&] {
    sys.reset(new FluidRanks(dim, n_owned, n_ghost, ids, width, coll));
    return Report();
  });
  const double v[3] = {static_cast<double>(mine.status), static_cast<double>(dim), width};
  const std::vector<double> all = coll.allgather(v, 3);
  const size_t np = all.size() / 3;
  std::vector<double> st(np);
  for (size_t p = 0; p < np; ++p) st[p] = all[3 * p];
  const Report agreed = coll.agree_from(st, mine);
  if (!agreed.ok()) throw Error(agreed.status, agreed.message);
  static const char *names[3] = {"", "the dimension", "the halo width"};
  for (size_t p = 1; p < np; ++p)
    for (int k = 1; k < 3; ++k)
      if (!(all[3 * p + k] == all[k])) {
        std::ostringstream s;
        s.precision(17);
        s << "ranks disagree on " << names[k] << ": rank 0 passes " << all[k] << ", rank " << p << " passes "
          << all[3 * p + k] << " (every rank must pass the same)";
        throw Error(MFREE_ERR_ARG, s.str());
      }
  return sys;
}

void FluidRanks::to_nodes(HVec<double> &a) const {
  HVec<double> b(a.size());
  for (size_t p = 0; p < a.size(); ++p) b[node_[p]] = a[p];
  a.swap(b);
}

void FluidRanks::rows_done() {
  const int32_t n = nq();
  need_.assign(n, 0);
  for (int32_t k : owned_) {
    need_[k] = 1;
    for (int64_t e = rb_[k]; e < re_[k]; ++e) need_[cols_[e]] = 1;
  }
  // With dummies and density diffusion, the density gradients at the needed nodes read
  // the extrapolated densities of the dummies in their rows (a pass deeper, level 3 at
  // most where the gradient weighs them), and these read the dummies of the pass before
  // (level 2, from the fluid in their rows): those two sets of dummy rows stay too, and
  // are complete with ghosts four support radii deep (depth()).
  if (depth() > 2)
    for (char level = 2; level <= 3; ++level)
      for (int32_t k = 0; k < n; ++k) {
        if (need_[k] != level - 1) continue;
        for (int64_t e = rb_[k]; e < re_[k]; ++e)
          if (cols_[e] >= n_ && !need_[cols_[e]]) need_[cols_[e]] = level;
      }
  // The rows are the particle set's lists (re_ points into them): the emptied rows go
  // to a copy of the row ends, which the next candidates() replaces.
  re_need_.resize(n);
  for (int32_t k = 0; k < n; ++k) {
    re_need_[k] = need_[k] ? re_[k] : rb_[k];
    if (!need_[k]) site_status_[k] = 0;
  }
  re_ = re_need_.data();
  const int32_t nch = (n + kChunk - 1) / kChunk;
  color_ptr_.assign({0, nch});
  chunk_order_.resize(nch);
  std::iota(chunk_order_.begin(), chunk_order_.end(), 0);
  scatter_threads_ = false;
}

void FluidRanks::load(const double *y) {
  const int D = dim(), rec = 2 * D + 1;
  const int32_t n = size();
  buf_.resize(static_cast<size_t>(n) * rec);
  const double *x = y, *v = y + static_cast<size_t>(D) * n_own_, *rho = y + 2 * static_cast<size_t>(D) * n_own_;
  for (int32_t p = 0; p < n_own_; ++p) {
    double *b = &buf_[static_cast<size_t>(p) * rec];
    for (int c = 0; c < D; ++c) {
      b[c] = x[p * D + c];
      b[D + c] = v[p * D + c];
    }
    b[2 * D] = rho[p];
  }
  coll_.exchange(rec, buf_.data(), rec);
  ys_.resize(static_cast<size_t>(rec) * n);
  double *xs = ys_.data(), *vs = xs + static_cast<size_t>(D) * n, *rs = vs + static_cast<size_t>(D) * n;
  for (int32_t p = 0; p < n; ++p) {
    const double *b = &buf_[static_cast<size_t>(p) * rec];
    const int32_t k = node_[p];
    for (int c = 0; c < D; ++c) {
      xs[k * D + c] = b[c];
      vs[k * D + c] = b[D + c];
    }
    rs[k] = b[2 * D];
  }
}

void FluidRanks::sync(double *a, int na, double *b, int nb, double *c, int nc) {
  const int rec = na + nb + nc;
  const int32_t n = size();
  buf_.resize(static_cast<size_t>(n) * rec);
  for (int32_t p = 0; p < n_own_; ++p) {
    double *r = &buf_[static_cast<size_t>(p) * rec];
    const size_t k = owned_[p];
    std::copy(a + k * na, a + (k + 1) * na, r);
    if (nb) std::copy(b + k * nb, b + (k + 1) * nb, r + na);
    if (nc) std::copy(c + k * nc, c + (k + 1) * nc, r + na + nb);
  }
  coll_.exchange(rec, buf_.data(), rec);
  for (int32_t p = n_own_; p < n; ++p) {
    const double *r = &buf_[static_cast<size_t>(p) * rec];
    const size_t k = node_[p];
    std::copy(r, r + na, a + k * na);
    if (nb) std::copy(r + na, r + na + nb, b + k * nb);
    if (nc) std::copy(r + na + nb, r + rec, c + k * nc);
  }
}

Report FluidRanks::owned_accel(const double *v, const double *rho, double *a) {
  Report r = accel(v, rho, a);
  ghost_fault_ = false;
  if (r.status != MFREE_FAIL_SINGULAR || lump_ != MFREE_LUMP_GALERKIN) return r;
  const int D = dim(), A = 2 * D + 2;
  for (int32_t k = 0; k < size(); ++k) {
    const double m = acc_[static_cast<size_t>(k) * A + D + 1];
    if (is_owned_[k] && !(m > 0.0)) {
      std::ostringstream s;
      s << "particle " << k << " (global id " << gid_[k] << ") has a non-positive lumped mass " << m;
      Report bad;
      bad.fail(MFREE_FAIL_SINGULAR, s.str());
      ghost_fault_ = false;
      return bad;
    }
  }
  return Report();
}

Report FluidRanks::prepare_accel(const double *ys, bool checked, double *a, double &limit, double &reach) {
  Report r = prepare_rows(ys, checked, limit, reach);
  if (!r.ok()) return r;
  const size_t nd = static_cast<size_t>(dim()) * size();
  return owned_accel(ys + nd, ys + 2 * nd, a);
}

Report FluidRanks::prepare_rows(const double *ys, bool checked, double &limit, double &reach) {
  ghost_fault_ = false;
  Report r = named(prepare(ys, checked));
  if (!r.ok()) return r;
  const int D = dim();
  const double *x = ys;
  if (xfirst_.size() != static_cast<size_t>(D) * n_own_ + 1) {  // (one more item: set, also with no owned particle)
    xfirst_.assign(static_cast<size_t>(D) * n_own_ + 1, 0.0);
    for (int32_t p = 0; p < n_own_; ++p)
      for (int c = 0; c < D; ++c) xfirst_[p * D + c] = x[static_cast<size_t>(owned_[p]) * D + c];
  }
  double d2 = 0.0;
  for (int32_t p = 0; p < n_own_; ++p) {
    double s = 0.0;
    for (int c = 0; c < D; ++c) {
      const double dc = x[static_cast<size_t>(owned_[p]) * D + c] - xfirst_[p * D + c];
      s += dc * dc;
    }
    d2 = std::max(d2, s);
  }
  // particles within depth() R h of an owned particle now were within depth() R h + 2 d of
  // it at the first evaluation, when the ghost layer held every particle within the width
  reach = -(depth() * (kernel_->radius() * h_) + 2.0 * std::sqrt(d2));
  limit = stable_dt(ys);
  return r;
}

void FluidRanks::check_reach(double reach, int64_t step) const {
  if (!(-reach > width_)) return;
  std::ostringstream s;
  if (step > 0) s << "step " << step << ": ";
  s << "the ghost layer (width " << width_ << ") no longer reaches "
    << (depth() > 2 ? "four support radii (dummy particles with density diffusion)" : "two support radii")
    << " around every owned particle (" << -reach << " with the particles' displacements): rebuild the halo and "
    << "the system";
  throw Error(MFREE_ERR_HALO, s.str());
}

Report FluidRanks::agree_min(const Report &mine, double *vals, int nv) const {
  const int rec = 2 + nv;
  std::vector<double> in(rec);
  in[0] = static_cast<double>(mine.status);
  in[1] = !mine.ok() && ghost_fault_;
  for (int k = 0; k < nv; ++k) in[2 + k] = mine.ok() ? vals[k] : INFINITY;
  const int np = coll_.size();
  std::vector<double> all(static_cast<size_t>(np) * rec);
  coll_.allgather(in.data(), rec, all.data(), static_cast<int64_t>(all.size()));
  std::vector<double> st(np);
  bool owner_failed = false;
  for (int p = 0; p < np; ++p) {
    st[p] = all[static_cast<size_t>(p) * rec];
    owner_failed = owner_failed || (st[p] != 0.0 && all[static_cast<size_t>(p) * rec + 1] == 0.0);
  }
  for (int k = 0; k < nv; ++k) {
    vals[k] = INFINITY;
    for (int p = 0; p < np; ++p) vals[k] = std::min(vals[k], all[static_cast<size_t>(p) * rec + 2 + k]);
  }
  // a ghost's fault is its owner's too: the owner's report is the one to keep
  Report me = mine;
  if (owner_failed) {
    for (int p = 0; p < np; ++p)
      if (all[static_cast<size_t>(p) * rec + 1] != 0.0) st[p] = 0.0;
    if (in[1] != 0.0) me = Report();
  }
  Report agreed = coll_.agree_from(st, me);
  if (agreed.status < 0) throw Error(agreed.status, agreed.message);
  return agreed;
}

Report FluidRanks::named(Report r) const {
  ghost_fault_ = false;
  if (r.ok()) return r;
  for (const char *word : {"particle ", "node "}) {
    const size_t at = r.message.find(word);
    if (at == std::string::npos) continue;
    const char *num = r.message.c_str() + at + std::char_traits<char>::length(word);
    char *end = nullptr;
    const long k = std::strtol(num, &end, 10);
    if (end == num || k < 0 || k >= size()) continue;
    ghost_fault_ = !is_owned_[k];
    r.message.insert(static_cast<size_t>(end - r.message.c_str()), " (global id " + std::to_string(gid_[k]) + ")");
    break;
  }
  return r;
}

Report FluidRanks::rhs(double t, const double *y, double *ydot) {
  (void)t;
  check_usable();
  if (open_) return open_rhs_ranks(y, ydot);
  const int D = dim();
  // (a second pass on the ghosts the host rebuilt when the layer was too shallow)
  for (int pass = 0;; ++pass) {
    const int32_t n = size();
    load(y);
    rate_n_.resize(static_cast<size_t>(D) * n);
    vh_n_.resize(static_cast<size_t>(D) * n);
    dr_n_.resize(n);
    double vals[2] = {INFINITY, INFINITY};
    const Report mine = coll_.local([&] {
      Report r = prepare_accel(ys_.data(), false, rate_n_.data(), vals[0], vals[1]);
      const size_t nd = static_cast<size_t>(D) * n;
      if (r.ok()) kinematics(ys_.data() + nd, ys_.data() + 2 * nd, vh_n_.data(), dr_n_.data());
      return r;
    });
    const Report agreed = agree_min(mine, vals, 2);
    if (!agreed.ok()) return agreed;
    if (-vals[1] > width_ && rebuild_ && pass == 0) {
      rebuild_halo(y);
      continue;
    }
    check_reach(vals[1], 0);
    const size_t no = static_cast<size_t>(D) * n_own_;
    for (int32_t p = 0; p < n_own_; ++p) {
      const size_t k = owned_[p];
      for (int c = 0; c < D; ++c) {
        ydot[p * D + c] = vh_n_[k * D + c];
        ydot[no + p * D + c] = rate_n_[k * D + c];
      }
      ydot[2 * no + p] = dr_n_[k];
    }
    return agreed;
  }
}

// The predictor-corrector's step dt from the node state ys_ (its tables, accelerations
// rate_n_ prepared) into yn_, 003 eqs 111-119 as FluidSystem::integrate takes them.
Report FluidRanks::corrected_state(double dt, int64_t step) {
  const int D = dim();
  const int32_t n = size();
  const size_t nd = static_cast<size_t>(D) * n;
  const double *x = ys_.data(), *v = x + nd, *rho = v + nd;
  double *xn = yn_.data(), *vn = xn + nd, *rn = vn + nd;
  const double *rate = rate_n_.data(), *vh = vh_n_.data(), *dr = dr_n_.data();
  Report agreed;
  // 003 eqs 111-119 as FluidSystem::integrate takes them: the predicted state (from
  // the rates at x^k), its tables and accelerations with the wall switch of v_hat^k,
  // the corrected state
  vh0_.resize(nd);
  dr0_.resize(n);
  a2_.resize(nd);
  yp_.resize(ys_.size());
  kinematics(v, rho, vh0_.data(), dr0_.data());
  double *xp = yp_.data(), *vp = xp + nd, *rp = vp + nd;
  for (int32_t k : owned_) {
    for (int c = 0; c < D; ++c) {
      xp[k * D + c] = x[k * D + c] + 0.5 * dt * vh0_[k * D + c];
      vp[k * D + c] = v[k * D + c] + 0.5 * dt * rate[k * D + c];
    }
    rp[k] = rho[k] + 0.5 * dt * dr0_[k];
  }
  sync(xp, D, vp, D, rp, 1);
  // (the switch velocities too: a row the predicted state needs may have been dropped
  // at x^k, its v_hat^k left incomplete here)
  sync(vh0_.data(), D);
  double pvals[2] = {INFINITY, INFINITY};
  const Report pred = guarded([&] {
    struct Reset {  // also when accel throws
      const double *&p;
      ~Reset() { p = nullptr; }
    } reset{wall_switch_v_};
    wall_switch_v_ = vh0_.data();
    return prepare_accel(yp_.data(), false, a2_.data(), pvals[0], pvals[1]);
  });
  agreed = agree_min(pred, pvals, 2);
  if (!agreed.ok()) {
    agreed.message = "step " + std::to_string(step) + ": " + agreed.message;
    return agreed;
  }
  for (int32_t k : owned_)
    for (int c = 0; c < D; ++c) vn[k * D + c] = v[k * D + c] + 0.5 * dt * a2_[k * D + c];  // v^C
  sync(vn, D);
  kinematics(vn, rp, vh_n_.data(), dr_n_.data());
  for (int32_t k : owned_) {
    rn[k] = rho[k] + 0.5 * dt * dr[k];                                                     // rho^C
    for (int c = 0; c < D; ++c) xn[k * D + c] = x[k * D + c] + 0.5 * dt * vh[k * D + c];  // x^C
    for (int c = 0; c < D; ++c) {                                                          // eqs 117-119
      xn[k * D + c] = 2.0 * xn[k * D + c] - x[k * D + c];
      vn[k * D + c] = 2.0 * vn[k * D + c] - v[k * D + c];
    }
    rn[k] = 2.0 * rn[k] - rho[k];
  }
  sync(xn, D, vn, D, rn, 1);
  return agreed;
}

// Leap-frog (003 Sect. 6.1) and the predictor-corrector as FluidSystem::integrate takes
// them, with the ghosts' states exchanged where their stages read them. Leap-frog:
// v^{k+1/2} before the kinematics, x and rho at the step's end, two all-gathers per
// step; the predictor-corrector: the predicted state and v_hat^k, v^C, the corrected
// state, three all-gathers.
Report FluidRanks::integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                             mfree_progress_fn progress, void *user, int64_t &nsteps) {
  nsteps = 0;
  // the arguments, checked and then agreed: ranks that took different steps would wait
  // for each other in the exchanges
  const Report args = coll_.local([&] {
    if (scheme != MFREE_INTEGRATOR_LEAPFROG && scheme != MFREE_INTEGRATOR_PREDICTOR_CORRECTOR)
      throw Error(MFREE_ERR_ARG, "unknown integrator");
    if (!(std::isfinite(t_end) && std::isfinite(t))) throw Error(MFREE_ERR_ARG, "times must be finite");
    if (!(std::isfinite(cfl) && cfl <= 1.0)) throw Error(MFREE_ERR_ARG, "cfl must be finite and <= 1");
    if (!(std::isfinite(dt_max) && dt_max >= 0.0)) throw Error(MFREE_ERR_ARG, "dt_max must be finite and >= 0");
    if (cfl <= 0.0 && dt_max <= 0.0) throw Error(MFREE_ERR_ARG, "give a CFL number or a fixed step dt_max");
    check_ready();
    return Report();
  });
  {
    // (and the acoustic step's setting: its power iteration exchanges and gathers)
    constexpr int V = 7;
    const double v[V] = {static_cast<double>(args.status), t, t_end, cfl, dt_max, acoustic_step_ ? 1.0 : 0.0,
                         open_ ? 1.0 : 0.0};
    const int np = coll_.size();
    std::vector<double> all(static_cast<size_t>(np) * V);
    coll_.allgather(v, V, all.data(), static_cast<int64_t>(all.size()));
    std::vector<double> st(np);
    for (int p = 0; p < np; ++p) st[p] = all[V * static_cast<size_t>(p)];
    const Report agreed = coll_.agree_from(st, args);
    if (!agreed.ok()) throw Error(agreed.status, agreed.message);
    static const char *names[V] = {"", "t", "t_end", "cfl", "dt_max", "the acoustic step", "open boundaries"};
    for (int p = 1; p < np; ++p)
      for (int k = 1; k < V; ++k)
        if (!(all[V * static_cast<size_t>(p) + k] == all[k])) {
          std::ostringstream s;
          s.precision(17);
          s << "ranks disagree on " << names[k] << ": rank 0 " << (k < 5 ? "passes " : "sets ") << all[k] << ", rank "
            << p << (k < 5 ? " passes " : " sets ") << all[V * static_cast<size_t>(p) + k] << " (every rank must "
            << (k < 5 ? "pass" : "set") << " the same)";
          throw Error(MFREE_ERR_ARG, s.str());
        }
  }
  check_usable();
  if (open_) return open_windows(scheme, y, t, t_end, cfl, dt_max, progress, user, nsteps);
  const int D = dim();
  // node arrays for the current nodes (again after a rebuild of the ghosts)
  auto seat = [&] {
    load(y);
    yn_.resize(ys_.size());
    rate_n_.resize(static_cast<size_t>(D) * size());
    vh_n_.resize(static_cast<size_t>(D) * size());
    dr_n_.resize(size());
  };
  seat();
  auto failed = [&](Report r, int64_t step) {
    r.message = "step " + std::to_string(step) + ": " + r.message;
    return r;
  };
  bool rebuilt = false;
  while (t < t_end) {
    const int32_t n = size();
    const size_t nd = static_cast<size_t>(D) * n;
    double vals[2] = {INFINITY, INFINITY};
    const Report mine = guarded([&] { return prepare_accel(ys_.data(), nsteps > 0, rate_n_.data(), vals[0], vals[1]); });
    Report agreed = agree_min(mine, vals, 2);
    if (!agreed.ok()) return failed(agreed, nsteps);
    if (-vals[1] > width_ && rebuild_ && !rebuilt) {
      // y holds the step's starting state of the owned particles
      rebuild_halo(y);
      seat();
      rebuilt = true;
      continue;
    }
    rebuilt = false;
    check_reach(vals[1], nsteps + 1);
    double dt = 0.0;
    agreed = step_size(vals[0], cfl, dt_max, t, t_end, nsteps, nullptr, dt, acoustic_cap(ys_.data()));
    if (!agreed.ok()) return agreed;
    const double *x = ys_.data(), *v = x + nd, *rho = v + nd;
    double *xn = yn_.data(), *vn = xn + nd, *rn = vn + nd;
    const double *rate = rate_n_.data(), *vh = vh_n_.data(), *dr = dr_n_.data();
    if (scheme == MFREE_INTEGRATOR_LEAPFROG) {
      for (int32_t k : owned_)
        for (int c = 0; c < D; ++c) vn[k * D + c] = v[k * D + c] + dt * rate[k * D + c];
      sync(vn, D);
      kinematics(vn, rho, vh_n_.data(), dr_n_.data());
      for (int32_t k : owned_) {
        for (int c = 0; c < D; ++c) xn[k * D + c] = x[k * D + c] + dt * vh[k * D + c];
        rn[k] = rho[k] + dt * dr[k];
      }
      sync(xn, D, rn, 1);
    } else {
      const Report pred = corrected_state(dt, nsteps + 1);
      if (!pred.ok()) return pred;
    }
    const Report bad = guarded([&] { return named(check_state(yn_.data(), nsteps + 1)); });
    agreed = agree_min(bad, nullptr, 0);
    if (!agreed.ok()) return agreed;  // y keeps the last good state
    ys_.swap(yn_);
    const double t_next = (t_end - t <= dt) ? t_end : t + dt;
    if (place_) place_(t_next, n, gid_.data(), ys_.data());
    const size_t no = static_cast<size_t>(D) * n_own_;
    for (int32_t p = 0; p < n_own_; ++p) {
      const size_t k = owned_[p];
      for (int c = 0; c < D; ++c) {
        y[p * D + c] = ys_[k * D + c];
        y[no + p * D + c] = ys_[nd + k * D + c];
      }
      y[2 * no + p] = ys_[2 * nd + k];
    }
    t = t_next;
    ++nsteps;
    if (progress && progress(user, nsteps, t, dt)) break;
  }
  return Report();
}

// ---- Outputs on ranks: the owned particles' values, or totals agreed by every rank ----

Report FluidRanks::output_prepare(const double *y, double *a, mfree_status_t refuse, const char *why, double *want,
                                  int nwant) {
  // (a rank without a state still takes part in the exchange and the agreement)
  check_usable();
  // (a second pass on the ghosts the host rebuilt when the layer was too shallow: only a
  // rank without owned particles can be without a state then)
  for (int pass = 0;; ++pass) {
    if (a && pass > 0) {  // (a is rate_n_, wall_force's: sized again for the new nodes)
      rate_n_.resize(static_cast<size_t>(dim()) * size());
      a = rate_n_.data();
    }
    if (!y) stand_in_.assign(static_cast<size_t>(neq()) + 1, 1.0);
    load(y ? y : stand_in_.data());
    double vals[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
    for (int k = 0; k < nwant; ++k) vals[2 + k] = want[k];
    const Report mine = coll_.local([&] {
      if (refuse != MFREE_SUCCESS) throw Error(refuse, why);
      check_ready();
      return a ? prepare_accel(ys_.data(), false, a, vals[0], vals[1])
               : prepare_rows(ys_.data(), false, vals[0], vals[1]);
    });
    const Report agreed = agree_min(mine, vals, 2 + nwant);
    if (agreed.ok() && -vals[1] > width_ && rebuild_ && pass == 0) {
      rebuild_halo(y);
      continue;
    }
    for (int k = 0; k < nwant; ++k) want[k] = vals[2 + k];
    if (agreed.ok()) check_reach(vals[1], 0);
    return agreed;
  }
}

// The velocity block on the owned rows: the lumped masses (003 eq 56) of the owned
// particles sum the terms of every row that holds them, the owned rows' and the kept
// ghost rows' (rows_done), sorted by value as on one process: bitwise the one-process
// fluid's. The consistent mass couples owned particles to ghosts, which the rank's
// state does not hold: its products are apply_mass's (fluid_ranks_matrices.cpp).
Report FluidRanks::mass(const double *y, bool consistent, SparseMatrix &M) {
  if (open_) return open_mass_ranks(y, consistent, M);
  const Report agreed = output_prepare(
      y, nullptr, consistent ? MFREE_ERR_UNSUPPORTED : MFREE_SUCCESS,
      "no consistent mass matrix for the fluid on ranks (its rows couple owned particles to ghosts): "
      "use its products (mfree_system_apply_mass) or the lumped mass");
  if (!agreed.ok()) return agreed;
  lumped_rows(M);
  return agreed;
}

void FluidRanks::lumped_rows(SparseMatrix &M) const {
  std::vector<int32_t> part(size(), -1);
  for (int32_t p = 0; p < n_own_; ++p) part[owned_[p]] = p;
  mass_matrix(n_own_, owned_.data(), part.data(), false, M);
}

// Local: the owned particles' densities and rest densities.
void FluidRanks::pressure(const double *y, double *p) const {
  const double *rho = y + 2 * static_cast<size_t>(dim()) * n_own_;
  for (int32_t i = 0; i < n_own_; ++i)
    p[i] = item_state(i) == kDormant ? 0.0 : pressure_at(rho[i], rho0_[owned_[i]]);
}

Report FluidRanks::velocity(const double *y, double *vhat) {
  if (open_) return open_velocity_ranks(y, vhat);
  const Report agreed = output_prepare(y, nullptr, MFREE_SUCCESS, "");
  if (!agreed.ok()) return agreed;
  const int D = dim();
  const size_t nd = static_cast<size_t>(D) * size();
  vh_n_.resize(nd);
  kinematics(ys_.data() + nd, ys_.data() + 2 * nd, vh_n_.data(), nullptr);
  for (int32_t p = 0; p < n_own_; ++p)
    for (int c = 0; c < D; ++c) vhat[p * D + c] = vh_n_[static_cast<size_t>(owned_[p]) * D + c];
  return agreed;
}

// The total: sum_i m_i a_i - M g over every rank's owned particles (FluidSystem::
// wall_force), each sum exact (every rank's accumulator all-gathered and added as
// integers), so that every rank gets the same bits, whatever the partition; per_wall:
// wall_shares.
Report FluidRanks::wall_force(const double *y, double *total, int32_t nwall, double *per_wall) {
  if (open_) return open_wall_force_ranks(y, total, nwall, per_wall);
  const int D = dim();
  const size_t nd = static_cast<size_t>(D) * size();
  rate_n_.resize(nd);
  const int32_t nw = walls_ ? walls_->size() : 0;
  mfree_status_t refuse = MFREE_SUCCESS;
  std::string why;
  if (per_wall && nwall != nw) {
    refuse = MFREE_ERR_ARG;
    why = "per_wall holds " + std::to_string(nwall) + " wall particles, the system has " + std::to_string(nw);
  }
  // which outputs any rank asks for: every rank takes part in their collectives
  double want[2] = {total ? 0.0 : 1.0, per_wall ? 0.0 : 1.0};
  const Report agreed = output_prepare(y, rate_n_.data(), refuse, why.c_str(), want, 2);
  if (!agreed.ok()) return agreed;
  const int A = 2 * D + 2;  // acc_ per node: force, mass sum, lumped mass, wall force
  const bool galerkin = lump_ == MFREE_LUMP_GALERKIN;
  std::vector<double> unused;
  if (want[1] == 0.0) {
    if (!per_wall) unused.resize(static_cast<size_t>(nw) * D + 1);
    wall_shares(galerkin, per_wall ? per_wall : unused.data());
  }
  if (want[0] != 0.0) return agreed;
  double none[3];
  if (!total) total = none;
  std::vector<ExactSum> sums(D + 1);
  for (int32_t k : owned_) {
    const double m = galerkin ? acc_[static_cast<size_t>(k) * A + D + 1] : mass_[k];
    for (int c = 0; c < D; ++c) sums[c].add(m * rate_n_[static_cast<size_t>(k) * D + c]);
    sums[D].add(mass_[k]);
  }
  double f[4] = {0, 0, 0, 0};
  coll_.exact_totals(sums.data(), D + 1, f);
  for (int c = 0; c < D; ++c) total[c] = f[c] - f[D] * g_[c];
  return agreed;
}

// Each wall particle's force sums the terms of the rows near it in node order on one
// rank (FluidSystem::wall_force): every rank gathers the terms of its owned rows with
// the wall and the row's global id, and every rank sums them all in the order of (wall,
// global id). The rows' masses m_k read the lumped masses of ghosts, which only their
// owners have complete.
void FluidRanks::wall_shares(bool galerkin, double *per_wall) {
  const int D = dim();
  const int A = 2 * D + 2;
  const int32_t n = size(), nw = walls_ ? walls_->size() : 0;
  std::vector<double> m(n);
  for (int32_t k = 0; k < n; ++k) m[k] = galerkin ? acc_[static_cast<size_t>(k) * A + D + 1] : mass_[k];
  sync(m.data(), 1);
  const double *vn = node_velocities(ys_.data() + static_cast<size_t>(D) * n);
  std::vector<double> rec;  // (wall, row's global id, m_k f2) per term
  std::vector<std::pair<int32_t, double>> terms;
  for (int32_t k = 0; k < n && nw > 0; ++k) {
    if (!is_owned_[k]) continue;
    wall_row(k, vn, m.data(), terms);
    for (const auto &e : terms) rec.insert(rec.end(), {static_cast<double>(e.first), Collective::pack(gid_[k]), e.second});
  }
  const std::vector<double> all = coll_.allgather(rec.data(), static_cast<int64_t>(rec.size()));
  std::vector<size_t> order(all.size() / 3);
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (all[3 * a] != all[3 * b]) return all[3 * a] < all[3 * b];
    return Collective::unpack(all[3 * a + 1]) < Collective::unpack(all[3 * b + 1]);
  });
  std::fill(per_wall, per_wall + static_cast<size_t>(nw) * D, 0.0);
  for (size_t t : order) {
    const size_t w = static_cast<size_t>(all[3 * t]);
    for (int c = 0; c < D; ++c) per_wall[w * D + c] += all[3 * t + 2] * wall_n_[w * D + c];
  }
}

}  // namespace mfree
