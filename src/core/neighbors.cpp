// Cell-list neighbour search with variable support, three conventions, periodic axes.
//
// Cells have edge c >= the mean search radius; particle i scans the cells within its
// own query radius R_i (gather: kappa h_i; symmetric-max: kappa max_j h_j, filtered by
// max(h_i, h_j); symmetric-mean: kappa (h_i + max h)/2, filtered by the mean), so
// uniform supports cost a 3^dim stencil and strongly variable ones stay correct.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "particles.hpp"

namespace mfree {

namespace {

struct Grid {
  int dim = 1;
  double lo[3] = {0, 0, 0};
  double cell[3] = {1, 1, 1};
  int64_t nc[3] = {1, 1, 1};
  bool periodic[3] = {false, false, false};

  int64_t coord(double x, int c) const {
    int64_t k = static_cast<int64_t>(std::floor((x - lo[c]) / cell[c]));
    if (periodic[c]) {
      k %= nc[c];
      if (k < 0) k += nc[c];
    } else {
      k = std::min<int64_t>(std::max<int64_t>(k, 0), nc[c] - 1);
    }
    return k;
  }
  int64_t index(const int64_t *k) const {
    int64_t id = 0;
    for (int c = dim - 1; c >= 0; --c) id = id * nc[c] + k[c];
    return id;
  }
};

}  // namespace

void find_neighbors(const ParticleSet &ps, const std::vector<int32_t> &status, Csr &out) {
  const int dim = ps.dim();
  const int32_t n = ps.size();
  const int32_t rows = ps.num_owned();
  const int conv = ps.search_convention();
  const double kappa = ps.kappa();
  out.rowptr.assign(static_cast<size_t>(rows) + 1, 0);
  out.cols.clear();

  // Gather the valid particles' coordinates (wrapped into the box on periodic axes).
  std::vector<double> xs(static_cast<size_t>(n) * 3, 0.0), rad(n, 0.0);
  std::vector<int32_t> valid;
  valid.reserve(n);
  double rmax = 0.0, rsum = 0.0;
  double bmin[3] = {0, 0, 0}, bmax[3] = {0, 0, 0};
  bool first = true;
  for (int32_t i = 0; i < n; ++i) {
    if (status[i] != 0) continue;
    valid.push_back(i);
    rad[i] = kappa * ps.h(i);
    rmax = std::max(rmax, rad[i]);
    rsum += rad[i];
    for (int c = 0; c < dim; ++c) {
      double x = ps.x(i, c);
      if (ps.periodic(c)) {
        const double L = ps.box_hi(c) - ps.box_lo(c);
        x -= L * std::floor((x - ps.box_lo(c)) / L);
      }
      xs[static_cast<size_t>(i) * 3 + c] = x;
      if (first || x < bmin[c]) bmin[c] = x;
      if (first || x > bmax[c]) bmax[c] = x;
    }
    first = false;
  }
  if (valid.empty()) return;

  for (int c = 0; c < dim; ++c)
    if (ps.periodic(c) && 2.0 * rmax >= ps.box_hi(c) - ps.box_lo(c)) {
      std::ostringstream s;
      s << "support radius kappa*h = " << rmax << " is not below half the periodic box length "
        << (ps.box_hi(c) - ps.box_lo(c)) << " on axis " << c;
      throw Error(MFREE_ERR_INPUT, s.str());
    }

  // Cell edge: the mean radius, enlarged so that the grid has at most ~4 cells per
  // particle (clustered or far-flung particles would otherwise make it huge).
  Grid g;
  g.dim = dim;
  double edge = rsum / static_cast<double>(valid.size());
  const double max_cells = 4.0 * static_cast<double>(valid.size()) + 64.0;
  for (int pass = 0; pass < 64; ++pass) {
    double total = 1.0;
    for (int c = 0; c < dim; ++c) {
      const double ext = ps.periodic(c) ? ps.box_hi(c) - ps.box_lo(c) : bmax[c] - bmin[c];
      total *= std::max(1.0, std::floor(ext / edge));
    }
    if (total <= max_cells) break;
    edge *= 1.5;
  }
  for (int c = 0; c < dim; ++c) {
    g.periodic[c] = ps.periodic(c);
    if (g.periodic[c]) {
      const double L = ps.box_hi(c) - ps.box_lo(c);
      g.lo[c] = ps.box_lo(c);
      g.nc[c] = std::max<int64_t>(1, static_cast<int64_t>(std::floor(L / edge)));
      g.cell[c] = L / static_cast<double>(g.nc[c]);
    } else {
      g.lo[c] = bmin[c];
      g.nc[c] = std::max<int64_t>(1, static_cast<int64_t>(std::floor((bmax[c] - bmin[c]) / edge)) + 1);
      g.cell[c] = edge;
    }
  }
  int64_t ncells = 1;
  for (int c = 0; c < dim; ++c) ncells *= g.nc[c];

  // Counting sort of the valid particles by cell (stable: ascending index in a cell).
  std::vector<int64_t> cell_of(n, -1), start(static_cast<size_t>(ncells) + 1, 0);
  for (int32_t i : valid) {
    int64_t k[3] = {0, 0, 0};
    for (int c = 0; c < dim; ++c) k[c] = g.coord(xs[static_cast<size_t>(i) * 3 + c], c);
    cell_of[i] = g.index(k);
    ++start[cell_of[i] + 1];
  }
  for (int64_t c = 0; c < ncells; ++c) start[c + 1] += start[c];
  std::vector<int32_t> members(valid.size());
  {
    std::vector<int64_t> fill(start.begin(), start.end() - 1);
    for (int32_t i : valid) members[fill[cell_of[i]]++] = i;
  }

  double L[3] = {0, 0, 0};
  for (int c = 0; c < dim; ++c)
    if (g.periodic[c]) L[c] = ps.box_hi(c) - ps.box_lo(c);

  std::vector<int32_t> row;
  for (int32_t i = 0; i < rows; ++i) {
    if (status[i] != 0) {
      out.rowptr[i + 1] = static_cast<int64_t>(out.cols.size());
      continue;
    }
    const double *xi = &xs[static_cast<size_t>(i) * 3];
    const double ri = rad[i];
    const double R = conv == MFREE_SEARCH_GATHER ? ri
                     : conv == MFREE_SEARCH_SYMMETRIC_MAX ? rmax
                                                          : 0.5 * (ri + rmax);
    // Cell ranges per axis: [k - m, k + m], clamped, or all cells once on a periodic
    // axis where the stencil would wrap onto itself.
    int64_t kc[3] = {0, 0, 0}, kmin[3] = {0, 0, 0}, kmax[3] = {0, 0, 0};
    for (int c = 0; c < dim; ++c) {
      kc[c] = g.coord(xi[c], c);
      const int64_t m = static_cast<int64_t>(std::ceil(R / g.cell[c]));
      if (g.periodic[c]) {
        if (2 * m + 1 >= g.nc[c]) {
          kmin[c] = 0;
          kmax[c] = g.nc[c] - 1;
        } else {
          kmin[c] = kc[c] - m;
          kmax[c] = kc[c] + m;
        }
      } else {
        kmin[c] = std::max<int64_t>(0, kc[c] - m);
        kmax[c] = std::min<int64_t>(g.nc[c] - 1, kc[c] + m);
      }
    }
    row.clear();
    int64_t k[3];
    for (k[2] = kmin[2]; k[2] <= kmax[2]; ++k[2])
      for (k[1] = kmin[1]; k[1] <= kmax[1]; ++k[1])
        for (k[0] = kmin[0]; k[0] <= kmax[0]; ++k[0]) {
          int64_t kw[3] = {k[0], k[1], k[2]};
          for (int c = 0; c < dim; ++c)
            if (g.periodic[c]) kw[c] = ((kw[c] % g.nc[c]) + g.nc[c]) % g.nc[c];
          const int64_t cell = g.index(kw);
          for (int64_t p = start[cell]; p < start[cell + 1]; ++p) {
            const int32_t j = members[p];
            const double *xj = &xs[static_cast<size_t>(j) * 3];
            double d2 = 0.0;
            for (int c = 0; c < dim; ++c) {
              double d = xi[c] - xj[c];
              if (g.periodic[c]) d -= L[c] * std::nearbyint(d / L[c]);
              d2 += d * d;
            }
            const double rj = rad[j];
            const double lim = conv == MFREE_SEARCH_GATHER ? ri
                               : conv == MFREE_SEARCH_SYMMETRIC_MAX ? std::max(ri, rj)
                                                                    : 0.5 * (ri + rj);
            if (d2 < lim * lim) row.push_back(j);
          }
        }
    std::sort(row.begin(), row.end());
    out.cols.insert(out.cols.end(), row.begin(), row.end());
    out.rowptr[i + 1] = static_cast<int64_t>(out.cols.size());
  }
}

}  // namespace mfree
