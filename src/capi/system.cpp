#include <cstring>
#include <string>
#include <vector>

#include "core/systems/elastodynamics.hpp"
#include "core/systems/fluid.hpp"
#include "core/systems/fluid_ranks.hpp"
#include "handles.hpp"

struct mfree_system {
  std::atomic<int> refs{1};
  mfree_context_t *ctx = nullptr;
  mfree_assembler_t *as = nullptr;       // retained by elastodynamic systems
  mfree_assembler_t *mass_as = nullptr;  // retained by Galerkin elastodynamic systems
  std::unique_ptr<mfree::System> sys;
  // The fault the host made pending (mfree_system_set_pending_error): the next call that
  // is collective on ranks returns it
  mfree::Report pending;
  mfree::System &core() { return *sys; }
  const mfree::System &core() const { return *sys; }
};

namespace {

// The concrete kind a kind-specific call needs, or MFREE_ERR_UNSUPPORTED.
template <class T>
T &kind(mfree::System &s, const char *what) {
  T *t = dynamic_cast<T *>(&s);
  if (!t) throw mfree::Error(MFREE_ERR_UNSUPPORTED, std::string("this system has no ") + what);
  return *t;
}
template <class T>
const T &kind(const mfree::System &s, const char *what) {
  const T *t = dynamic_cast<const T *>(&s);
  if (!t) throw mfree::Error(MFREE_ERR_UNSUPPORTED, std::string("this system has no ") + what);
  return *t;
}

// The arguments of a call that is collective for a system on ranks. A fault found here
// (a NULL array or output), or one the host made pending on the system before the call
// (mfree_system_set_pending_error), is thrown at once for a system in one process, as by
// any call; on ranks the call goes on with stand-in buffers and the fault pending on the
// system's collective operations, whose first agreement returns it on every rank, so
// that no rank waits in a collective for one that returned. A fault that no agreement
// took (the operation is local on ranks) is thrown when the call ends.
class CollectiveArgs {
 public:
  explicit CollectiveArgs(mfree_system_t *h) : coll_(h->core().collective()) {
    mfree::Report host;
    std::swap(host, h->pending);  // (taken: reported once)
    require(host.ok(), host.status, host.message.c_str());
  }
  explicit CollectiveArgs(const mfree::Collective *coll) : coll_(coll) {}
  CollectiveArgs(const CollectiveArgs &) = delete;
  CollectiveArgs &operator=(const CollectiveArgs &) = delete;
  ~CollectiveArgs() {
    if (coll_) coll_->set_pending(mfree::Report());
  }
  // A check: its fault (the first one) thrown, or pending on ranks.
  void require(bool ok, mfree_status_t st, const char *why) {
    if (ok || faulty()) return;
    if (!coll_) throw mfree::Error(st, why);
    fault_.fail(st, why);
    coll_->set_pending(fault_);
  }
  bool faulty() const { return !fault_.ok(); }
  // p, or after a fault a stand-in of n values (the faulty rank reads and writes none of
  // the host's arrays).
  template <class T>
  T *stand_in(T *p, int64_t n) {
    if (!faulty()) return p;
    stand_ins_.emplace_back(static_cast<size_t>(n > 0 ? n : 0) + 1, 0.0);
    return stand_ins_.back().data();
  }
  // The call's outcome, or the fault no agreement took.
  mfree_status_t done(mfree_status_t st) {
    mfree::Report f;
    if (coll_ && coll_->take_pending(f)) throw mfree::Error(f.status, f.message);
    return st;
  }

 private:
  const mfree::Collective *coll_;
  mfree::Report fault_;
  std::vector<std::vector<double>> stand_ins_;  // (moved on growth: their data stay put)
};

// Fill *M (created when NULL) at state y through a core routine that writes a
// SparseMatrix; a NULL M with a fault pending fills a stand-in.
template <class Fill>
mfree_status_t fill_matrix(mfree_system_t *s, const char *fn, const double *y, mfree_matrix_t **M, Fill &&fill) {
  return mfree::with_handle(s, fn, [&](mfree::System &f) {
    CollectiveArgs args(s);
    args.require(y || f.neq() == 0, MFREE_ERR_NULL, "y is NULL");
    args.require(M, MFREE_ERR_NULL, "output pointer is NULL");
    y = args.stand_in(y, f.neq());
    if (!M) {
      mfree::SparseMatrix scratch;
      return args.done(mfree::finish(s->ctx, fn, fill(f, y, scratch)));
    }
    mfree_matrix_t *m = *M;
    bool fresh = false;
    if (!m) {
      m = new mfree_matrix_t(s->ctx);
      mfree::retain(s->ctx);
      fresh = true;
    }
    mfree::Report rep;
    try {
      rep = fill(f, y, m->m);
      args.done(MFREE_SUCCESS);
    } catch (...) {
      if (fresh) mfree::release(m);
      throw;
    }
    if (!rep.ok() && fresh) {
      mfree::release(m);
      return mfree::finish(s->ctx, fn, rep);
    }
    *M = m;
    return mfree::finish(s->ctx, fn, rep);
  });
}

// The handle of a new elastodynamic system: it keeps its context and assembler alive.
mfree_system_t *elastic_handle(mfree_context_t *ctx, std::unique_ptr<mfree::ElasticSystem> impl,
                               mfree_assembler_t *as) {
  auto *s = new mfree_system_t();
  s->ctx = ctx;
  s->as = as;
  s->sys = std::move(impl);
  mfree::retain(ctx);
  as->refs.fetch_add(1, std::memory_order_relaxed);
  return s;
}

// The totals of an open boundary k (an inflow gate or an outflow line); either output
// may be NULL.
template <class Totals>
mfree_status_t open_boundary_totals(const mfree_system_t *sys, const char *fn, const char *what, Totals totals,
                                    int32_t k, int64_t *count, double *mass) {
  return mfree::with_handle(sys, fn, [&](const mfree::System &base) {
    const auto &f = kind<mfree::FluidSystem>(base, what);
    int64_t c = 0;
    double m = 0.0;
    (f.*totals)(k, c, m);
    if (count) *count = c;
    if (mass) *mass = m;
    return MFREE_SUCCESS;
  });
}
}  // namespace

extern "C" {

mfree_status_t mfree_system_create_fluid(mfree_context_t *ctx, int32_t dim, int32_t n, mfree_system_t **sys) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_system_create_fluid", [&]() {
    MFREE_REQUIRE(sys, MFREE_ERR_NULL, "output pointer is NULL");
    *sys = nullptr;
    MFREE_REQUIRE(n >= 0, MFREE_ERR_ARG, "particle count " + std::to_string(n) + " is negative");
    auto impl = std::make_unique<mfree::FluidSystem>(dim, n);
    auto *s = new mfree_system_t();
    s->ctx = ctx;
    s->sys = std::move(impl);
    mfree::retain(ctx);
    *sys = s;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_destroy(mfree_system_t **sys) {
  if (!sys || !*sys) return MFREE_SUCCESS;
  mfree_system_t *s = *sys;
  if (s->refs.fetch_sub(1, std::memory_order_acq_rel) == 1) {
    mfree_context_t *c = s->ctx;
    mfree_assembler_t *a = s->as, *ma = s->mass_as;
    delete s;
    mfree::release(a);
    mfree::release(ma);
    mfree::release(c);
  }
  *sys = nullptr;
  return MFREE_SUCCESS;
}

#define MFREE_SYS_SETTER(name, call)                                          \
  return mfree::with_handle(sys, name, [&](mfree::System &base) {             \
    auto &f = kind<mfree::FluidSystem>(base, "fluid parameters (not a fluid)"); \
    call;                                                                     \
    f.options_changed();                                                      \
    return MFREE_SUCCESS;                                                     \
  })

mfree_status_t mfree_system_set_fluid(mfree_system_t *sys, const double *rho0, int64_t stride, double kappa,
                                      double gamma, double mu) {
  MFREE_SYS_SETTER("mfree_system_set_fluid", f.set_fluid(rho0, stride, kappa, gamma, mu));
}
mfree_status_t mfree_system_set_masses(mfree_system_t *sys, const double *m, int64_t stride) {
  MFREE_SYS_SETTER("mfree_system_set_masses", f.set_masses(m, stride));
}
mfree_status_t mfree_system_set_smoothing(mfree_system_t *sys, double h) {
  MFREE_SYS_SETTER("mfree_system_set_smoothing", f.set_smoothing(h));
}
mfree_status_t mfree_system_set_gravity(mfree_system_t *sys, const double *g) {
  MFREE_SYS_SETTER("mfree_system_set_gravity", f.set_gravity(g));
}
mfree_status_t mfree_system_set_lumping(mfree_system_t *sys, mfree_lumping_t lump) {
  MFREE_SYS_SETTER("mfree_system_set_lumping", f.set_lumping(lump));
}
mfree_status_t mfree_system_set_walls(mfree_system_t *sys, int32_t nwall, const double *x, const double *normals,
                                      double r0, double strength) {
  MFREE_SYS_SETTER("mfree_system_set_walls", f.set_walls(nwall, x, normals, r0, strength));
}
mfree_status_t mfree_system_set_box(mfree_system_t *sys, const double *lo, const double *hi) {
  MFREE_SYS_SETTER("mfree_system_set_box", f.set_box(lo, hi));
}

mfree_status_t mfree_system_set_shepard_condition(mfree_system_t *sys, double max_cond) {
  MFREE_SYS_SETTER("mfree_system_set_shepard_condition", f.set_shepard_condition(max_cond));
}

mfree_status_t mfree_system_set_approximation(mfree_system_t *sys, mfree_method_t method, int32_t order,
                                              mfree_kernel_t kernel, double param) {
  MFREE_SYS_SETTER("mfree_system_set_approximation", f.set_approximation(method, order, kernel, param));
}

mfree_status_t mfree_system_set_dummy_particles(mfree_system_t *sys, int32_t n, const double *x,
                                               const double *volumes, int64_t stride) {
  MFREE_SYS_SETTER("mfree_system_set_dummy_particles", f.set_dummy_particles(n, x, volumes, stride));
}
mfree_status_t mfree_system_set_density_diffusion(mfree_system_t *sys, double delta) {
  MFREE_SYS_SETTER("mfree_system_set_density_diffusion", f.set_density_diffusion(delta));
}

mfree_status_t mfree_system_set_consistent_integration(mfree_system_t *sys, int32_t on) {
  MFREE_SYS_SETTER("mfree_system_set_consistent_integration", f.set_consistent_integration(on));
}
mfree_status_t mfree_system_set_velocity_smoothing(mfree_system_t *sys, double beta) {
  MFREE_SYS_SETTER("mfree_system_set_velocity_smoothing", f.set_velocity_smoothing(beta));
}
mfree_status_t mfree_system_set_lumped_mass_step(mfree_system_t *sys, int32_t on) {
  MFREE_SYS_SETTER("mfree_system_set_lumped_mass_step", f.set_lumped_mass_step(on));
}
mfree_status_t mfree_system_set_acoustic_step(mfree_system_t *sys, int32_t on) {
  MFREE_SYS_SETTER("mfree_system_set_acoustic_step", f.set_acoustic_step(on));
}

mfree_status_t mfree_system_get_size(const mfree_system_t *sys, int32_t *neq) {
  return mfree::with_handle(sys, "mfree_system_get_size", [&](const mfree::System &f) {
    MFREE_REQUIRE(neq, MFREE_ERR_NULL, "output pointer is NULL");
    *neq = f.neq();
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_rhs(mfree_system_t *sys, double t, const double *y, double *ydot) {
  return mfree::with_handle(sys, "mfree_system_rhs", [&](mfree::System &f) {
    CollectiveArgs args(sys);
    args.require((y && ydot) || f.neq() == 0, MFREE_ERR_NULL, "y or ydot is NULL");
    const mfree::Report rep = f.rhs(t, args.stand_in(y, f.neq()), args.stand_in(ydot, f.neq()));
    return args.done(mfree::finish(sys->ctx, "mfree_system_rhs", rep));
  });
}

mfree_status_t mfree_system_assemble_mass(mfree_system_t *sys, const double *y, int32_t consistent,
                                          mfree_matrix_t **M) {
  return fill_matrix(sys, "mfree_system_assemble_mass", y, M,
                     [&](mfree::System &f, const double *ys, mfree::SparseMatrix &m) {
                       return f.mass(ys, consistent != 0, m);
                     });
}

mfree_status_t mfree_system_assemble_interpolation(mfree_system_t *sys, const double *y, mfree_matrix_t **S) {
  return fill_matrix(sys, "mfree_system_assemble_interpolation", y, S,
                     [&](mfree::System &f, const double *ys, mfree::SparseMatrix &m) {
                       return kind<mfree::FluidSystem>(f, "interpolation matrix (not a fluid)").interpolation(ys, m);
                     });
}

mfree_status_t mfree_system_apply_mass(mfree_system_t *sys, const double *y, int32_t consistent, const double *v,
                                       double *Mv) {
  return mfree::with_handle(sys, "mfree_system_apply_mass", [&](mfree::System &f) {
    CollectiveArgs args(sys);
    args.require((y && v && Mv) || f.neq() == 0, MFREE_ERR_NULL, "y, v or Mv is NULL");
    const mfree::Report rep = f.apply_mass(args.stand_in(y, f.neq()), consistent != 0, args.stand_in(v, f.neq()),
                                           args.stand_in(Mv, f.neq()));
    return args.done(mfree::finish(sys->ctx, "mfree_system_apply_mass", rep));
  });
}

mfree_status_t mfree_system_get_pressure(const mfree_system_t *sys, const double *y, double *p) {
  return mfree::with_handle(sys, "mfree_system_get_pressure", [&](const mfree::System &base) {
    const auto &f = kind<mfree::FluidSystem>(base, "pressure (not a fluid)");
    MFREE_REQUIRE((y && p) || f.neq() == 0, MFREE_ERR_NULL, "y or p is NULL");
    f.pressure(y, p);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_get_velocity(mfree_system_t *sys, const double *y, double *vhat) {
  return mfree::with_handle(sys, "mfree_system_get_velocity", [&](mfree::System &base) {
    CollectiveArgs args(sys);
    auto &f = kind<mfree::FluidSystem>(base, "interpolated velocity (not a fluid)");
    args.require((y && vhat) || f.neq() == 0, MFREE_ERR_NULL, "y or vhat is NULL");
    const mfree::Report rep =
        f.velocity(args.stand_in(y, f.neq()), args.stand_in(vhat, static_cast<int64_t>(f.dim()) * f.size()));
    return args.done(mfree::finish(sys->ctx, "mfree_system_get_velocity", rep));
  });
}

mfree_status_t mfree_system_get_wall_force(mfree_system_t *sys, const double *y, double *total, int32_t nwall,
                                          double *per_wall) {
  return mfree::with_handle(sys, "mfree_system_get_wall_force", [&](mfree::System &base) {
    CollectiveArgs args(sys);
    auto &f = kind<mfree::FluidSystem>(base, "wall force (not a fluid)");
    args.require(total || per_wall, MFREE_ERR_NULL, "total and per_wall are both NULL");
    args.require(y || f.neq() == 0, MFREE_ERR_NULL, "y is NULL");
    const mfree::Report rep =
        f.wall_force(args.stand_in(y, f.neq()), args.stand_in(total, f.dim()), nwall,
                     args.stand_in(per_wall, static_cast<int64_t>(f.dim()) * nwall));
    return args.done(mfree::finish(sys->ctx, "mfree_system_get_wall_force", rep));
  });
}

mfree_status_t mfree_system_integrate(mfree_system_t *sys, mfree_integrator_t scheme, double *y, double *t,
                                      double t_end, double cfl, double dt_max, mfree_progress_fn progress,
                                      void *user, int64_t *nsteps) {
  // steps taken is written on every return, also when integrate throws part-way
  int64_t steps = 0;
  const mfree_status_t status = mfree::with_handle(sys, "mfree_system_integrate", [&](mfree::System &f) {
    CollectiveArgs args(sys);
    args.require(t && (y || f.neq() == 0), MFREE_ERR_NULL, "y or t is NULL");
    const mfree::Report rep = f.integrate(scheme, args.stand_in(y, f.neq()), *args.stand_in(t, 1), t_end, cfl,
                                          dt_max, progress, user, steps);
    return args.done(mfree::finish(sys->ctx, "mfree_system_integrate", rep));
  });
  if (nsteps) *nsteps = steps;
  return status;
}

mfree_status_t mfree_system_set_active(mfree_system_t *sys, int32_t nactive) {
  MFREE_SYS_SETTER("mfree_system_set_active", f.set_active(nactive));
}
mfree_status_t mfree_system_set_inflow(mfree_system_t *sys, int32_t gate, const double *origin, const double *edges,
                                       const double *normal, double speed, double density, double spacing) {
  MFREE_SYS_SETTER("mfree_system_set_inflow", f.set_inflow(gate, origin, edges, normal, speed, density, spacing));
}
mfree_status_t mfree_system_set_outflow(mfree_system_t *sys, int32_t k, const double *point, const double *normal) {
  MFREE_SYS_SETTER("mfree_system_set_outflow", f.set_outflow(k, point, normal));
}

mfree_status_t mfree_system_update_open_boundaries(mfree_system_t *sys, double t, double *y) {
  return mfree::with_handle(sys, "mfree_system_update_open_boundaries", [&](mfree::System &base) {
    CollectiveArgs args(sys);  // (collective on ranks)
    auto &f = kind<mfree::FluidSystem>(base, "open boundaries (not a fluid)");
    args.require(y || f.neq() == 0, MFREE_ERR_NULL, "y is NULL");
    const mfree::Report rep = f.update_open(t, args.stand_in(y, f.neq()));
    return args.done(mfree::finish(sys->ctx, "mfree_system_update_open_boundaries", rep));
  });
}

mfree_status_t mfree_system_get_active(const mfree_system_t *sys, int32_t *nactive, int32_t n, int32_t *state) {
  return mfree::with_handle(sys, "mfree_system_get_active", [&](const mfree::System &base) {
    const auto &f = kind<mfree::FluidSystem>(base, "active particles (not a fluid)");
    MFREE_REQUIRE(nactive, MFREE_ERR_NULL, "nactive is NULL");
    *nactive = f.active_states(n, state);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_get_inflow(const mfree_system_t *sys, int32_t gate, int64_t *count, double *mass) {
  return open_boundary_totals(sys, "mfree_system_get_inflow", "inflow (not a fluid)",
                              &mfree::FluidSystem::inflow_totals, gate, count, mass);
}

mfree_status_t mfree_system_get_outflow(const mfree_system_t *sys, int32_t k, int64_t *count, double *mass) {
  return open_boundary_totals(sys, "mfree_system_get_outflow", "outflow (not a fluid)",
                              &mfree::FluidSystem::outflow_totals, k, count, mass);
}

mfree_status_t mfree_system_create_elastodynamic(mfree_context_t *ctx, mfree_assembler_t *as, double density,
                                                mfree_system_t **sys) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_system_create_elastodynamic", [&]() {
    MFREE_REQUIRE(sys, MFREE_ERR_NULL, "output pointer is NULL");
    *sys = nullptr;
    MFREE_REQUIRE(as, MFREE_ERR_NULL, "assembler is NULL");
    *sys = elastic_handle(ctx, std::make_unique<mfree::ElasticSystem>(&as->as, density), as);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_create_elastodynamic_galerkin(mfree_context_t *ctx, mfree_assembler_t *stiffness,
                                                        mfree_assembler_t *mass, mfree_system_t **sys) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_system_create_elastodynamic_galerkin", [&]() {
    MFREE_REQUIRE(sys, MFREE_ERR_NULL, "output pointer is NULL");
    *sys = nullptr;
    MFREE_REQUIRE(stiffness && mass, MFREE_ERR_NULL, "stiffness or mass assembler is NULL");
    auto impl = std::make_unique<mfree::ElasticSystem>(&stiffness->as, &mass->as);
    auto *s = new mfree_system_t();
    s->ctx = ctx;
    s->as = stiffness;
    s->mass_as = mass;
    s->sys = std::move(impl);
    mfree::retain(ctx);
    stiffness->refs.fetch_add(1, std::memory_order_relaxed);
    mass->refs.fetch_add(1, std::memory_order_relaxed);
    *sys = s;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_create_elastodynamic_ranks(mfree_context_t *ctx, mfree_assembler_t *as, double density,
                                                      mfree_exchange_fn exchange, mfree_allgather_fn allgather,
                                                      void *user, mfree_system_t **sys) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_system_create_elastodynamic_ranks", [&]() {
    // (a local failure: without the callbacks no rank can be told)
    MFREE_REQUIRE(exchange && allgather, MFREE_ERR_NULL, "exchange or allgather callback is NULL");
    if (sys) *sys = nullptr;
    const mfree::Collective coll(exchange, allgather, user);
    CollectiveArgs args(&coll);
    args.require(sys, MFREE_ERR_NULL, "output pointer is NULL");
    auto impl = mfree::ElasticSystem::on_ranks(as ? &as->as : nullptr, density, coll);
    args.done(MFREE_SUCCESS);
    *sys = elastic_handle(ctx, std::move(impl), as);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_set_load_history(mfree_system_t *sys, mfree_history_fn g, void *user) {
  return mfree::with_handle(sys, "mfree_system_set_load_history", [&](mfree::System &base) {
    kind<mfree::ElasticSystem>(base, "load history (not elastodynamic)").set_load_history(g, user);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_get_stress(mfree_system_t *sys, double t, const double *y, double *sigma) {
  return mfree::with_handle(sys, "mfree_system_get_stress", [&](mfree::System &base) {
    CollectiveArgs args(sys);
    const auto &e = kind<mfree::ElasticSystem>(base, "stress output (not elastodynamic)");
    MFREE_REQUIRE(!e.galerkin(), MFREE_ERR_UNSUPPORTED,
                  "no stress output for Galerkin systems: apply the trial approximant's gradient "
                  "(mfree_approximant_apply, MFREE_OP_GRADIENT) to the displacements");
    args.require((y && sigma) || e.neq() == 0, MFREE_ERR_NULL, "y or sigma is NULL");
    e.stress(t, args.stand_in(y, e.neq()),
             args.stand_in(sigma, static_cast<int64_t>(e.stress_components()) * e.num_particles()));
    return args.done(MFREE_SUCCESS);
  });
}

mfree_status_t mfree_system_get_dimension(const mfree_system_t *sys, int32_t *dim, int32_t *n) {
  return mfree::with_handle(sys, "mfree_system_get_dimension", [&](const mfree::System &base) {
    MFREE_REQUIRE(dim || n, MFREE_ERR_NULL, "both outputs are NULL");
    int32_t d = 0, np = 0;
    if (const auto *f = dynamic_cast<const mfree::FluidSystem *>(&base)) {
      d = f->dim();
      // (on ranks the outputs' particles are the owned ones, neq = (2 dim + 1) n_owned)
      np = f->on_ranks() ? f->neq() / (2 * d + 1) : f->size();
    } else {
      const auto &e = kind<mfree::ElasticSystem>(base, "particles");
      d = e.dim();
      np = e.num_particles();
    }
    if (dim) *dim = d;
    if (n) *n = np;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_set_pending_error(mfree_system_t *sys, mfree_status_t status, const char *message) {
  return mfree::with_handle(sys, "mfree_system_set_pending_error", [&](mfree::System &) {
    MFREE_REQUIRE(status <= MFREE_SUCCESS && std::strcmp(mfree_status_string(status), "unknown status") != 0,
                  MFREE_ERR_ARG,
                  "status " + std::to_string(static_cast<int>(status)) +
                      " is not an error status (a negative mfree_status_t, or MFREE_SUCCESS to clear)");
    mfree::Report fault;
    if (status != MFREE_SUCCESS) {
      // (the caller's "mfree_...: " prefix dropped: the collective call names itself)
      const char *text = message ? message : mfree_status_string(status);
      const char *colon = std::strstr(text, ": ");
      fault.fail(status, colon && std::strncmp(text, "mfree_", 6) == 0 ? colon + 2 : text);
    }
    sys->pending = fault;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_get_context(const mfree_system_t *sys, mfree_context_t **ctx) {
  if (!sys || !ctx) return MFREE_ERR_NULL;
  *ctx = sys->ctx;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_system_create_fluid_ranks(mfree_context_t *ctx, int32_t dim, int32_t n_owned, int32_t n_ghost,
                                               const int64_t *global_ids, double width, mfree_exchange_fn exchange,
                                               mfree_allgather_fn allgather, void *user, mfree_system_t **sys) {
  if (!ctx) return MFREE_ERR_NULL;
  return mfree::guard(ctx, "mfree_system_create_fluid_ranks", [&]() {
    // (a local failure: without the callbacks no rank can be told)
    MFREE_REQUIRE(exchange && allgather, MFREE_ERR_NULL, "exchange or allgather callback is NULL");
    if (sys) *sys = nullptr;
    const mfree::Collective coll(exchange, allgather, user);
    CollectiveArgs args(&coll);
    args.require(sys, MFREE_ERR_NULL, "output pointer is NULL");
    auto impl = mfree::FluidRanks::create(dim, n_owned, n_ghost, global_ids, width, coll);
    args.done(MFREE_SUCCESS);
    auto *s = new mfree_system_t();
    s->ctx = ctx;
    s->sys = std::move(impl);
    mfree::retain(ctx);
    *sys = s;
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_set_halo_rebuild(mfree_system_t *sys, mfree_halo_rebuild_fn rebuild) {
  return mfree::with_handle(sys, "mfree_system_set_halo_rebuild", [&](mfree::System &base) {
    kind<mfree::FluidRanks>(base, "halo rebuild (not a fluid on ranks)").set_rebuild(rebuild);
    return MFREE_SUCCESS;
  });
}

mfree_status_t mfree_system_move_particles(mfree_system_t *sys, int32_t n_new, mfree_particles_move_fn move,
                                           void *move_user, double *y, int64_t capacity) {
  return mfree::with_handle(sys, "mfree_system_move_particles", [&](mfree::System &base) {
    CollectiveArgs args(sys);
    kind<mfree::FluidRanks>(base, "particle move (not a fluid on ranks)")
        .move_particles(n_new, move, move_user, args.stand_in(y, 0), capacity);
    return args.done(MFREE_SUCCESS);
  });
}

}  // extern "C"
