// libmfree_mpi: migration of owned particles and their registered fields to new owners,
// decided by Zoltan's geometric partitioners (RCB, HSFC) or by the host. A plan call
// (partition or set_owners) fixes each particle's destination and exchanges the counts;
// execute moves the fields as packed records of raw bytes in one MPI_Alltoallv, in place.
// Every collective step agrees on its status first (collective.hpp).
#include "mfree_mpi.h"

#include "collective.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <new>
#include <string>
#include <vector>

#ifdef MFREE_MPI_WITH_ZOLTAN
#include <zoltan.h>
#endif

struct mfree_migration {
  mfree_context_t *ctx = nullptr;
  mfree_matrix_t *ctx_ref = nullptr;  // a 0 x 0 matrix: holds a reference on ctx
  MPI_Comm comm = MPI_COMM_NULL;      // the host's communicator, duplicated
  int rank = 0, size = 1, dim = 0;
  int32_t method = MFREE_PARTITIONER_RCB;
  double imbalance_tol = 1.05;
  mfree_mpi_detail::Pending pending;  // mfree_migration_set_pending_error
  struct Field {
    unsigned char *data;
    int64_t bytes, stride;
  };
  std::vector<Field> fields;
  // the plan
  bool planned = false;
  int32_t n_owned = 0, n_new = 0;
  int64_t n_send = 0, n_recv = 0;  // particles leaving and arriving
  std::vector<int32_t> dest;                        // destination of each owned particle
  std::vector<int> scount, sdispl, rcount, rdispl;  // particles per rank
  std::vector<unsigned char> sbuf, rbuf;
#ifdef MFREE_MPI_WITH_ZOLTAN
  struct Zoltan_Struct *zz = nullptr;
  bool has_regions = false;  // a rebalance succeeded with the current zz settings
  int32_t zz_method = 0;
  double zz_tol = 0;
  // the positions Zoltan's callbacks read during a partition call
  int32_t z_n = 0;
  const double *z_x = nullptr;
  int64_t z_ld = 0;
#endif
};

namespace {

using namespace mfree_mpi_detail;

mfree_status_t agree(mfree_migration_t *m, const char *fn, const Local &l, Loc *vals = nullptr,
                     int nv = 0) noexcept {
  return mfree_mpi_detail::agree(m->ctx, m->comm, m->rank, fn, l, vals, nv);
}

// A collective call's local step: a failure handed over by
// mfree_migration_set_pending_error, else body's outcome.
template <class Body>
Local first_step(mfree_migration_t *m, Body &&body) noexcept {
  return m->pending.first_step(body);
}

#ifdef MFREE_MPI_WITH_ZOLTAN
// Zoltan's callbacks over the owned particles: global ids (rank, index) in two entries
// (unique whatever the host's ids; ZOLTAN_ID_TYPE may be 32 bits), local ids the index.
int z_num_obj(void *data, int *ierr) {
  *ierr = ZOLTAN_OK;
  return static_cast<mfree_migration_t *>(data)->z_n;
}

void z_obj_list(void *data, int, int, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids, int, float *, int *ierr) {
  const mfree_migration_t *m = static_cast<mfree_migration_t *>(data);
  for (int32_t k = 0; k < m->z_n; ++k) {
    gids[2 * k] = static_cast<ZOLTAN_ID_TYPE>(m->rank);
    gids[2 * k + 1] = static_cast<ZOLTAN_ID_TYPE>(k);
    lids[k] = static_cast<ZOLTAN_ID_TYPE>(k);
  }
  *ierr = ZOLTAN_OK;
}

int z_num_geom(void *data, int *ierr) {
  *ierr = ZOLTAN_OK;
  return static_cast<mfree_migration_t *>(data)->dim;
}

void z_geom(void *data, int, int, int nobj, ZOLTAN_ID_PTR, ZOLTAN_ID_PTR lids, int ndim, double *g, int *ierr) {
  const mfree_migration_t *m = static_cast<mfree_migration_t *>(data);
  for (int k = 0; k < nobj; ++k)
    for (int d = 0; d < ndim; ++d) g[k * ndim + d] = m->z_x[static_cast<int64_t>(lids[k]) * m->z_ld + d];
  *ierr = ZOLTAN_OK;
}

void free_zoltan(mfree_migration_t *m) {
  if (m->zz) Zoltan_Destroy(&m->zz);
  m->zz = nullptr;
  m->has_regions = false;
}

// A Zoltan structure for the chosen method, made (collectively) when there is none or the
// method or tolerance changed; KEEP_CUTS so that later calls can assign points to regions.
void make_zoltan(mfree_migration_t *m, Local &r) {
  if (m->zz && m->zz_method == m->method && m->zz_tol == m->imbalance_tol) return;
  free_zoltan(m);
  m->zz = Zoltan_Create(m->comm);
  if (!m->zz) return r.fail(MFREE_ERR_ALLOC, "Zoltan_Create failed");
  char tol[32];
  std::snprintf(tol, sizeof tol, "%.17g", m->imbalance_tol);
  const char *params[][2] = {{"DEBUG_LEVEL", "0"},
                             {"LB_METHOD", m->method == MFREE_PARTITIONER_HSFC ? "HSFC" : "RCB"},
                             {"NUM_GID_ENTRIES", "2"},
                             {"NUM_LID_ENTRIES", "1"},
                             {"OBJ_WEIGHT_DIM", "0"},
                             {"RETURN_LISTS", "EXPORT"},
                             {"KEEP_CUTS", "1"},
                             {"IMBALANCE_TOL", tol}};
  for (auto &p : params)
    if (Zoltan_Set_Param(m->zz, p[0], p[1]) != ZOLTAN_OK)
      return r.fail(MFREE_ERR_INTERNAL, std::string("Zoltan_Set_Param ") + p[0] + " failed");
  Zoltan_Set_Num_Obj_Fn(m->zz, z_num_obj, m);
  Zoltan_Set_Obj_List_Fn(m->zz, z_obj_list, m);
  Zoltan_Set_Num_Geom_Fn(m->zz, z_num_geom, m);
  Zoltan_Set_Geom_Multi_Fn(m->zz, z_geom, m);
  m->zz_method = m->method;
  m->zz_tol = m->imbalance_tol;
}
#endif

// The plan's counts from m->dest: an MPI_Alltoall of the per-rank counts, then n_new.
void plan_counts(mfree_migration_t *m, Local &r) {
  const int P = m->size;
  m->scount.assign(P, 0);
  m->rcount.assign(P, 0);
  m->sdispl.assign(P, 0);
  m->rdispl.assign(P, 0);
  for (int32_t i = 0; i < m->n_owned; ++i) ++m->scount[m->dest[i]];
  mpi_ok(r, MPI_Alltoall(m->scount.data(), 1, MPI_INT, m->rcount.data(), 1, MPI_INT, m->comm), "MPI_Alltoall");
  if (r.st) return;
  // the records this rank keeps are not sent: the send and receive lists skip it
  const int32_t kept = m->scount[m->rank];
  m->scount[m->rank] = 0;
  m->rcount[m->rank] = 0;
  int64_t s = 0, n = kept;
  for (int p = 0; p < P; ++p) {
    m->sdispl[p] = static_cast<int>(s);
    m->rdispl[p] = static_cast<int>(n - kept);
    s += m->scount[p];
    n += m->rcount[p];
  }
  if (n > std::numeric_limits<int32_t>::max())
    return r.fail(MFREE_ERR_ARG, "the migration would leave " + std::to_string(n) +
                                     " particles on this rank (more than 2^31 - 1)");
  m->n_new = static_cast<int32_t>(n);
  m->n_send = s;
  m->n_recv = n - kept;
}

// The end of a plan call: the counts, agreed; the plan ready for execute.
mfree_status_t finish_plan(mfree_migration_t *m, const char *fn, int32_t *n_new) noexcept {
  const Local l = run_local([&](Local &r) { plan_counts(m, r); });
  const mfree_status_t st = agree(m, fn, l);
  if (st != MFREE_SUCCESS) return st;
  m->planned = true;
  if (n_new) *n_new = m->n_new;
  return MFREE_SUCCESS;
}

}  // namespace

extern "C" {

mfree_status_t mfree_migration_create(mfree_context_t *ctx, MPI_Comm comm, int32_t dim,
                                      mfree_migration_t **migration) {
  const char *fn = "mfree_migration_create";
  if (!ctx) return MFREE_ERR_NULL;
  if (!migration) return record(ctx, MFREE_ERR_NULL, fn, "output pointer is NULL");
  *migration = nullptr;
  if (comm == MPI_COMM_NULL) return record(ctx, MFREE_ERR_ARG, fn, "communicator is MPI_COMM_NULL");
  mfree_migration_t *m = new (std::nothrow) mfree_migration_t;
  if (!m) return record(ctx, MFREE_ERR_ALLOC, fn, "out of memory");
  m->ctx = ctx;
  m->dim = dim;
  if (MPI_Comm_dup(comm, &m->comm) != MPI_SUCCESS) {
    delete m;
    return record(ctx, MFREE_ERR_INTERNAL, fn, "MPI_Comm_dup failed");
  }
  MPI_Comm_set_errhandler(m->comm, MPI_ERRORS_RETURN);
  MPI_Comm_rank(m->comm, &m->rank);
  MPI_Comm_size(m->comm, &m->size);
  Local l = run_local([&](Local &r) {
    if (dim < 1 || dim > 3) r.fail(MFREE_ERR_ARG, "dimension " + std::to_string(dim) + " is not 1, 2 or 3");
  });
  if (l.st == MFREE_SUCCESS) {
    // The ABI has no context retain: an empty matrix on ctx keeps it alive for us.
    int64_t zero = 0;
    const mfree_status_t st = mfree_matrix_create_csr(ctx, 0, 0, &zero, nullptr, nullptr, &m->ctx_ref);
    if (st != MFREE_SUCCESS) l.fail(st, "cannot hold the context");
  }
#ifdef MFREE_MPI_WITH_ZOLTAN
  if (l.st == MFREE_SUCCESS) {
    float version = 0;
    if (Zoltan_Initialize(0, nullptr, &version) != ZOLTAN_OK) l.fail(MFREE_ERR_INTERNAL, "Zoltan_Initialize failed");
  }
#endif
  Loc dims[2] = {{static_cast<double>(dim), 0}, {-static_cast<double>(dim), 0}};
  mfree_status_t st = agree(m, fn, l, dims, 2);
  if (st == MFREE_SUCCESS) st = same_everywhere(m->ctx, fn, "the dimension", dims[0], dims[1]);
  if (st != MFREE_SUCCESS) {
    mfree_migration_destroy(&m);
    return st;
  }
  *migration = m;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_migration_create_f(mfree_context_t *ctx, int32_t fcomm, int32_t dim,
                                        mfree_migration_t **migration) {
  return mfree_migration_create(ctx, MPI_Comm_f2c(static_cast<MPI_Fint>(fcomm)), dim, migration);
}

mfree_status_t mfree_migration_destroy(mfree_migration_t **migration) {
  if (!migration || !*migration) return MFREE_SUCCESS;
  mfree_migration_t *m = *migration;
  // After MPI_Finalize the communicators (ours and Zoltan's duplicate) went with MPI and
  // freeing them is erroneous: only the memory is left to free.
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) {
#ifdef MFREE_MPI_WITH_ZOLTAN
    free_zoltan(m);
#endif
    if (m->comm != MPI_COMM_NULL) MPI_Comm_free(&m->comm);
  }
  mfree_matrix_t *ref = m->ctx_ref;
  delete m;
  mfree_matrix_destroy(&ref);
  *migration = nullptr;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_migration_set_partitioner(mfree_migration_t *m, int32_t method, double imbalance_tol) {
  const char *fn = "mfree_migration_set_partitioner";
  if (!m) return MFREE_ERR_NULL;
  if (method != MFREE_PARTITIONER_RCB && method != MFREE_PARTITIONER_HSFC) {
    char text[96];
    std::snprintf(text, sizeof text, "unknown partitioner %d (MFREE_PARTITIONER_RCB or _HSFC)", method);
    return record(m->ctx, MFREE_ERR_ARG, fn, text);
  }
  if (!(imbalance_tol >= 1.0 && imbalance_tol <= 10.0)) {
    char text[96];
    std::snprintf(text, sizeof text, "imbalance tolerance %g is not in [1, 10]", imbalance_tol);
    return record(m->ctx, MFREE_ERR_ARG, fn, text);
  }
  m->method = method;
  m->imbalance_tol = imbalance_tol;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_migration_add_field(mfree_migration_t *m, void *data, int64_t item_bytes,
                                         int64_t stride_bytes) {
  const char *fn = "mfree_migration_add_field";
  if (!m) return MFREE_ERR_NULL;
  if (item_bytes < 1 || stride_bytes < item_bytes) {
    char text[128];
    std::snprintf(text, sizeof text, "item_bytes %lld must be >= 1 and stride_bytes %lld >= item_bytes",
                  static_cast<long long>(item_bytes), static_cast<long long>(stride_bytes));
    return record(m->ctx, MFREE_ERR_ARG, fn, text);
  }
  try {
    m->fields.push_back({static_cast<unsigned char *>(data), item_bytes, stride_bytes});
  } catch (...) {
    return record(m->ctx, MFREE_ERR_ALLOC, fn, "out of memory");
  }
  return MFREE_SUCCESS;
}

mfree_status_t mfree_migration_clear_fields(mfree_migration_t *m) {
  if (!m) return MFREE_ERR_NULL;
  m->fields.clear();
  return MFREE_SUCCESS;
}

mfree_status_t mfree_migration_partition(mfree_migration_t *m, int32_t n_owned, const double *x, int64_t ld,
                                         int32_t rebalance, int32_t *n_new) {
  const char *fn = "mfree_migration_partition";
  if (!m) return MFREE_ERR_NULL;
  m->planned = false;
  const int dim = m->dim;
  // 1. arguments
  Local l = first_step(m, [&](Local &r) {
    if (n_owned < 0) return r.fail(MFREE_ERR_ARG, "n_owned " + std::to_string(n_owned) + " is negative");
    if (ld < dim) return r.fail(MFREE_ERR_ARG, "leading dimension " + std::to_string(ld) + " is below dim");
    if (rebalance != 0 && rebalance != 1)
      return r.fail(MFREE_ERR_ARG, "rebalance must be 0 or 1, got " + std::to_string(rebalance));
    if (n_owned > 0 && !x) return r.fail(MFREE_ERR_NULL, "positions pointer is NULL");
    for (int32_t i = 0; i < n_owned; ++i)
      for (int c = 0; c < dim; ++c)
        if (!std::isfinite(x[i * ld + c]))
          return r.fail(MFREE_ERR_INPUT, "position of particle " + std::to_string(i) + ", component " +
                                             std::to_string(c) + " is not finite");
#ifndef MFREE_MPI_WITH_ZOLTAN
    r.fail(MFREE_ERR_UNSUPPORTED, "libmfree_mpi was built without Zoltan (use mfree_migration_set_owners)");
#endif
  });
  // agreed with the status: the method, the tolerance and rebalance (Zoltan's partition is
  // collective, its point assignment local: all ranks must take the same path)
  Loc v[6] = {{static_cast<double>(m->method), 0}, {-static_cast<double>(m->method), 0},
              {m->imbalance_tol, 0},               {-m->imbalance_tol, 0},
              {static_cast<double>(rebalance), 0}, {-static_cast<double>(rebalance), 0}};
  mfree_status_t st = agree(m, fn, l, v, 6);
  if (st == MFREE_SUCCESS) st = same_everywhere(m->ctx, fn, "the partitioner", v[0], v[1]);
  if (st == MFREE_SUCCESS) st = same_everywhere(m->ctx, fn, "the imbalance tolerance", v[2], v[3]);
  if (st == MFREE_SUCCESS) st = same_everywhere(m->ctx, fn, "rebalance", v[4], v[5]);
  if (st != MFREE_SUCCESS) return st;

#ifdef MFREE_MPI_WITH_ZOLTAN
  // 2. destinations: Zoltan's new regions (collective), or the kept regions' owners
  bool whole = rebalance == 1;
  l = run_local([&](Local &r) {
    make_zoltan(m, r);
    if (r.st) return;
    whole = whole || !m->has_regions;
    m->n_owned = n_owned;
    m->dest.assign(static_cast<size_t>(n_owned), m->rank);
    if (!whole) {
      for (int32_t i = 0; i < n_owned; ++i) {
        double p[3] = {0, 0, 0};
        for (int c = 0; c < dim; ++c) p[c] = x[i * ld + c];
        int proc = -1;
        if (Zoltan_LB_Point_Assign(m->zz, p, &proc) != ZOLTAN_OK || proc < 0 || proc >= m->size)
          return r.fail(MFREE_ERR_INTERNAL, "Zoltan_LB_Point_Assign failed");
        m->dest[i] = proc;
      }
    }
  });
  // (whole is the same on every rank: rebalance is, and has_regions changes collectively)
  st = agree(m, fn, l);
  if (st != MFREE_SUCCESS) return st;
  if (whole) {
    l = run_local([&](Local &r) {
      m->has_regions = false;
      m->z_n = n_owned;
      m->z_x = x;
      m->z_ld = ld;
      int changes = 0, ngid = 0, nlid = 0, nimp = 0, nexp = 0;
      int *iproc = nullptr, *ipart = nullptr, *eproc = nullptr, *epart = nullptr;
      ZOLTAN_ID_PTR igid = nullptr, ilid = nullptr, egid = nullptr, elid = nullptr;
      const int rc = Zoltan_LB_Partition(m->zz, &changes, &ngid, &nlid, &nimp, &igid, &ilid, &iproc, &ipart,
                                         &nexp, &egid, &elid, &eproc, &epart);
      m->z_x = nullptr;
      if (rc == ZOLTAN_OK || rc == ZOLTAN_WARN) {
        for (int k = 0; k < nexp; ++k) {
          const int64_t i = static_cast<int64_t>(elid[k]);
          if (i < 0 || i >= n_owned || eproc[k] < 0 || eproc[k] >= m->size) {
            r.fail(MFREE_ERR_INTERNAL, "Zoltan_LB_Partition exported an unknown particle or to an unknown rank");
            break;
          }
          m->dest[i] = eproc[k];
        }
      } else {
        r.fail(rc == ZOLTAN_MEMERR ? MFREE_ERR_ALLOC : MFREE_ERR_INTERNAL, "Zoltan_LB_Partition failed");
      }
      Zoltan_LB_Free_Part(&igid, &ilid, &iproc, &ipart);
      Zoltan_LB_Free_Part(&egid, &elid, &eproc, &epart);
    });
    st = agree(m, fn, l);
    if (st != MFREE_SUCCESS) return st;
    m->has_regions = true;
  }
#endif
  // 3. counts
  return finish_plan(m, fn, n_new);
}

mfree_status_t mfree_migration_set_owners(mfree_migration_t *m, int32_t n_owned, const int32_t *owners,
                                          int32_t *n_new) {
  const char *fn = "mfree_migration_set_owners";
  if (!m) return MFREE_ERR_NULL;
  m->planned = false;
  Local l = first_step(m, [&](Local &r) {
    if (n_owned < 0) return r.fail(MFREE_ERR_ARG, "n_owned " + std::to_string(n_owned) + " is negative");
    if (n_owned > 0 && !owners) return r.fail(MFREE_ERR_NULL, "owners pointer is NULL");
    for (int32_t i = 0; i < n_owned; ++i)
      if (owners[i] < 0 || owners[i] >= m->size)
        return r.fail(MFREE_ERR_INPUT, "owner of particle " + std::to_string(i) + " is rank " +
                                           std::to_string(owners[i]) + ", not in [0, " + std::to_string(m->size) +
                                           ")");
    m->n_owned = n_owned;
    m->dest.assign(owners, owners + n_owned);
  });
  mfree_status_t st = agree(m, fn, l);
  if (st != MFREE_SUCCESS) return st;
  return finish_plan(m, fn, n_new);
}

mfree_status_t mfree_migration_execute(mfree_migration_t *m, int32_t capacity) {
  const char *fn = "mfree_migration_execute";
  if (!m) return MFREE_ERR_NULL;
  // 1. checks and the layout of the registered fields, agreed: their number, the bytes of
  // a record and a signature of the item sizes in order (different layouts would
  // misread each other's records)
  // (the signature: a 64-bit FNV-1a hash of the sizes, cut to 52 bits, exact in a double)
  int64_t rec = 0;
  uint64_t hash = 14695981039346656037ULL;
  for (const auto &f : m->fields) {
    rec += f.bytes;
    for (int b = 0; b < 64; b += 8) hash = (hash ^ ((static_cast<uint64_t>(f.bytes) >> b) & 0xff)) * 1099511628211ULL;
  }
  const double sig = static_cast<double>(hash >> 12);
  Local l = first_step(m, [&](Local &r) {
    if (!m->planned)
      return r.fail(MFREE_ERR_STATE, "no plan to execute (call mfree_migration_partition or _set_owners first)");
    if (capacity < m->n_new)
      return r.fail(MFREE_ERR_ARG, "capacity " + std::to_string(capacity) + " is below the " +
                                       std::to_string(m->n_new) + " particles this rank owns after the migration");
    // (the arrays hold the owned particles the plan moves: a capacity below their count
    // would be read past)
    if (capacity < m->n_owned)
      return r.fail(MFREE_ERR_ARG, "capacity " + std::to_string(capacity) + " is below the " +
                                       std::to_string(m->n_owned) + " owned particles the plan moves");
    for (size_t f = 0; f < m->fields.size(); ++f)
      if (!m->fields[f].data && capacity > 0)
        return r.fail(MFREE_ERR_NULL, "field " + std::to_string(f) + " has no data");
    if (rec > std::numeric_limits<int>::max()) return r.fail(MFREE_ERR_ARG, "a record exceeds 2^31 - 1 bytes");
    m->sbuf.resize(static_cast<size_t>(m->n_send) * static_cast<size_t>(rec));
    m->rbuf.resize(static_cast<size_t>(m->n_recv) * static_cast<size_t>(rec));
  });
  const double nf = static_cast<double>(m->fields.size());
  Loc v[6] = {{nf, 0}, {-nf, 0}, {static_cast<double>(rec), 0}, {-static_cast<double>(rec), 0}, {sig, 0}, {-sig, 0}};
  mfree_status_t st = agree(m, fn, l, v, 6);
  if (st == MFREE_SUCCESS && (v[0].v != -v[1].v || v[2].v != -v[3].v || v[4].v != -v[5].v)) {
    char text[256];
    const bool count = v[0].v != -v[1].v;
    const Loc &a = count ? v[0] : v[2].v != -v[3].v ? v[2] : v[4], &b = count ? v[1] : v[2].v != -v[3].v ? v[3] : v[5];
    std::snprintf(text, sizeof text,
                  "ranks disagree on the registered fields: ranks %d and %d register %s (every rank registers the "
                  "same item sizes in the same order)",
                  a.r, b.r,
                  count ? "different numbers of fields" : v[2].v != -v[3].v ? "records of different sizes"
                                                                           : "items of different sizes");
    st = record(m->ctx, MFREE_ERR_ARG, fn, text);
  }
  if (st != MFREE_SUCCESS) return st;

  // 2. pack the leaving particles by destination, exchange, then keep and unpack in place
  const int P = m->size;
  std::vector<int> pos(m->sdispl);
  for (int32_t i = 0; i < m->n_owned; ++i) {
    const int d = m->dest[i];
    if (d == m->rank) continue;
    unsigned char *out = m->sbuf.data() + static_cast<size_t>(pos[d]++) * static_cast<size_t>(rec);
    for (const auto &f : m->fields) {
      std::memcpy(out, f.data + i * f.stride, static_cast<size_t>(f.bytes));
      out += f.bytes;
    }
  }
  l = run_local([&](Local &r) {
    if (rec == 0) return;
    MPI_Datatype type;
    mpi_ok(r, MPI_Type_contiguous(static_cast<int>(rec), MPI_BYTE, &type), "MPI_Type_contiguous");
    if (r.st) return;
    mpi_ok(r, MPI_Type_commit(&type), "MPI_Type_commit");
    if (!r.st)
      mpi_ok(r, MPI_Alltoallv(m->sbuf.data(), m->scount.data(), m->sdispl.data(), type, m->rbuf.data(),
                              m->rcount.data(), m->rdispl.data(), type, m->comm),
             "MPI_Alltoallv");
    MPI_Type_free(&type);
  });
  st = agree(m, fn, l);
  if (st != MFREE_SUCCESS) return st;
  int32_t k = 0;
  for (int32_t i = 0; i < m->n_owned; ++i) {
    if (m->dest[i] != m->rank) continue;
    if (k != i)
      for (const auto &f : m->fields) std::memmove(f.data + k * f.stride, f.data + i * f.stride, static_cast<size_t>(f.bytes));
    ++k;
  }
  const unsigned char *in = m->rbuf.data();
  for (int p = 0; p < P; ++p)
    for (int q = 0; q < m->rcount[p]; ++q, ++k)
      for (const auto &f : m->fields) {
        std::memcpy(f.data + k * f.stride, in, static_cast<size_t>(f.bytes));
        in += f.bytes;
      }
  m->planned = false;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_migration_get_counts(const mfree_migration_t *m, int32_t *n_owned, int32_t *n_new,
                                          int64_t *n_send, int64_t *n_recv) {
  if (!m) return MFREE_ERR_NULL;
  if (!m->planned)
    return record(m->ctx, MFREE_ERR_STATE, "mfree_migration_get_counts", "no plan (or executed already)");
  if (n_owned) *n_owned = m->n_owned;
  if (n_new) *n_new = m->n_new;
  if (n_send) *n_send = m->n_send;
  if (n_recv) *n_recv = m->n_recv;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_migration_get_owners(const mfree_migration_t *m, int32_t *owners, int64_t capacity) {
  const char *fn = "mfree_migration_get_owners";
  if (!m) return MFREE_ERR_NULL;
  if (!m->planned) return record(m->ctx, MFREE_ERR_STATE, fn, "no plan (or executed already)");
  if (capacity < m->n_owned) {
    char text[128];
    std::snprintf(text, sizeof text, "capacity %lld is below the plan's %d owned particles",
                  static_cast<long long>(capacity), m->n_owned);
    return record(m->ctx, MFREE_ERR_ARG, fn, text);
  }
  if (!owners && m->n_owned > 0) return record(m->ctx, MFREE_ERR_NULL, fn, "output pointer is NULL");
  std::copy(m->dest.begin(), m->dest.end(), owners);
  return MFREE_SUCCESS;
}

mfree_status_t mfree_migration_get_context(const mfree_migration_t *m, mfree_context_t **ctx) {
  if (!m || !ctx) return MFREE_ERR_NULL;
  *ctx = m->ctx;
  return MFREE_SUCCESS;
}

mfree_status_t mfree_migration_set_pending_error(mfree_migration_t *m) {
  if (!m) return MFREE_ERR_NULL;
  return m->pending.take_from(m->ctx, "mfree_migration_set_pending_error");
}

}  // extern "C"
