// Finite-element shape functions, the one set used by MPFEM's meshes (mpfem_mesh.cpp) and
// by the assembler's finite-element layer (discretize/assembler_fe_layer.cpp):
//   - the element types of mfree_element_t (dimension, node count, name);
//   - isoparametric functions of the reference element (LINE2 is affine, QUAD4 bilinear,
//     HEX8 trilinear, corners in VTK order), the isoparametric map and its Jacobian, and
//     the functions at a physical point found by inverting the map (TRI3 in closed form);
//   - the general shape functions of paper 004 (eqs 1-2): the element's interpolant in
//     physical coordinates over multilinear monomials, which MPFEM extends over the whole
//     domain. On a triangle and on an axis-aligned rectangle or brick they equal the
//     isoparametric ones; on other quadrilaterals they differ, which is why both exist.
// Node coordinates are passed with 3 numbers per node (unused axes 0).
#pragma once

#include <cstdint>

namespace mfree {

// Dimension and node count of an mfree_element_t (0 for an unknown type), and its name.
int element_dim(int type);
int element_nodes(int type);
const char *element_name(int type);

// Most nodes of any element type (HEX8).
constexpr int kMaxElementNodes = 8;

// Reference coordinates of corner k of a QUAD4 or HEX8 (2 or 3 numbers).
const double *reference_corner(int type, int k);

// Isoparametric functions of a QUAD4 or HEX8 at reference point r: N[n] and their
// reference derivatives dNr[3 * n] (dN_I / dr_k at dNr[3 * I + k]).
void iso_shape(int type, const double *r, double *N, double *dNr);

// Isoparametric map of a QUAD4 or HEX8 with nodes X at reference point r: the point x
// (in X's coordinates) and det dx/dr.
void iso_map(int type, const double *X, const double *r, double *x, double &det);

// Cross product (2D) of the edges leaving corner k of a polygon with n nodes X toward
// its next and its previous node: positive at every corner of a counter-clockwise convex
// polygon, so that it measures orientation and degeneracy of TRI3 and QUAD4 corners.
double corner_cross(const double *X, int n, int k);

// Functions of a 2D TRI3 or QUAD4 with nodes X at the physical point x: N[n] and their
// gradients dN[2 * n]; false (N and dN undefined) if x lies outside the element beyond a
// tolerance of 1e-10 in reference coordinates. QUAD4 inverts the isoparametric map by
// Newton's method.
bool element_shape_at(int type, const double *X, const double *x, double *N, double *dN);

// General shape functions (004 eq 1) of an element of type `type` with nodes X relative
// to its first node, in the coordinates xi = (x - center) / scale: the coefficients
// coef[m * kMaxElementNodes + I] of node I's function over the element's monomials.
// False when the nodes do not determine the interpolant (singular Vandermonde matrix).
bool general_shape_coefficients(int type, const double *X, const double *center, double scale,
                                double *coef);
// Their values N[n], gradients dN[3 * n] and Hessians d2N[6 * n] (packed as
// hessian_index) at xr, relative to the first node; each output may be NULL.
void general_shape(int type, int dim, const double *coef, const double *center, double scale,
                   const double *xr, double *N, double *dN, double *d2N);

}  // namespace mfree
