// Test or trial functions at quadrature or boundary points, as the assembler integrates
// them (after the FE layer's blending and the consistent-integration correction).
#pragma once

#include <cstdint>
#include <vector>

namespace mfree {

// Weight per point, CSR rows of particles with values and gradients.
struct QTable {
  std::vector<double> w;
  std::vector<int64_t> rowptr{0};
  std::vector<int32_t> cols;
  std::vector<double> val, grad;
  std::vector<double> x;  // position of each point (dim per point)
  // Derivatives for the shear strains when they differ from grad (Johnson-Beissel,
  // paper 000 eqs 48-52: the shear keeps the symmetrised SPH derivatives); empty: grad.
  std::vector<double> sgrad;
  int32_t size() const { return static_cast<int32_t>(w.size()); }
};

// Read-only view with the accessor names of Approximant, so loops read alike.
struct QView {
  const QTable &t;
  const std::vector<int64_t> &rowptr() const { return t.rowptr; }
  const std::vector<int32_t> &cols() const { return t.cols; }
  const std::vector<double> &values() const { return t.val; }
  const std::vector<double> &gradients() const { return t.grad; }
  int32_t num_sites() const { return t.size(); }
};

}  // namespace mfree
