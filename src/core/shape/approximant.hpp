// Approximant: shape-function tables (values, gradients, Hessians) of one method at a
// set of sites (the owned particles or host points), applied to host fields.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/base/error.hpp"
#include "core/base/kernel.hpp"
#include "core/shape/local.hpp"
#include "core/particles/particles.hpp"
#include "core/shape/shape_fast.hpp"

namespace mfree {

class Mesh;

// The pair support h_sj of a site with support hs and a neighbour with hj under a search
// convention (MFREE_SEARCH_*).
inline double pair_support(int convention, double hs, double hj) {
  switch (convention) {
    case MFREE_SEARCH_SYMMETRIC_MAX:
      return hs < hj ? hj : hs;  // std::max
    case MFREE_SEARCH_SYMMETRIC_MEAN:
      return 0.5 * (hs + hj);
    default:
      return hs;
  }
}

// The method's name in messages ("MLS", "Randles-Libersky", ...).
const char *method_name(int method);

// Everything that defines an approximant apart from its particle set and sites; the
// assembler clones it onto its own quadrature points.
struct ApproxConfig {
  int method = MFREE_METHOD_MLS;
  int kernel = MFREE_KERNEL_CUBIC_SPLINE;
  double param = 0.0;
  int order = 1;
  int flags = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT;
  int fallback = MFREE_FALLBACK_NONE;
  std::shared_ptr<const Mesh> mesh;  // MPFEM only
  int mpfem_deriv = MFREE_MPFEM_DERIV_FULL;
  int mpfem_ngauss = 8;
};

class Approximant {
 public:
  Approximant(const ParticleSet *ps, int method);
  Approximant(const ParticleSet *ps, const ApproxConfig &cfg);
  ApproxConfig config() const;
  const ParticleSet &particles() const { return *ps_; }
  const HVec<int64_t> &rowptr() const { return rowptr_; }
  const HVec<int32_t> &cols() const { return cols_; }
  const HVec<double> &values() const { return val_; }
  const HVec<double> &gradients() const { return grad_; }
  const HVec<double> &hessians() const { return hess_; }

  void set_kernel(int kernel, double param);
  void set_order(int order);
  void set_derivatives(int flags);
  void set_fallback(int policy);
  // Sites whose local system is worse conditioned than max_cond (condition estimate, as
  // site_cond reports it) get Shepard functions of the volume-weighted kernel instead,
  // with order 0 and their condition kept; the default, infinity, never does. (Moving
  // particles: a site in a thin sheet of particles is not singular, yet its gradients are
  // no use; paper 003 Sect. 6.)
  void set_shepard_condition(double max_cond);
  void set_points(int32_t npts, const double *x, int layout, int64_t ld, const double *h,
                  int64_t h_stride, int mem);
  // MPFEM (mpfem.cpp): the mesh, the derivative form and the edge-integral rule.
  void set_mesh(std::shared_ptr<const Mesh> mesh);
  void set_mpfem(int deriv, int ngauss);
  // True after an MPFEM setup whose supports satisfy 004 eq 13 (Kronecker delta).
  bool interpolating() const { return method_ == MFREE_METHOD_MPFEM && interpolating_; }

  // Throws MFREE_ERR_UNSUPPORTED when the tables of flags (MFREE_DERIV_*) of the method
  // and order need a derivative of the kernel that it does not have (linear, quadratic).
  static void check_kernel_use(int method, int kernel, int order, int flags);

  // Build pattern and tables (positive failures reported, negative ones thrown).
  Report setup();
  // Recompute tables on the existing pattern.
  Report update();

  bool is_setup() const { return setup_done_; }
  int method() const { return method_; }
  int dim() const { return ps_->dim(); }
  int32_t num_sites() const { return nsites_; }
  int64_t nnz() const { return static_cast<int64_t>(cols_.size()); }
  int flags() const { return flags_; }

  // out (+)= op(u); checks done by the caller (capi) except consistency of state.
  void apply(int op, int ncomp, const double *u, int ulayout, int64_t uld, double *out,
             int olayout, int64_t old, bool add) const;
  // Output components of op for ncomp input components (throws on misuse).
  int op_components(int op, int ncomp) const;

  void export_csr(int deriv, int component, int64_t *rowptr, int32_t *cols, double *vals) const;
  void check_reproduction(int order, double &fn_err, double &deriv_err) const;

  // Pair-list hosts (pairs.cpp). For every pair of the particle set's pair list, in its
  // order: the gradient of particle i's row at j and of j's row at i, per unit volume
  // (gi[k*ld + c], gj[k*ld + c]; gj may be NULL), or with antisym their antisymmetric
  // mean (gi only). The caller checks the buffers.
  void pair_gradients(double *gi, double *gj, int64_t ld, bool antisym) const;
  // Per-site correction data (layout in mfree.h): doubles per site, and the records.
  int correction_size() const;
  void correction(double *c, int64_t ld) const;
  // The ghosts' records (ghost g at c[g * ld], the layout of correction()), copied: the
  // ghost side of the pair gradients then comes from them until the next setup/update.
  void set_ghost_correction(const double *c, int64_t ld);

  const HVec<int32_t> &site_status() const { return status_; }
  const HVec<int32_t> &site_support() const { return support_; }
  const HVec<double> &site_cond() const { return cond_; }
  const HVec<int32_t> &site_order() const { return order_used_; }

 private:
  void validate_config() const;
  void build_pattern();
  // The pattern as a copy of the particle set's rows (src); false when they do not
  // qualify (a failed particle, a row without its site), and nothing is decided.
  bool share_rows(const Csr &src);
  // MFREE_ERR_ALLOC up front when a pattern of nnz entries and its tables would take
  // more than the machine's memory (alloc.hpp, request_too_large).
  void check_table_size(int64_t nnz) const;
  Report compute(const char *what);
  // compute's parts: the per-thread scratch of nt threads sized for the longest row; the
  // fast path's view of the tables and packed records; the general path (local.cpp) of
  // site s with its fallbacks and the Shepard rule (fast_done: the fast path's result
  // stands but for the rows), writing the site's rows, record (coef, ncoef doubles;
  // nullptr when not kept) and results; the message of the first failed site of nfailed.
  void reserve_scratch(int nt);
  FastTables fast_tables();
  struct SiteScratch;
  void general_site(int32_t s, const LocalConfig &base, bool fast_done, SiteScratch &w, double *coef,
                    int ncoef);
  void report_failures(int64_t nfailed, Report &rep) const;
  // Particle (and point) data as SoA arrays for the pattern and the fast path, re-read
  // from the (possibly borrowed) host arrays at every setup and update.
  void pack();
  Report compute_mpfem();
  // The data status of every particle now (ParticleSet::data_status) into pbad_: borrowed
  // data may have turned invalid since the set's last setup or update.
  void find_bad_particles();
  // Fail every site of [b, e) whose own data or a neighbour's is invalid now (with the
  // data's class) or whose row holds a non-finite value (MFREE_FAIL_NONFINITE), and zero
  // its row: a site reported valid holds finite values only. Returns how many sites of
  // the range failed in all. Needs find_bad_particles first.
  int64_t screen_sites(int64_t b, int64_t e);
  // The particle set's state this approximant was set up on (ghost count, rows); update
  // throws MFREE_ERR_STATE when the set was set up again since with other ones.
  void record_set_state();
  void check_set_unchanged();
  double site_x(int32_t s, int c) const;
  double site_h(int32_t s) const;
  int32_t site_particle(int32_t s) const { return points_ ? -1 : s; }
  void site_displacement(int32_t s, int32_t j, double *d) const;
  double pair_h(int32_t s, int32_t j) const;
  // the local solve's configuration for this approximant, with the outputs wanted
  LocalConfig local_config(bool value, bool grad, bool hess) const;
  // The general path's input of site s: displacements x_j - x_s (3 per neighbour),
  // volumes and pair supports of its row.
  void site_input(int32_t s, double *d, double *v, double *h) const;
  // Pair-list checks shared by pair_gradients and correction (pairs.cpp).
  void check_pairs_ready(const char *what) const;
  // pair_gradients' three ways (pair_gradients.cpp): SPH's kernel gradient where h_ij is
  // symmetric, the tables at the pair offsets, and the general case (records, lookups).
  void pair_gradients_sph(double *gi, double *gj, int64_t ld, bool antisym) const;
  void pair_gradients_direct(double *gi, double *gj, int64_t ld, bool antisym) const;
  void pair_gradients_general(double *gi, double *gj, int64_t ld, bool antisym) const;
  // grad_s W(x_s - x_j, h_sj) into g (3 doubles)
  void kernel_gradient(int32_t s, int32_t j, double *g) const;
  // The volumes of the last setup/update: particle j's is vol[j * stride].
  const double *packed_volumes(int64_t &stride) const;
  // Whether the method has correction data (correction_size() does not throw).
  bool has_correction() const;
  // Whether setup and update keep the sites' records (records_) for the pair gradients:
  // a pair-list set, a gradient table, a method with correction data.
  bool keeps_records() const;
  // The records of the sites (correction()) computed into c, every ld doubles; with
  // missing_only, only those whose first value is NaN (not written with the rows), and
  // zeros for failed or fallen-back sites.
  void compute_records(double *c, int64_t ld, bool missing_only = false) const;

  const ParticleSet *ps_;
  int method_;
  int kernel_id_ = MFREE_KERNEL_CUBIC_SPLINE;
  double kernel_param_ = 0.0;
  std::unique_ptr<Kernel> kernel_;
  int order_;
  int flags_ = MFREE_DERIV_VALUE | MFREE_DERIV_GRADIENT;
  int fallback_ = MFREE_FALLBACK_NONE;
  double shepard_cond_ = HUGE_VAL;
  std::shared_ptr<const Mesh> mesh_;
  int mpfem_deriv_ = MFREE_MPFEM_DERIV_FULL;
  int mpfem_ngauss_ = 8;
  bool interpolating_ = false;

  // host points (sites), when set
  bool points_ = false;
  int32_t npts_ = 0;
  VectorArray px_;
  ScalarArray ph_;
  Csr point_nbr_;  // neighbours of the points among the particles

  bool setup_done_ = false;
  int64_t set_setups_ = -1;  // the particle set's setup_count() the pattern was built on
  int32_t nsites_ = 0;
  // tables and per-site data come from the context's allocator hook (alloc.hpp)
  HVec<int64_t> rowptr_ = HVec<int64_t>(1, 0);
  int maxrow_ = 0;  // the longest row of the pattern
  HVec<int32_t> cols_;
  HVec<int32_t> self_;  // position of the site itself in its row, or -1
  HVec<double> val_, grad_, hess_;
  HVec<int32_t> status_, support_, order_used_;
  HVec<double> cond_;
  // per-thread row scratch (displacements, volumes, pair supports) and local work,
  // reused by every update
  struct SiteScratch {
    HVec<double> d, v, h;
    LocalWork work;
    FastScratch fast;
  };
  HVec<SiteScratch> scratch_;
  // AoS copies: particles (dim coordinates, volume, support; in 3D the supports after
  // 32-byte records x y z vol, see record_length in approximant_pack.hpp) and host points
  // (dim coordinates, support)
  HVec<double> pack_, spack_;
  HVec<int32_t> pbad_;  // find_bad_particles
  uint64_t set_rows_hash_ = 0;  // (with set_setups_: record_set_state)
  bool rows_shared_ = false;    // the pattern is a copy of the set's rows (share_rows)
  bool any_bad_ = true;         // some particle's data is invalid (find_bad_particles)
  // Correction records (pair-list sets): the sites' (empty when not kept) and the
  // ghosts' (set_ghost_correction; ghost_valid_ false for a record of zeros, a site that
  // failed at its owner, and for all after a setup/update).
  HVec<double> records_, ghost_records_;
  HVec<uint8_t> ghost_valid_;
  // per particle: 1 when its pair-gradient side comes from a record (records_ for the
  // owned ones, ghost_records_ for the ghosts), kept with them
  HVec<uint8_t> rec_ok_;
  bool ghost_set_ = false;
  int32_t set_owned_ = 0;
};

}  // namespace mfree
