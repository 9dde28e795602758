// Open boundaries of the fluid on ranks (fluid_inflow.hpp): the one-process fluid's active
// set, inflow gates and outflow planes, bitwise that fluid's whatever the partition.
//
// The capacity is every rank's items, numbered by global id 0 .. N - 1: a particle's
// global id is its index in the one-process capacity. The bookkeeping (each particle's
// state, the gates' rows, the counters) is kept per global id on every rank, and every
// decision is a function of it and of the particles that crossed an outflow plane, which
// every rank gathers and takes in global-id order: the new rows take the lowest dormant
// ids, as on one process, so injected particles get the same ids on any number of ranks,
// and the totals sum in the same order. A dormant particle stays an item of its owner
// (the state keeps its length between migrations, as one process keeps y's) but is no
// node: the evaluations run on an inner FluidRanks of the active items, whose callbacks
// relay to this system's host (an exchange expands its items into the host's, a rebuild
// sets the host's halo up around every owned item). The inner system is built again,
// on a halo rebuilt around the current positions, whenever the active set changes.
#include <algorithm>
#include <cmath>
#include <string>

#include "core/systems/fluid_ranks.hpp"

namespace mfree {

int8_t FluidRanks::item_state(int32_t p) const {
  if (!open_) return kFluid;
  const int64_t g = gid_[node_[p]];
  const FluidOpen &o = *open_;
  if (o.global) return o.state[static_cast<size_t>(g)];
  return o.pending_active < 0 || g < o.pending_active ? kFluid : kDormant;
}

int32_t FluidRanks::active_states(int32_t n, int32_t *state) const {
  if (state && n != n_own_)
    throw Error(MFREE_ERR_ARG, "state holds " + std::to_string(n) + " values, the rank owns " + std::to_string(n_own_) +
                                   " particles");
  int32_t na = 0;
  for (int32_t p = 0; p < n_own_; ++p) {
    const int8_t s = item_state(p);
    if (state) state[p] = s;
    na += s != kDormant;
  }
  return na;
}

void FluidRanks::open_init() {
  FluidOpen &o = *open_;
  if (o.global) return;
  // every rank's owned ids: the capacity, numbered 0 .. N - 1
  std::vector<double> mine(static_cast<size_t>(n_own_) + 1);
  for (int32_t p = 0; p < n_own_; ++p) mine[p] = Collective::pack(gid_[owned_[p]]);
  const std::vector<double> all = coll_.allgather(mine.data(), n_own_);
  const int64_t N = static_cast<int64_t>(all.size());
  std::vector<char> seen(static_cast<size_t>(N), 0);
  for (double v : all) {
    const int64_t g = Collective::unpack(v);
    if (g < 0 || g >= N || seen[static_cast<size_t>(g)])
      throw Error(MFREE_ERR_INPUT, "open boundaries on ranks need the global ids 0 .. " + std::to_string(N - 1) +
                                       ", each owned by one rank (the capacity of every rank's items); id " +
                                       std::to_string(g) + " is not");
    seen[static_cast<size_t>(g)] = 1;
  }
  // every rank's settings: the same decisions need the same gates, planes and count
  std::vector<double> set = {static_cast<double>(o.pending_active), rebuild_ ? 1.0 : 0.0,
                             static_cast<double>(o.gates.size()), static_cast<double>(o.outflows.size())};
  for (const InflowGate &g : o.gates) {
    set.insert(set.end(), g.o, g.o + 3);
    set.insert(set.end(), g.e[0], g.e[0] + 3);
    set.insert(set.end(), g.e[1], g.e[1] + 3);
    set.insert(set.end(), g.nrm, g.nrm + 3);
    set.insert(set.end(), {g.U, g.rho, g.d});
  }
  for (const OutflowPlane &p : o.outflows) {
    set.insert(set.end(), p.p, p.p + 3);
    set.insert(set.end(), p.nrm, p.nrm + 3);
  }
  const double len = static_cast<double>(set.size());
  const std::vector<double> lens = coll_.allgather(&len, 1);
  const std::vector<double> sets = coll_.allgather(set.data(), static_cast<int64_t>(set.size()));
  for (size_t p = 0, at = 0; p < lens.size(); at += static_cast<size_t>(lens[p]), ++p)
    if (lens[p] != len || !std::equal(set.begin(), set.end(), sets.begin() + static_cast<std::ptrdiff_t>(at)))
      throw Error(MFREE_ERR_ARG, "ranks disagree on the open boundaries: rank " + std::to_string(p) +
                                     " sets another active count, gates or outflow planes (every rank must set the "
                                     "same)");
  if (!rebuild_)
    throw Error(MFREE_ERR_STATE, "open boundaries on ranks need a halo rebuild callback "
                                 "(mfree_system_set_halo_rebuild): injected particles appear away from their owners' "
                                 "ghosts");
  if (o.pending_active > N)
    throw Error(MFREE_ERR_ARG, "active count " + std::to_string(o.pending_active) + " outside [0, " +
                                   std::to_string(N) + "]");
  o.state.assign(static_cast<size_t>(N), kFluid);
  if (o.pending_active >= 0)
    for (int64_t g = o.pending_active; g < N; ++g) o.state[static_cast<size_t>(g)] = kDormant;
  o.gate_of.assign(static_cast<size_t>(N), -1);
  o.row_of.assign(static_cast<size_t>(N), 0);
  o.base.assign(static_cast<size_t>(N) * dim(), 0.0);
  o.index_active();
  o.global = true;
}

Report FluidRanks::update_open(double t, double *y) {
  const Report args = coll_.local([&] {
    if (!std::isfinite(t)) throw Error(MFREE_ERR_ARG, "time must be finite");
    if (!y && n_own_ > 0) throw Error(MFREE_ERR_NULL, "y is NULL");
    check_usable();
    check_ready();
    return Report();
  });
  const Report agreed = coll_.agree(args);
  if (!agreed.ok()) throw Error(agreed.status, agreed.message);
  FluidOpen &o = open();
  open_init();
  const int D = dim();
  const size_t no = static_cast<size_t>(D) * n_own_;
  // the owned fluid particles past a plane, every rank's in global-id order
  std::vector<double> mine;
  for (int32_t p = 0; p < n_own_; ++p) {
    const int64_t g = gid_[owned_[p]];
    if (o.state[static_cast<size_t>(g)] != kFluid) continue;
    const int32_t k = crossed_plane(y + static_cast<size_t>(p) * D);
    if (k >= 0) mine.insert(mine.end(), {Collective::pack(g), static_cast<double>(k), mass_[owned_[p]]});
  }
  const std::vector<double> all = coll_.allgather(mine.data(), static_cast<int64_t>(mine.size()));
  std::vector<OutflowCrossing> out(all.size() / 3);
  for (size_t q = 0; q < out.size(); ++q)
    out[q] = {static_cast<int32_t>(Collective::unpack(all[3 * q])), static_cast<int32_t>(all[3 * q + 1]),
              all[3 * q + 2]};
  std::sort(out.begin(), out.end(), [](const OutflowCrossing &a, const OutflowCrossing &b) { return a.i < b.i; });
  std::vector<std::pair<int32_t, int32_t>> fresh;
  const Report rep = open_plan(t, out, fresh);  // the same outcome on every rank
  if (!rep.ok()) return rep;
  if (!fresh.empty()) {  // the injected particles' rest density and mass, at every item
    std::vector<int32_t> gate(o.state.size(), -1);
    for (const auto &q : fresh) gate[q.first] = q.second;
    for (int32_t k = 0; k < size(); ++k) {
      const int32_t g = gate[static_cast<size_t>(gid_[k])];
      if (g < 0) continue;
      rho0_[k] = o.gates[g].rho;
      mass_[k] = o.gates[g].mass_each;
    }
  }
  for (int32_t p = 0; p < n_own_; ++p) {
    const int64_t g = gid_[owned_[p]];
    if (o.state[static_cast<size_t>(g)] == kInflow)
      buffer_state(static_cast<int32_t>(g), t, y + static_cast<size_t>(p) * D, y + no + static_cast<size_t>(p) * D,
                   y + 2 * no + p);
  }
  return Report();
}

void FluidRanks::open_items() {
  link_.outer = this;
  link_.item.clear();
  link_.ids.clear();
  for (int pass = 0; pass < 2; ++pass)
    for (int32_t p = pass ? n_own_ : 0; p < (pass ? size() : n_own_); ++p)
      if (item_state(p) != kDormant) {
        link_.item.push_back(p);
        link_.ids.push_back(gid_[node_[p]]);
      }
  link_.n_own = 0;
  while (link_.n_own < static_cast<int32_t>(link_.item.size()) && link_.item[link_.n_own] < n_own_) ++link_.n_own;
}

FluidRanks &FluidRanks::open_ranks_inner(const double *y) {
  FluidOpen &o = *open_;
  if (o.inner && !o.dirty) return static_cast<FluidRanks &>(*o.inner);
  const int D = dim();
  // the halo around the current positions: injected particles were dormant elsewhere
  rebuild_halo(y);
  open_items();
  link_.xo.assign(y, y + static_cast<size_t>(D) * n_own_);
  link_.xo.push_back(0.0);  // (one more: a rank without owned particles)
  const int32_t na = static_cast<int32_t>(link_.item.size());
  std::unique_ptr<FluidRanks> in = create(D, link_.n_own, na - link_.n_own, link_.ids.data(), width_,
                                          Collective(&open_exchange, &open_allgather, &link_));
  std::vector<double> r0(static_cast<size_t>(na) + 1), m(static_cast<size_t>(na) + 1);
  for (int32_t q = 0; q < na; ++q) {
    r0[q] = rho0_[node_[link_.item[q]]];
    m[q] = mass_[node_[link_.item[q]]];
  }
  open_options(*in, r0.data(), m.data());
  in->set_rebuild(&open_rebuild);
  in->place_ = [this](double t, int32_t n, const int64_t *gid, double *ys) {
    const FluidOpen &op = *open_;
    const int Dm = dim();
    const size_t nd = static_cast<size_t>(Dm) * n;
    for (int32_t k = 0; k < n; ++k) {
      const size_t at = static_cast<size_t>(k) * Dm;
      if (op.state[static_cast<size_t>(gid[k])] == kInflow)
        buffer_state(static_cast<int32_t>(gid[k]), t, ys + at, ys + nd + at, ys + 2 * nd + k);
    }
  };
  o.inner = std::move(in);
  o.dirty = false;
  return static_cast<FluidRanks &>(*o.inner);
}

void FluidRanks::open_ranks_gather(const double *y, std::vector<double> &yc) const {
  const int D = dim();
  const size_t na = static_cast<size_t>(link_.n_own), no = static_cast<size_t>(D) * n_own_;
  yc.assign((2 * D + 1) * na + 1, 0.0);
  for (size_t q = 0; q < na; ++q) {
    const size_t p = static_cast<size_t>(link_.item[q]);
    for (int c = 0; c < D; ++c) {
      yc[q * D + c] = y[p * D + c];
      yc[na * D + q * D + c] = y[no + p * D + c];
    }
    yc[2 * na * D + q] = y[2 * no + p];
  }
}

void FluidRanks::open_ranks_scatter(const double *yc, double *y) const {
  const int D = dim();
  const size_t na = static_cast<size_t>(link_.n_own), no = static_cast<size_t>(D) * n_own_;
  for (size_t q = 0; q < na; ++q) {
    const size_t p = static_cast<size_t>(link_.item[q]);
    for (int c = 0; c < D; ++c) {
      y[p * D + c] = yc[q * D + c];
      y[no + p * D + c] = yc[na * D + q * D + c];
    }
    y[2 * no + p] = yc[2 * na * D + q];
  }
}

// ---- The inner system's callbacks: relayed to this system's host ----

mfree_status_t FluidRanks::open_exchange(void *u, int32_t ncomp, double *field, int64_t ld) {
  OpenLink &L = *static_cast<OpenLink *>(u);
  const FluidRanks &s = *L.outer;
  const size_t w = static_cast<size_t>(ld), nc = static_cast<size_t>(ncomp);
  L.buf.assign(static_cast<size_t>(s.size()) * w + 1, 0.0);
  for (size_t q = 0; q < static_cast<size_t>(L.n_own); ++q)
    std::copy_n(field + q * w, nc, &L.buf[static_cast<size_t>(L.item[q]) * w]);
  try {
    s.coll_.exchange(ncomp, L.buf.data(), ld);
  } catch (const Error &e) {
    return e.status();
  }
  for (size_t q = static_cast<size_t>(L.n_own); q < L.item.size(); ++q)
    std::copy_n(&L.buf[static_cast<size_t>(L.item[q]) * w], nc, field + q * w);
  return MFREE_SUCCESS;
}

mfree_status_t FluidRanks::open_allgather(void *u, const double *in, int64_t n, double *out, int64_t cap,
                                          int64_t *total) {
  const Collective &c = static_cast<OpenLink *>(u)->outer->coll_;
  return c.allgather_fn()(c.user(), in, n, out, cap, total);
}

mfree_status_t FluidRanks::open_rebuild(void *u, int32_t n_owned, const double *x, int64_t ld, const int64_t *ids,
                                        double width, int32_t *n_ghost, const int64_t **all_ids) {
  (void)ids, (void)width;
  OpenLink &L = *static_cast<OpenLink *>(u);
  FluidRanks &s = *L.outer;
  const int D = s.dim();
  try {
    for (int32_t q = 0; q < n_owned; ++q)
      std::copy_n(x + static_cast<size_t>(q) * ld, D, &L.xo[static_cast<size_t>(L.item[q]) * D]);
    s.rebuild_halo(L.xo.data());  // the host's halo around every owned item
    s.open_items();
  } catch (const Error &e) {
    return e.status();
  }
  *n_ghost = static_cast<int32_t>(L.item.size()) - L.n_own;
  *all_ids = L.ids.data();
  return MFREE_SUCCESS;
}

int32_t FluidRanks::open_progress_ranks(void *u, int64_t step, double t, double dt) {
  auto &p = *static_cast<OpenProgress *>(u);
  const auto &s = static_cast<const FluidRanks &>(*p.sys);
  const FluidOpen &o = *s.open_;
  if (p.fn && p.fn(p.user, p.base + step, t, dt)) p.user_stop = true;
  if (o.outflows.empty()) return p.user_stop;
  // a fluid particle past a plane on any rank stops every rank at this step
  double crossed = 0.0;
  for (int32_t q = 0; q < s.link_.n_own && crossed == 0.0; ++q)
    if (o.state[static_cast<size_t>(s.link_.ids[q])] == kFluid &&
        s.crossed_plane(p.yc + static_cast<size_t>(q) * s.dim()) >= 0)
      crossed = 1.0;
  for (double c : s.coll_.allgather(&crossed, 1)) crossed = std::max(crossed, c);
  return p.user_stop || crossed != 0.0;
}

FluidSystem &FluidRanks::open_stage(const double *y) {
  FluidRanks &in = open_ranks_inner(y);
  open_ranks_gather(y, open_->yc);
  return in;
}

Report FluidRanks::open_begin(const double *y, FluidRanks *&in) {
  // a fault pending on one rank, before the halo is rebuilt around its (stand-in) state
  const Report agreed = coll_.agree(coll_.local([] { return Report(); }));
  if (!agreed.ok()) return agreed;
  open();
  open_init();
  in = &static_cast<FluidRanks &>(open_stage(y));
  return agreed;
}

const InflowGate *FluidRanks::buffer_gate(int32_t p) const {
  const FluidOpen &o = *open_;
  const size_t g = static_cast<size_t>(gid_[owned_[p]]);
  return o.state[g] == kInflow ? &o.gates[o.gate_of[g]] : nullptr;
}

Report FluidRanks::open_rhs_ranks(const double *y, double *ydot) {
  FluidRanks *in = nullptr;
  const Report begun = open_begin(y, in);
  if (!begun.ok()) return begun;
  FluidOpen &o = *open_;
  const int D = dim();
  const size_t na = static_cast<size_t>(link_.n_own), no = static_cast<size_t>(D) * n_own_;
  o.rc.assign((2 * D + 1) * na + 1, 0.0);
  const Report rep = o.active.empty() ? Report() : in->rhs(0.0, o.yc.data(), o.rc.data());
  std::fill(ydot, ydot + static_cast<size_t>(neq()), 0.0);  // dormant: zero rates
  open_ranks_scatter(o.rc.data(), ydot);
  for (int32_t p = 0; p < n_own_; ++p) {  // buffers: imposed motion
    const InflowGate *gate = buffer_gate(p);
    if (!gate) continue;
    for (int c = 0; c < D; ++c) {
      ydot[static_cast<size_t>(p) * D + c] = gate->U * gate->nrm[c];
      ydot[no + static_cast<size_t>(p) * D + c] = 0.0;
    }
    ydot[2 * no + p] = 0.0;
  }
  return rep;
}

Report FluidRanks::open_velocity_ranks(const double *y, double *vhat) {
  FluidRanks *in = nullptr;
  const Report begun = open_begin(y, in);
  if (!begun.ok()) return begun;
  FluidOpen &o = *open_;
  const int D = dim();
  const size_t na = static_cast<size_t>(link_.n_own);
  o.rc.assign(D * na + 1, 0.0);
  const Report rep = o.active.empty() ? Report() : in->velocity(o.yc.data(), o.rc.data());
  std::fill(vhat, vhat + static_cast<size_t>(D) * n_own_, 0.0);  // dormant: zero
  for (size_t q = 0; q < na; ++q)
    std::copy_n(&o.rc[q * D], D, vhat + static_cast<size_t>(link_.item[q]) * D);
  for (int32_t p = 0; p < n_own_; ++p) {  // buffers: imposed
    const InflowGate *gate = buffer_gate(p);
    if (gate)
      for (int c = 0; c < D; ++c) vhat[static_cast<size_t>(p) * D + c] = gate->U * gate->nrm[c];
  }
  return rep;
}

Report FluidRanks::open_mass_ranks(const double *y, bool consistent, SparseMatrix &M) {
  FluidRanks *in = nullptr;
  const Report begun = open_begin(y, in);
  if (!begun.ok()) return begun;
  SparseMatrix Mc;
  const Report rep = open_->active.empty() ? Report() : in->mass(open_->yc.data(), consistent, Mc);
  if (rep.ok()) open_expand(Mc, link_.item.data(), static_cast<size_t>(link_.n_own), n_own_, M);
  return rep;
}

// M v as the one-process fluid's expanded matrix applies it: the inner fluid's product at
// the active particles' unknowns, v itself at the dormant ones (identity rows).
Report FluidRanks::open_apply_mass_ranks(const double *y, bool consistent, const double *v, double *Mv) {
  FluidRanks *in = nullptr;
  const Report begun = open_begin(y, in);
  if (!begun.ok()) return begun;
  FluidOpen &o = *open_;
  open_ranks_gather(v, o.vc);
  o.rc.assign(o.vc.size(), 0.0);
  const Report rep = o.active.empty() ? Report() : in->apply_mass(o.yc.data(), consistent, o.vc.data(), o.rc.data());
  std::copy_n(v, neq(), Mv);
  open_ranks_scatter(o.rc.data(), Mv);
  return rep;
}

// The owned rows over the host's items: the inner fluid's rows at the active owned items,
// its columns (its items) at theirs; identity rows at the dormant owned items.
Report FluidRanks::open_interpolation_ranks(const double *y, SparseMatrix &S) {
  FluidRanks *in = nullptr;
  const Report begun = open_begin(y, in);
  if (!begun.ok()) return begun;
  SparseMatrix Sc;
  const Report rep = open_->active.empty() ? Report() : in->interpolation(open_->yc.data(), Sc);
  if (!rep.ok()) return rep;
  if (open_->active.empty()) Sc.set_pattern(0, 0, std::vector<int64_t>(1, 0), {});
  expand(Sc, link_.item, n_own_, size(), S);
  return rep;
}

Report FluidRanks::open_wall_force_ranks(const double *y, double *total, int32_t nwall, double *per_wall) {
  FluidRanks *in = nullptr;
  const Report begun = open_begin(y, in);
  return begun.ok() ? in->wall_force(open_->yc.data(), total, nwall, per_wall) : begun;
}

}  // namespace mfree
