// Weakly compressible free-surface flow by Galerkin SPH with MLS shape functions
// (paper 003): the semi-discrete right-hand side, mass matrices and the native
// leap-frog and predictor-corrector integrators.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/shape/approximant.hpp"
#include "core/base/error.hpp"
#include "core/base/parallel.hpp"
#include "core/systems/fluid_inflow.hpp"
#include "core/systems/fluid_wall.hpp"
#include "core/discretize/matrix.hpp"
#include "mfree.h"
#include "core/particles/particles.hpp"
#include "core/systems/system.hpp"

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
  // The shape functions (fluid_tables.cpp): an approximant's method, order, kernel and
  // its shape parameter (paper 003: MLS, order 1, the cubic spline, the default).
  void set_approximation(int method, int order, int kernel, double param);
  // Options beyond paper 003 (fluid_wall.cpp): dummy wall particles (n = 0 removes them),
  // density diffusion coefficient delta (0 = off, the default).
  void set_dummy_particles(int32_t n, const double *x, const double *vol, int64_t stride);
  void set_density_diffusion(double delta);
  void set_consistent_integration(int on);  // 0 (default) or 1: constant VCI correction
  void set_velocity_smoothing(double beta);  // 0 (default): off
  // The CFL step with each particle's speed scaled by sqrt(M_i / m_i) where its Galerkin
  // lumped mass m_i is below its particle mass M_i (fluid.cpp, stable_dt); 0 (default): eq 120.
  void set_lumped_mass_step(int on);
  // The step also at most 1.5 / omega_max, omega_max the largest frequency of the
  // linearised acoustic operator by a power iteration carried from step to step (fluid.cpp,
  // acoustic_omega2); 0 (default): off.
  void set_acoustic_step(int on);

  int dim() const { return dim_; }
  int32_t size() const { return n_; }
  int32_t neq() const override { return (2 * dim_ + 1) * n_; }

  Report rhs(double t, const double *y, double *ydot) override;
  Report mass(const double *y, bool consistent, SparseMatrix &M) override;
  virtual Report interpolation(const double *y, SparseMatrix &S);
  // M(y) v (mfree_system_apply_mass): the mass assembled at y, kept for the next product
  // while y's bits, the kind and the options stay (a mass solver's products within one
  // solve ask for the same mass), applied to v (neq values each).
  Report apply_mass(const double *y, bool consistent, const double *v, double *Mv) override;
  virtual void pressure(const double *y, double *p) const;
  virtual Report velocity(const double *y, double *vhat);
  // The walls' force on the fluid at state y (fluid_wall.cpp): total (dim values, or
  // NULL) and each wall particle's share of the eqs 122-124 force (per_wall: dim values
  // for each of the nwall wall particles, or NULL).
  virtual Report wall_force(const double *y, double *total, int32_t nwall, double *per_wall);
  Report integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                   mfree_progress_fn progress, void *user, int64_t &nsteps) override;

  // Open boundaries (fluid_inflow.cpp): with any of these n is a capacity, of which the
  // active particles are the fluid; the evaluations above then run on the active ones
  // (a fluid of their own, built with this system's options: a new option must be
  // copied in open_inner too).
  void set_active(int32_t nactive);
  void set_inflow(int32_t gate, const double *origin, const double *edges, const double *normal, double speed,
                  double density, double spacing);
  void set_outflow(int32_t k, const double *point, const double *normal);
  virtual Report update_open(double t, double *y);
  // The active count (on ranks the owned ones); states if n > 0.
  virtual int32_t active_states(int32_t n, int32_t *state) const;
  void inflow_totals(int32_t gate, int64_t &count, double &mass) const;
  void outflow_totals(int32_t k, int64_t &count, double &mass) const;
  void options_changed() {  // after every setter
    if (open_) open_->dirty = true;
    ++options_gen_;
  }

  // On ranks (fluid_ranks.hpp): a FluidRanks numbers its nodes by global id and overrides
  // these two hooks; the one-process fluid leaves them empty.
  virtual bool on_ranks() const { return false; }

 protected:
  // Per-particle parameters given in the host's order (set_fluid, set_masses) into the
  // nodes' order.
  virtual void to_nodes(HVec<double> &per_particle) const { (void)per_particle; }
  // After the rows of a prepare, before their statuses are checked: the rows a rank does
  // not need are dropped there, and its scatter runs in node order.
  virtual void rows_done() {}
  // Whether stable_dt's lumped-mass scaling (set_lumped_mass_step) and the power
  // iteration's sums (set_acoustic_step) count node i: on ranks only the owned nodes,
  // whose lumped masses sum every row that holds them (a far ghost's rows are dropped,
  // its sum incomplete; its owner counts it).
  virtual bool steps_by(int32_t i) const { (void)i; return true; }
  // The power iteration of set_acoustic_step on ranks: the owned nodes' values of a node
  // array (na per node) to the ghosts (before each product), and node i's global id (the
  // index of its share of the iteration's fixed vector).
  virtual void to_ghosts(double *a, int na) { (void)a; (void)na; }
  virtual int64_t global_id(int32_t i) const { return i; }
  // The mass matrix of mass() from the prepared tables, for np particles: the state's
  // particle i at node node[i], node k the state's particle part[k] (-1: none, its
  // terms dropped; nodes < n_).
  void mass_matrix(int32_t np, const int32_t *node, const int32_t *part, bool consistent, SparseMatrix &M) const;
  // Row k's terms of the force per wall particle (wall_force's per_wall): (w, m_k f2) for
  // each wall particle w the point x_k approaches within r0 (eqs 122-124 as accel takes
  // them; m_k = sum_i N_i(x_k) m_i with the masses m accel divides by, vn the nodes'
  // velocities); wall w's force sums m_k f2 n_w over the rows in node order.
  void wall_row(int32_t k, const double *vn, const double *m, std::vector<std::pair<int32_t, double>> &terms) const;
  // The interpolation matrix's rows (interpolation): np rows, row r holding node node[r]'s
  // values N_j(x_k) at the fluid nodes j, in column col[j] of ncols, sorted by column.
  void interpolation_rows(int32_t np, const int32_t *node, const int32_t *col, int32_t ncols, SparseMatrix &S) const;
  // apply_mass's kept mass: M assembled at the state y (neq values) of kind consistent
  // with the options of generation gen (options_gen_); valid: M may be used.
  struct KeptMass {
    SparseMatrix M;
    std::vector<double> y;
    bool consistent = false, valid = false;
    int64_t gen = -1;
    bool holds(const double *at, int32_t neq, bool c, int64_t g) const;
    void keep(const double *at, int32_t neq, bool c, int64_t g);
  };
  KeptMass kept_mass_;
  int64_t options_gen_ = 0;
  // The Tait pressure at density rho, rest density rho0.
  double pressure_at(double rho, double rho0) const { return kappa_ * (std::pow(rho / rho0, gamma_) - 1.0); }

 private:
  friend class FluidRanks;
  void check_ready() const;
  // Threads for a loop of a few operations per particle (checks, volumes, updates): waking a
  // team and meeting at its barrier cost as much as thousands of such operations, and more
  // on a loaded machine, so they pay off only from ~8,000 particles.
  static int light_threads(int64_t n) { return num_threads(n / 4); }
  // Validate the state (unless checked: integrate's state after a step, which
  // check_state has just passed) and build the shape-function tables at the nodes (below).
  Report prepare(const double *y, bool checked = false);
  // The tables' rows for the node positions xn: the search of ps_ with its skin (see
  // cols_), and with new candidate lists the colouring and the wall lists on them.
  Report candidates(const double *xn);
  // Tables rows [k0, k1) on thread t: the approximants' rows (the fast path, the general
  // path with its fallbacks and Shepard rule where it does not finish a row or a row is
  // worse conditioned than shepard_cond_); with transpose, also NT_ (true if a pair is in
  // one node's row only, which the search rules out). k0 starts a chunk of kChunk rows.
  bool table_rows(int t, int32_t k0, int32_t k1, const double *xn, const double *pack, bool transpose);
  // Per-thread scratch of the rows: the fast path's, the general path's input (offsets,
  // volumes, supports) and work.
  struct RowsScratch {
    FastScratch fast;
    HVec<double> d, v, h;
    LocalWork work;
  };
  // Row k by the general path (local.hpp, compute_site_rules); fast_done: the fast path's
  // rows stand, only the Shepard rule applies.
  void general_row(int32_t k, const double *xn, RowsScratch &w, bool fast_done);
  // Chunks of kChunk rows coloured so that no two chunks of a colour touch a common
  // node on the candidate pattern cand, for the scatter of accel (rebuilt with the lists).
  void color_chunks(const Csr &cand);
  // Acceleration parameters a (dim per particle) from the prepared tables and v, rho:
  // accel_args (node arrays, zeroed sums), accel_point for every row in colour order
  // (chunk_order_), accel_end (the nodes' accelerations).
  struct AccelArgs {
    const double *v, *rho, *rho0, *mass;
    bool keep_pack;
  };
  Report accel(const double *v, const double *rho, double *a);
  AccelArgs accel_args(const double *v, const double *rho);
  template <int D>
  void accel_point(int64_t k, const AccelArgs &aa);
  // Point k's stress sigma_k V_k (from the interpolated velocity vh and the velocity
  // gradient L at x_k), masses M_k and L_k and wall force F (wall: F != 0), shared by
  // accel_point and the AVX2 copy of its 2D rows; also fills pack_ when asked.
  template <int D>
  struct PointTerms {
    double S[D][D], Mk, Lk, F[D];
    bool wall;
  };
  template <int D>
  void point_terms(int64_t k, const AccelArgs &aa, const double (&vh)[D], const double (&L)[D][D], PointTerms<D> &pt);
  // accel_point<2> for rows [k0, k1) and the 2D kinematics of nodes [k0, k1), four table
  // entries at a time for AVX2 + FMA (the same sums, rounded differently), chosen per step.
  void accel_rows2_avx2(int64_t k0, int64_t k1, const AccelArgs &aa);
  void kinematics2_avx2(int64_t k0, int64_t k1, const double *v, const double *rho, double *vhat, double *drho) const;
  template <int D>
  Report accel_end(const AccelArgs &aa, double *a);
  // Interpolated velocities and density rates for velocity parameters v.
  void kinematics(const double *v, const double *rho, double *vhat, double *drho) const;
  double stable_dt(const double *y);  // h / max(c_i + |v_i|), or with lumped_step_ (on the prepared tables)
  // integrate's step from the stable limit (003 eq 120): cfl * limit capped by dt_max (cfl
  // > 0) or dt_max checked against the limit, then cut at t_end; a failure if it no longer
  // advances t (y, if not NULL, names the fastest particle in the message).
  Report step_size(double limit, double cfl, double dt_max, double t, double t_end, int64_t nsteps,
                   const double *y, double &dt, double cap = INFINITY) const;
  double acoustic_cap(const double *y);  // set_acoustic_step's bound 1.5 / omega (INFINITY when off)
  std::string fastest(const double *y) const;  // message part naming the particle of max c_i + |v_i|
  // The first invalid particle of y, if any; step >= 0 prefixes the message with it.
  Report check_state(const double *y, int64_t step) const;
  double tait(double rho, double rho0) const;  // (rho / rho0)^gamma
  // fluid_wall.cpp. Nodes (and nodal quadrature points): the n_ fluid particles, then
  // the dummies. Without dummies the node arrays are the fluid's own.
  int32_t nq() const { return n_ + dummy_.n; }
  // A new node set: the n_ fluid particles, then ndummy dummies of volumes dvol (the
  // search lists, the tables and the fluid's volumes follow at the next prepare); on ranks
  // also after the ghosts changed (the dummies stay).
  void seat_nodes(int32_t ndummy, const double *dvol);
  const double *node_positions(const double *y);     // fluid positions + dummies
  const double *node_velocities(const double *v) const;  // v + zeros for the dummies
  const double *node_densities(const double *rho) const;  // rho + extrapolated (fills rho0, mass)
  double share(int32_t k) const { return dummy_.n ? dummy_.share[k] : 1.0; }
  void fluid_share();                                 // fills dummy_.share after the tables
  void density_diffusion(const double *rho, double *drho) const;  // adds the delta-SPH term
  void vci_setup();  // after the tables
  void vci_correct(const double *pack, int per_point, double *a) const;  // end of accel
  void velocity_smoothing(const double *v, const double *m, int stride, double *a) const;  // end of accel

  int dim_;
  int32_t n_;
  HVec<double> rho0_, mass_;  // (copies of host data come from the context's hook)
  double kappa_ = 1.0, gamma_ = 7.0, mu_ = 0.0, h_ = 0.0;
  double g_[3] = {0, 0, 0};
  int lump_ = MFREE_LUMP_GALERKIN;
  std::unique_ptr<ParticleSet> walls_;
  HVec<double> wall_n_;
  double r0_ = 0.0, strength_ = 0.0;
  double shepard_cond_ = 100.0;
  // The shape functions (set_approximation) and the fast path for them (made at prepare)
  int method_ = MFREE_METHOD_MLS, order_ = 1, kernel_id_ = MFREE_KERNEL_CUBIC_SPLINE;
  double kernel_param_ = 0.0;
  std::unique_ptr<Kernel> kernel_;
  std::unique_ptr<FastPath> fast_;
  mutable DummyWall dummy_;  // scratch node arrays are refilled by const evaluations
  double delta_ = 0.0;
  bool vci_ = false;
  double vsmooth_ = 0.0;
  bool box_ = false;
  double lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};

  // Shape functions at the nodes, rebuilt at every prepare (003: linear MLS with the
  // cubic spline, nodal quadrature): rows sorted by column, entries [rb(k), re(k)) of
  // cols_, values N_ and gradients G_ (dim per entry) of node cols_[e] at node k. Only
  // with consistent integration (vci_, whose sums fluid_wall.cpp takes as gathers) also
  // the transpose NT_ on the same pattern (it is symmetric: one h for all), value and
  // gradient interleaved (dim + 1 per entry): entry e of row i holds N_i(x_j), j =
  // cols_[e]. The force assembly itself scatters row by row (see chunk_order_) and needs
  // no transpose.
  //
  // The rows are the neighbour lists of ps_ (the nodes, search radius R h, the kernel's
  // closed support): its search keeps candidate lists of radius R h + skin_ h and filters
  // the rows from them while no node has moved more than half the skin since their build
  // (particles/neighbors_verlet.inc), so that the tables never depend on the skin, only
  // the cost does. The tables are sized for the candidates (no allocation until the next
  // build); the colouring and the wall lists are built on them, with each new build
  // (cand_search_: the set's search count they are for).
  ParticleSet ps_;
  HVec<double> vol_;
  int64_t rb(int64_t k) const { return rb_[k]; }
  int64_t re(int64_t k) const { return re_[k]; }
  // row begins and ends and the columns: ps_.neighbors() after the last prepare, or,
  // where the set left its rows to the fast path's filter (ps_.rows_left(): no
  // consistent integration, whose transposed writes need every row first), rows in the
  // candidates' storage, each chunk's rows one after the other from its candidates' start
  // (FastTables::kept): columns in kept_, begins and ends in rowbeg_ and rowend_
  const int64_t *rb_ = nullptr, *re_ = nullptr;
  const int32_t *cols_ = nullptr;
  HVec<int32_t> kept_;
  HVec<int64_t> rowbeg_, rowend_;
  // HVec: without an allocator hook, blocks >= 2 MiB get transparent huge pages (alloc.hpp):
  // the tables (~18 MB at 25,000 particles) are written and read three times per step
  HVec<double> N_, G_, NT_;
  std::vector<double> cond_;
  double skin_ = 0.25;  // in units of h
  bool lists_valid_ = false;  // false: colour and find the wall lists at the next prepare
  int64_t cand_search_ = -1;
  const double *xbound_ = nullptr;  // node positions ps_ borrows
  int64_t maxrow_ = 0;               // longest candidate row
  std::vector<RowsScratch> rows_scratch_;
  // per node: the rows' status, support and order, the node's place in its row; the
  // nodes' positions and volumes in records for the methods that weight by volume
  std::vector<int32_t> site_status_, site_support_, site_order_, self_;
  std::vector<double> node_pack_;
  Csr wall_nbr_;
  // per node (reused): packed quadrature-point data of accel; integrate's states and rates
  std::vector<double> pack_, work_state_, stage_, rate_, vh_, dr_, vh_start_;
  // Velocities (dim per fluid particle) that decide the wall force's switch f1 (003 eq
  // 123) in accel instead of v_hat at the point, or nullptr: the predictor-corrector's
  // corrector stage decides it with the step's starting v_hat (fluid.cpp, integrate).
  const double *wall_switch_v_ = nullptr;
  bool lumped_step_ = false;           // set_lumped_mass_step
  std::vector<double> lumped_;         // stable_dt's lumped masses (with lumped_step_)
  // set_acoustic_step: the power iteration's vector (kept between steps) and its scratch
  bool acoustic_step_ = false;
  bool pw_started_ = false;  // pw_u_ holds the last call's vector
  std::vector<double> pw_u_, pw_w_, pw_div_, pw_m_;
  double acoustic_omega2(const double *y, int iters);  // on the prepared tables
  void galerkin_lumped(std::vector<double> &m) const;  // eq 56 on the prepared tables
  // accel scatters row k's contributions to the nodes of the row; rows go in chunks of
  // kChunk, chunk_order_[color_ptr_[c] .. color_ptr_[c + 1]) are the chunks of colour c,
  // which no two of touch a common node. Colours run one after another, so every node
  // sums its contributions in the same order (colour, then row) for any thread count.
  static constexpr int32_t kChunk = 512;
  std::vector<int32_t> chunk_order_, color_ptr_;
  std::vector<uint64_t> color_mask_;  // scratch of color_chunks
  std::vector<int32_t> chunk_color_, chunk_fill_;  // scratch of color_chunks
  bool scatter_threads_ = true;       // false: one colour, the chunks in order, one thread
  std::vector<double> acc_;           // per node: force, mass, lumped mass, wall force

  // Open boundaries (fluid_inflow.cpp); null: every particle is active (paper 003).
  std::unique_ptr<FluidOpen> open_;
  FluidOpen &open();
  FluidSystem &open_inner() const;                // built when dirty
  const double *open_gather(const double *y) const;  // compact state of the active particles
  Report open_result(Report r) const;               // particle numbers of the capacity
  Report open_rhs(const double *y, double *ydot);
  Report open_velocity(const double *y, double *vhat);
  void open_pressure(const double *y, double *p) const;
  Report open_interpolation(const double *y, SparseMatrix &S);
  Report open_mass(const double *y, bool consistent, SparseMatrix &M);
  Report open_wall_force(const double *y, double *total, int32_t nwall, double *per_wall);
  Report open_integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                        mfree_progress_fn progress, void *user, int64_t &nsteps);
  void open_options(FluidSystem &in, const double *r0, const double *m) const;  // this system's, on in
  // The inner fluid's matrix Mc over the state of its na particles (emptied for none) as M
  // over the state of n particles, particle a being item[a] (increasing); identity rows
  // for the others.
  void open_expand(SparseMatrix &Mc, const int32_t *item, size_t na, int32_t n, SparseMatrix &M) const;
  // A matrix of compact unknowns written on n rows and ncols columns: row and column q of A
  // become map[q] (increasing); the other rows are identity rows.
  static void expand(const SparseMatrix &A, const std::vector<int32_t> &map, int32_t n, int32_t ncols,
                     SparseMatrix &out);
  // The decisions of an update (the counters, the state of every particle of the capacity)
  // from the crossings out, in increasing particle order; fresh: the particles it
  // activated, with their gates.
  Report open_plan(double t, const std::vector<OutflowCrossing> &out, std::vector<std::pair<int32_t, int32_t>> &fresh);
  void buffer_state(int32_t i, double t, double *x, double *v, double *rho) const;  // buffer particle i's
  void place_buffer(double t, double *y, bool compact) const;  // imposed state of the buffers
  int32_t crossed_plane(const double *x) const;                // the first outflow x is past, or -1
  bool open_crossed(const double *y, bool compact) const;      // a fluid particle past an outflow
  static int32_t open_progress(void *u, int64_t step, double t, double dt);  // integrate's, per step
  // The integration in windows between the gates' releases, updated between them, on the
  // inner fluid (fluid_inflow.cpp); its three steps, which a fluid on ranks replaces: the
  // inner fluid with its state in open_->yc, that state back into y, the per-step callback.
  Report open_windows(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                      mfree_progress_fn progress, void *user, int64_t &nsteps);
  virtual FluidSystem &open_stage(const double *y);
  virtual void open_unstage(const double *yc, double *y) const;
  virtual mfree_progress_fn open_stepper() const { return &FluidSystem::open_progress; }
};

}  // namespace mfree
