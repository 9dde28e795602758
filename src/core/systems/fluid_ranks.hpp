// The fluid of paper 003 on one rank of several: the rank's owned particles and two
// support radii of ghosts, numbered by global id, so that every owned particle's
// acceleration, velocity and density rate are bitwise those of one rank (docs/fluid-ranks.md).
// The state a host sees holds the owned particles only; the ghosts' states come from
// the host's exchange callback, the reductions (step limit, statuses) from its
// all-gather.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/systems/collective.hpp"
#include "core/systems/fluid.hpp"

namespace mfree {

class FluidRanks final : public FluidSystem {
 public:
  // Collective: every rank gets the same outcome (a failure on one rank, or ranks that
  // disagree on dim or width, throws the agreed error on every rank). ids: the global
  // ids of the n_owned + n_ghost local items, owned first (the host's order, which the
  // exchange callback uses); width: the depth of the ghost layer around the owned
  // particles (at least two support radii, four with dummies and density diffusion:
  // depth(); checked at every evaluation).
  static std::unique_ptr<FluidRanks> create(int dim, int32_t n_owned, int32_t n_ghost, const int64_t *ids,
                                            double width, const Collective &coll);

  bool on_ranks() const override { return true; }
  const Collective *collective() const override { return &coll_; }
  int32_t neq() const override { return (2 * dim() + 1) * n_own_; }
  Report rhs(double t, const double *y, double *ydot) override;
  Report mass(const double *y, bool consistent, SparseMatrix &M) override;
  void pressure(const double *y, double *p) const override;
  // The mass products and the interpolation matrix on ranks (fluid_ranks_matrices.cpp).
  Report apply_mass(const double *y, bool consistent, const double *v, double *Mv) override;
  Report interpolation(const double *y, SparseMatrix &S) override;
  Report velocity(const double *y, double *vhat) override;
  Report wall_force(const double *y, double *total, int32_t nwall, double *per_wall) override;
  Report integrate(int scheme, double *y, double &t, double t_end, double cfl, double dt_max,
                   mfree_progress_fn progress, void *user, int64_t &nsteps) override;

  // Ghosts rebuilt and particles moved (the host's callbacks, fluid_ranks.cpp's last block).
  // With a rebuild callback, an evaluation whose ghost layer is no longer deep enough has
  // the host rebuild it around the owned particles and runs again on the new ghosts.
  void set_rebuild(mfree_halo_rebuild_fn rebuild) { rebuild_ = rebuild; }
  // Collective: the owned particles' records (state from y, rest density, mass, global id)
  // through the host's move, the halo rebuilt around the n_new particles that arrive, the
  // system re-seated on them and their state written to y (capacity doubles).
  void move_particles(int32_t n_new, mfree_particles_move_fn move, void *move_user, double *y, int64_t capacity);

  // Open boundaries on ranks (fluid_ranks_open.cpp): the capacity is every rank's items,
  // global ids 0 .. N - 1; the bookkeeping is per global id and the same on every rank,
  // the update collective; the owned items' states.
  Report update_open(double t, double *y) override;
  int32_t active_states(int32_t n, int32_t *state) const override;

 protected:
  void to_nodes(HVec<double> &per_particle) const override;
  void rows_done() override;
  bool steps_by(int32_t i) const override { return is_owned_[i] != 0; }
  void to_ghosts(double *a, int na) override { sync(a, na); }
  int64_t global_id(int32_t i) const override { return gid_[i]; }

 private:
  FluidRanks(int dim, int32_t n_owned, int32_t n_ghost, const int64_t *ids, double width, const Collective &coll);
  // The owned particles' state y (x, v, rho of the owned items) into the node state ys_,
  // the ghosts' through one exchange.
  void load(const double *y);
  // The owned nodes' values of node arrays a (na per node), b and c (nb, nc per node, or
  // none) to the ghost nodes: one exchange of na + nb + nc values per item.
  void sync(double *a, int na, double *b = nullptr, int nb = 0, double *c = nullptr, int nc = 0);
  // The tables at the node state ys (checked: its state check passed), the halo's depth
  // check, and the accelerations a of the owned nodes (node arrays); limit: this rank's
  // step limit; reach: twice the largest displacement of an owned particle since the
  // first evaluation, negated (for the minimum of the all-gather).
  Report prepare_accel(const double *ys, bool checked, double *a, double &limit, double &reach);
  // prepare_accel without the accelerations.
  Report prepare_rows(const double *ys, bool checked, double &limit, double &reach);
  // MFREE_ERR_HALO on every rank when reach (agreed by agree_min) exceeds the width;
  // step > 0: integrate's step, named in the message.
  void check_reach(double reach, int64_t step) const;
  // The ghost layer's depth in support radii: two for the rows of the owned particles'
  // neighbours; four with dummies and density diffusion (rows_done).
  int depth() const { return dummy_.n > 0 && delta_ > 0.0 ? 4 : 2; }
  // The outputs' evaluation at the owned state y: load, the tables (and with a, the
  // accelerations into a), agreed; refuse != MFREE_SUCCESS: this rank's error instead,
  // with the message why (every rank then returns it); y may be NULL on a rank that owns
  // no particle; want: nwant (<= 2) values replaced by their minima over the ranks.
  Report output_prepare(const double *y, double *a, mfree_status_t refuse, const char *why, double *want = nullptr,
                        int nwant = 0);
  std::vector<double> stand_in_;  // output_prepare's stand-in for a NULL state
  // After output_prepare: the lumped mass of the owned rows (mass's matrix), or the
  // consistent mass's owned rows over every node (apply_mass's).
  void lumped_rows(SparseMatrix &M) const;
  void consistent_rows(SparseMatrix &M) const;
  std::vector<double> w_;  // apply_mass's node vector
  // wall_force's per_wall (every rank's rows' terms gathered) after output_prepare with
  // the accelerations; galerkin: the rows' masses are the lumped masses.
  void wall_shares(bool galerkin, double *per_wall);
  // The predictor-corrector's corrected state in yn_ (integrate's step number step).
  Report corrected_state(double dt, int64_t step);
  // accel, with the mass check restricted to the owned nodes (ghost nodes far out have
  // no complete rows and no mass).
  Report owned_accel(const double *v, const double *rho, double *a);
  // Every rank's status and nv values: the agreed outcome (a failure at an owned particle
  // before one at a ghost), and vals replaced by their minima over the ranks (exact in
  // any order).
  Report agree_min(const Report &mine, double *vals, int nv) const;
  // A failure's message names the particle's global id; ghost_fault_: the particle is a
  // ghost (its owner fails alike, and its report is the one every rank returns).
  Report named(Report r) const;
  mutable bool ghost_fault_ = false;

  // The nodes from the n_own_ + n_ghost_ items' global ids (checked: >= 0, distinct).
  void number(const int64_t *ids);
  // The halo rebuilt by the host around n_owned particles (positions xo, dim per particle,
  // ids oid, per-particle data: rest density and mass, two per particle, host order) and
  // the system re-seated on them and the new ghosts (collective; a failure after the
  // host's rebuild leaves the system broken_: its ghosts no longer match the host's).
  // pw: the power iteration's vector at the owned particles (dim per particle, host
  // order; with pw_started_), which the iteration carries on from.
  void reseat(int32_t n_owned, const double *xo, const int64_t *oid, const double *data, const double *pw);
  // reseat around the owned particles' current positions (the first part of y).
  void rebuild_halo(const double *y);
  void check_usable() const;
  mfree_halo_rebuild_fn rebuild_ = nullptr;
  bool broken_ = false;
  std::vector<double> mv_x_, mv_data_, mv_rec_, mv_pw_;
  std::vector<int64_t> mv_id_;

  // ---- Open boundaries on ranks (fluid_ranks_open.cpp) ----
  // The evaluations run on an inner FluidRanks of the active items, whose callbacks relay
  // to this system's host: its items are this system's active owned items, then its
  // active ghosts (host order), and an exchange expands them into the host's items.
  struct OpenLink {
    FluidRanks *outer = nullptr;
    std::vector<int32_t> item;  // inner item -> this system's host item
    int32_t n_own = 0;          // the active owned items among them
    std::vector<int64_t> ids;   // their global ids
    std::vector<double> buf;    // the host's items for an exchange
    std::vector<double> xo;     // this system's owned positions (host order): the halo's rebuild
  };
  OpenLink link_;
  // On an inner system: after each step of integrate, the buffer particles' imposed state
  // at the new time, at every node (the one-process fluid places them between steps).
  std::function<void(double t, int32_t n, const int64_t *gid, double *ys)> place_;
  void open_init();                                  // the bookkeeping per global id (collective)
  void open_items();                                 // link_ from the current items
  FluidRanks &open_ranks_inner(const double *y);     // built when dirty (collective)
  void open_ranks_gather(const double *y, std::vector<double> &yc) const;  // the inner's owned part
  void open_ranks_scatter(const double *yc, double *y) const;
  // An evaluation's start (collective): a pending fault agreed, the bookkeeping set up, the
  // inner system in, its state in open_->yc.
  Report open_begin(const double *y, FluidRanks *&in);
  const InflowGate *buffer_gate(int32_t p) const;  // owned item p's gate if a buffer particle
  Report open_rhs_ranks(const double *y, double *ydot);
  Report open_velocity_ranks(const double *y, double *vhat);
  Report open_mass_ranks(const double *y, bool consistent, SparseMatrix &M);
  Report open_interpolation_ranks(const double *y, SparseMatrix &S);
  Report open_apply_mass_ranks(const double *y, bool consistent, const double *v, double *Mv);
  Report open_wall_force_ranks(const double *y, double *total, int32_t nwall, double *per_wall);
  FluidSystem &open_stage(const double *y) override;  // (open_windows' steps)
  void open_unstage(const double *yc, double *y) const override { open_ranks_scatter(yc, y); }
  mfree_progress_fn open_stepper() const override { return &FluidRanks::open_progress_ranks; }
  int8_t item_state(int32_t p) const;  // host item p's state
  static mfree_status_t open_exchange(void *u, int32_t ncomp, double *field, int64_t ld);
  static mfree_status_t open_allgather(void *u, const double *in, int64_t n, double *out, int64_t cap,
                                       int64_t *total);
  static mfree_status_t open_rebuild(void *u, int32_t n_owned, const double *x, int64_t ld, const int64_t *ids,
                                     double width, int32_t *n_ghost, const int64_t **all_ids);
  static int32_t open_progress_ranks(void *u, int64_t step, double t, double dt);

  Collective coll_;
  int32_t n_own_ = 0, n_ghost_ = 0;
  double width_ = 0.0;
  std::vector<int32_t> node_;    // host item -> node (nodes in ascending global id)
  std::vector<int64_t> gid_;     // node -> global id
  std::vector<int32_t> owned_;   // the owned nodes, in the host's order
  std::vector<char> is_owned_, need_;  // per node
  std::vector<int64_t> re_need_;         // row ends with the rows not needed emptied (rows_done)
  std::vector<double> ys_, yn_, rate_n_, vh_n_, dr_n_, buf_;  // node states and rates
  std::vector<double> yp_, vh0_, dr0_, a2_;  // the predictor-corrector's predicted stage
  std::vector<double> xfirst_;   // owned positions at the first evaluation (the halo's reference)
};

}  // namespace mfree
