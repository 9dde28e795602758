// Cell-list neighbour search with variable support, three conventions, periodic axes.
//
// Cells have edge c >= the mean search radius; a query with radius R scans the cells
// within R (gather: kappa h_i; symmetric-max: kappa max_j h_j, filtered by
// max(h_i, h_j); symmetric-mean: kappa (h_i + max h)/2, filtered by the mean), so
// uniform supports cost a 3^dim stencil and strongly variable ones stay correct. The
// same grid answers queries from the particles themselves and from host points.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "approximant.hpp"
#include "kernel.hpp"
#include "particles.hpp"

namespace mfree {

namespace {

class CellGrid {
 public:
  CellGrid(const ParticleSet &ps, const std::vector<int32_t> &status);

  bool empty() const { return valid_.empty(); }
  double rmax() const { return rmax_; }
  double radius(int32_t j) const { return rad_[j]; }

  // Wrap a coordinate into the periodic box along periodic axes.
  double wrap(double x, int c) const {
    if (!periodic_[c]) return x;
    return x - L_[c] * std::floor((x - lo_[c]) / L_[c]);
  }

  // Append to row every valid particle j with squared distance to xq (wrapped) below
  // lim(j)^2 among those within R of xq.
  template <class Limit>
  void query(const double *xq, double R, Limit &&lim, std::vector<int32_t> &row) const;

 private:
  int64_t coord(double x, int c) const {
    int64_t k = static_cast<int64_t>(std::floor((x - lo_[c]) / cell_[c]));
    if (periodic_[c]) {
      k %= nc_[c];
      if (k < 0) k += nc_[c];
    } else {
      k = std::min<int64_t>(std::max<int64_t>(k, 0), nc_[c] - 1);
    }
    return k;
  }
  int64_t index(const int64_t *k) const {
    int64_t id = 0;
    for (int c = dim_ - 1; c >= 0; --c) id = id * nc_[c] + k[c];
    return id;
  }

  int dim_;
  double lo_[3] = {0, 0, 0}, cell_[3] = {1, 1, 1}, L_[3] = {0, 0, 0};
  int64_t nc_[3] = {1, 1, 1};
  bool periodic_[3] = {false, false, false};
  double rmax_ = 0.0;
  std::vector<double> xs_, rad_;
  std::vector<int32_t> valid_, members_;
  std::vector<int64_t> start_;
};

CellGrid::CellGrid(const ParticleSet &ps, const std::vector<int32_t> &status) : dim_(ps.dim()) {
  const int32_t n = ps.size();
  const double kappa = ps.kappa();
  for (int c = 0; c < dim_; ++c) {
    periodic_[c] = ps.periodic(c);
    if (periodic_[c]) {
      lo_[c] = ps.box_lo(c);
      L_[c] = ps.box_hi(c) - ps.box_lo(c);
    }
  }
  xs_.assign(static_cast<size_t>(n) * 3, 0.0);
  rad_.assign(n, 0.0);
  valid_.reserve(n);
  double rsum = 0.0, bmin[3] = {0, 0, 0}, bmax[3] = {0, 0, 0};
  for (int32_t i = 0; i < n; ++i) {
    if (status[i] != 0) continue;
    rad_[i] = kappa * ps.h(i);
    rmax_ = std::max(rmax_, rad_[i]);
    rsum += rad_[i];
    for (int c = 0; c < dim_; ++c) {
      const double x = wrap(ps.x(i, c), c);
      xs_[static_cast<size_t>(i) * 3 + c] = x;
      if (valid_.empty() || x < bmin[c]) bmin[c] = x;
      if (valid_.empty() || x > bmax[c]) bmax[c] = x;
    }
    valid_.push_back(i);
  }
  if (valid_.empty()) return;

  for (int c = 0; c < dim_; ++c)
    if (periodic_[c] && 2.0 * rmax_ >= L_[c]) {
      std::ostringstream s;
      s << "support radius kappa*h = " << rmax_ << " is not below half the periodic box length "
        << L_[c] << " on axis " << c;
      throw Error(MFREE_ERR_INPUT, s.str());
    }

  // Cell edge: the mean radius, enlarged so that the grid has at most ~4 cells per
  // particle (clustered or far-flung particles would otherwise make it huge). Enlarge
  // until the grid fits (one particle at 1e15 needs more than 64 steps); an extent whose
  // cell count is not a finite double gets one cell, which is always correct because
  // coordinates are clamped into the grid, and never reaches an out-of-range cast.
  double edge = rsum / static_cast<double>(valid_.size());
  const double max_cells = 4.0 * static_cast<double>(valid_.size()) + 64.0;
  auto span = [&edge](double ext) {
    const double k = std::floor(ext / edge);
    return std::isfinite(k) ? k : 0.0;
  };
  for (;;) {
    double total = 1.0;
    for (int c = 0; c < dim_; ++c) {
      const double ext = periodic_[c] ? L_[c] : bmax[c] - bmin[c];
      total *= std::max(1.0, span(ext));
    }
    if (total <= max_cells) break;
    edge *= 1.5;
  }
  for (int c = 0; c < dim_; ++c) {
    if (periodic_[c]) {
      nc_[c] = std::max<int64_t>(1, static_cast<int64_t>(span(L_[c])));
      cell_[c] = L_[c] / static_cast<double>(nc_[c]);
    } else {
      lo_[c] = bmin[c];
      nc_[c] = static_cast<int64_t>(span(bmax[c] - bmin[c])) + 1;
      cell_[c] = edge;
    }
  }
  int64_t ncells = 1;
  for (int c = 0; c < dim_; ++c) ncells *= nc_[c];

  // Counting sort of the valid particles by cell (stable: ascending index in a cell).
  std::vector<int64_t> cell_of(n, -1);
  start_.assign(static_cast<size_t>(ncells) + 1, 0);
  for (int32_t i : valid_) {
    int64_t k[3] = {0, 0, 0};
    for (int c = 0; c < dim_; ++c) k[c] = coord(xs_[static_cast<size_t>(i) * 3 + c], c);
    cell_of[i] = index(k);
    ++start_[cell_of[i] + 1];
  }
  for (int64_t c = 0; c < ncells; ++c) start_[c + 1] += start_[c];
  members_.resize(valid_.size());
  std::vector<int64_t> fill(start_.begin(), start_.end() - 1);
  for (int32_t i : valid_) members_[fill[cell_of[i]]++] = i;
}

template <class Limit>
void CellGrid::query(const double *xq, double R, Limit &&lim, std::vector<int32_t> &row) const {
  if (valid_.empty()) return;
  // Cell ranges per axis: [k - m, k + m], clamped, or all cells once on a periodic axis
  // where the stencil would wrap onto itself.
  int64_t kmin[3] = {0, 0, 0}, kmax[3] = {0, 0, 0};
  for (int c = 0; c < dim_; ++c) {
    const int64_t kc = coord(xq[c], c);
    const int64_t m = static_cast<int64_t>(std::ceil(R / cell_[c]));
    if (periodic_[c] && 2 * m + 1 >= nc_[c]) {
      kmin[c] = 0;
      kmax[c] = nc_[c] - 1;
    } else if (periodic_[c]) {
      kmin[c] = kc - m;
      kmax[c] = kc + m;
    } else {
      kmin[c] = std::max<int64_t>(0, kc - m);
      kmax[c] = std::min<int64_t>(nc_[c] - 1, kc + m);
    }
  }
  int64_t k[3];
  for (k[2] = kmin[2]; k[2] <= kmax[2]; ++k[2])
    for (k[1] = kmin[1]; k[1] <= kmax[1]; ++k[1])
      for (k[0] = kmin[0]; k[0] <= kmax[0]; ++k[0]) {
        int64_t kw[3] = {k[0], k[1], k[2]};
        for (int c = 0; c < dim_; ++c)
          if (periodic_[c]) kw[c] = ((kw[c] % nc_[c]) + nc_[c]) % nc_[c];
        const int64_t cell = index(kw);
        for (int64_t p = start_[cell]; p < start_[cell + 1]; ++p) {
          const int32_t j = members_[p];
          const double *xj = &xs_[static_cast<size_t>(j) * 3];
          double d2 = 0.0;
          for (int c = 0; c < dim_; ++c) {
            double d = xq[c] - xj[c];
            if (periodic_[c]) d -= L_[c] * std::nearbyint(d / L_[c]);
            d2 += d * d;
          }
          const double l = lim(j);
          if (d2 <= l * l * (1.0 + kEdgeTol2)) row.push_back(j);
        }
      }
}

// Query radius and pair limit of a site with search radius ri under the convention.
struct Rule {
  int conv;
  double rmax;
  double query(double ri) const {
    return conv == MFREE_SEARCH_GATHER ? ri : conv == MFREE_SEARCH_SYMMETRIC_MAX ? rmax : 0.5 * (ri + rmax);
  }
  double limit(double ri, double rj) const {
    return conv == MFREE_SEARCH_GATHER ? ri : conv == MFREE_SEARCH_SYMMETRIC_MAX ? std::max(ri, rj) : 0.5 * (ri + rj);
  }
};

}  // namespace

void find_neighbors(const ParticleSet &ps, const std::vector<int32_t> &status, Csr &out) {
  const int32_t rows = ps.num_owned();
  out.rowptr.assign(static_cast<size_t>(rows) + 1, 0);
  out.cols.clear();
  const CellGrid grid(ps, status);
  const Rule rule{ps.search_convention(), grid.rmax()};
  std::vector<int32_t> row;
  for (int32_t i = 0; i < rows; ++i) {
    if (status[i] == 0 && !grid.empty()) {
      double xi[3] = {0, 0, 0};
      for (int c = 0; c < ps.dim(); ++c) xi[c] = grid.wrap(ps.x(i, c), c);
      const double ri = grid.radius(i);
      row.clear();
      grid.query(xi, rule.query(ri), [&](int32_t j) { return rule.limit(ri, grid.radius(j)); }, row);
      std::sort(row.begin(), row.end());
      out.cols.insert(out.cols.end(), row.begin(), row.end());
    }
    out.rowptr[i + 1] = static_cast<int64_t>(out.cols.size());
  }
}

void find_point_neighbors(const ParticleSet &ps, const std::vector<int32_t> &status, int32_t npts,
                          const VectorArray &x, const ScalarArray &h, Csr &out) {
  out.rowptr.assign(static_cast<size_t>(npts) + 1, 0);
  out.cols.clear();
  const CellGrid grid(ps, status);
  const Rule rule{ps.search_convention(), grid.rmax()};
  std::vector<int32_t> row;
  for (int32_t s = 0; s < npts; ++s) {
    double xs[3] = {0, 0, 0};
    for (int c = 0; c < ps.dim(); ++c) xs[c] = grid.wrap(x(s, c), c);
    const double rs = ps.kappa() * h(s);
    row.clear();
    grid.query(xs, rule.query(rs), [&](int32_t j) { return rule.limit(rs, grid.radius(j)); }, row);
    std::sort(row.begin(), row.end());
    out.cols.insert(out.cols.end(), row.begin(), row.end());
    out.rowptr[s + 1] = static_cast<int64_t>(out.cols.size());
  }
}

}  // namespace mfree
