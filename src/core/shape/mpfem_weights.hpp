// The element weights of MPFEM's moving kernel (paper 004 eqs 4-13, 21): the 1D kernel
// profile with its cumulative integral, the unnormalised weight of one element with its
// derivatives, and a bucket grid that finds the elements a support may reach.
#pragma once

#include <cstdint>
#include <vector>

#include "core/base/kernel.hpp"
#include "core/particles/particles.hpp"
#include "core/shape/mpfem.hpp"

namespace mfree {

// The 1D profile g(t) = W1(|t|, h) of a kernel, its derivative and its cumulative
// integral G(t) = int_{-Rh}^t g, so that the tensor kernel prod_c g(t_c) has unit
// integral. Closed forms for the MPFEM kernels, panel Gauss sums for the others.
class KernelProfile {
 public:
  KernelProfile(int kernel, double param);
  double radius() const { return R_; }
  void g(double t, double h, double &v, double &dv) const;
  double G(double t, double h) const;
  // Knots in units of h where g or g' may jump (the support edges, 0, spline knots).
  const std::vector<double> &knots() const { return knots_; }
  bool continuous() const { return id_ != MFREE_KERNEL_HAAR; }
  // The cosine kernel g = (k/2) cos(k t), k = pi / (2 R h): edge integrals of products of
  // g, G and g' are sums of sines and cosines of linear functions, integrated exactly.
  bool cosine() const { return id_ == MFREE_KERNEL_COSINE; }

 private:
  double Gq(double q) const;  // cumulative in units of h
  int id_;
  Kernel k_;
  double R_;
  std::vector<double> knots_, cum_, xg_, wg_;
};

struct ElemWeight {
  double W = 0.0, dW[3] = {0, 0, 0}, d2W[6] = {0, 0, 0, 0, 0, 0};
};

// Unnormalised weight int_e phi(y - x) dy and its x-derivatives (004 eq 11), for element
// e whose first node is at d0 = x_first - x; d1, d2: the first, second derivatives too;
// (xg, wg): the Gauss rule of the edge integrals of polygons.
void element_weight(const MeshGeometry &geo, const KernelProfile &K, int32_t e, const double *d0,
                    double h, bool d1, bool d2, const std::vector<double> &xg,
                    const std::vector<double> &wg, ElemWeight &out);

// Whether element e's box (first node at d0 from the site) meets the support [-Rh, Rh]^dim.
bool box_overlaps(const MeshGeometry &geo, int32_t e, const double *d0, double Rh);

// Uniform bucket grid over the elements' bounding boxes (absolute coordinates), so that
// a site finds the elements its support box may reach without a sweep over the mesh.
// Not used on periodic sets, whose elements are placed by nearest image.
class ElementGrid {
 public:
  ElementGrid(const MeshGeometry &geo, const ParticleSet &ps);
  // Elements whose box may overlap [x - r, x + r], ascending, each once.
  void query(const double *x, double r, int32_t tag, std::vector<int32_t> &out);

 private:
  void range(const double *lo, const double *hi, int32_t *a, int32_t *b) const;
  int dim_;
  double org_[3] = {0, 0, 0}, cs_[3] = {1, 1, 1};
  int32_t n_[3] = {1, 1, 1};
  std::vector<double> lo_, hi_;
  std::vector<int64_t> start_, fill_;
  std::vector<int32_t> elems_, stamp_;
};

}  // namespace mfree
