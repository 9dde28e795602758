// Moving particle finite element method (paper 004): finite-element meshes over the
// particles and their geometry at the current positions (mpfem_mesh.cpp), with the
// general shape functions of eqs 1-3 from the finite-element shape-function module
// (fe_shape.hpp). The element weights of the moving kernel (eqs 4-13, 21) are in
// mpfem_weights.*; Approximant::compute_mpfem (mpfem.cpp) fills the approximant's tables.
#pragma once

#include <cstdint>
#include <vector>

#include "core/base/error.hpp"
#include "core/particles/particles.hpp"
#include "core/shape/fe_shape.hpp"

namespace mfree {

// Element connectivity over the particles of a set, in blocks of one element type,
// copied or borrowed.
class Mesh {
 public:
  explicit Mesh(const ParticleSet *ps) : ps_(ps) {}
  const ParticleSet &particles() const { return *ps_; }
  int dim() const { return ps_->dim(); }
  void add_elements(int type, int32_t n, const int32_t *conn, int base, int mem);
  int32_t num_elements() const;
  // The current connectivity, 0-based (borrowed blocks are re-read and checked).
  void connectivity(std::vector<int32_t> &type, std::vector<int32_t> &ptr,
                    std::vector<int32_t> &nodes) const;

 private:
  struct Block {
    int type = 0;
    int32_t n = 0;
    int base = 0;
    const int32_t *ptr = nullptr;
    HVec<int32_t> own;  // (from the context's hook, like every copy of host data)
  };
  void check_block(const Block &b, int32_t first) const;
  const ParticleSet *ps_;
  std::vector<Block> blocks_;
};

// A mesh at the current node positions: per element its nodes relative to the first
// one (nearest image along periodic axes), bounding box, measure, and the coefficients
// of its general shape functions, the element interpolant in physical coordinates
// extended over the whole domain (004 eqs 1-2).
struct MeshGeometry {
  static constexpr int kMaxNodes = kMaxElementNodes;
  int dim = 1;
  std::vector<int32_t> type, ptr, nodes;
  std::vector<double> rel;            // 3 per node entry, relative to the element's first node
  std::vector<double> lo, hi, center; // 3 per element, relative to the first node
  std::vector<double> scale, measure; // 1 per element
  std::vector<double> coef;           // kMaxNodes^2 per element: C[m * 8 + I]
  std::vector<char> box;              // axis-aligned rectangle or brick
  std::vector<int64_t> node_ptr;      // node -> incident elements (CSR)
  std::vector<int32_t> node_elems;

  // Throws Error(MFREE_ERR_INPUT) naming the first invalid element.
  void build(const Mesh &m);
  int32_t size() const { return static_cast<int32_t>(type.size()); }
  int nn(int32_t e) const { return static_cast<int>(ptr[e + 1] - ptr[e]); }
  // General shape functions of element e at xr = x - x_first: values N[nn], gradients
  // dN[nn * 3] and Hessians d2N[nn * 6] (packed as hessian_index), each may be NULL.
  void shape(int32_t e, const double *xr, double *N, double *dN, double *d2N) const;
  // Gauss points (absolute coordinates of the first node plus relative ones).
  void quadrature(const ParticleSet &ps, int ngauss, std::vector<double> &x,
                  std::vector<double> &w) const;
};

}  // namespace mfree
