// Small-strain kinematics in Voigt notation, shared by the forms and the traction
// operators of the assembler: inline, since they sit in the innermost assembly loops.
#pragma once

#include <algorithm>

namespace mfree {

// Rows of the strain-displacement matrix B(g) for gradient g (Voigt: xx, yy, [zz,] xy
// [, yz, zx]); B[v][a] is the factor of u_a in strain component v.
inline int strain_rows(int dim, const double *g, double B[6][3]) {
  for (int v = 0; v < 6; ++v) B[v][0] = B[v][1] = B[v][2] = 0.0;
  if (dim == 2) {
    B[0][0] = g[0];
    B[1][1] = g[1];
    B[2][0] = g[1];
    B[2][1] = g[0];
    return 3;
  }
  B[0][0] = g[0];
  B[1][1] = g[1];
  B[2][2] = g[2];
  B[3][0] = g[1];
  B[3][1] = g[0];
  B[4][1] = g[2];
  B[4][2] = g[1];
  B[5][0] = g[2];
  B[5][2] = g[0];
  return 6;
}

// The same with the shear rows from gradient gs (Johnson-Beissel: paper 000 eqs 48-52
// correct the normal strains only).
inline int strain_rows(int dim, const double *g, const double *gs, double B[6][3]) {
  double Bs[6][3];
  const int nv = strain_rows(dim, g, B);
  if (gs == g) return nv;
  strain_rows(dim, gs, Bs);
  for (int v = dim; v < nv; ++v)
    for (int a = 0; a < 3; ++a) B[v][a] = Bs[v][a];
  return nv;
}

// Voigt index of the stress component (a, b).
inline int voigt(int dim, int a, int b) {
  if (a == b) return a;
  if (dim == 2) return 2;
  const int lo = std::min(a, b), hi = std::max(a, b);
  return lo == 0 ? (hi == 1 ? 3 : 5) : 4;
}

}  // namespace mfree
