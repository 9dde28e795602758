// Wall and stabilisation options of the Galerkin-SPH fluid (fluid.hpp) that paper 003
// does not have: dummy wall particles with extrapolated pressure (Adami, Hu & Adams
// 2012) and a density-diffusion term (delta-SPH, Molteni & Colagrossi 2009, with the
// gradient correction of Antuono et al. 2010). The functions are FluidSystem members
// defined in fluid_wall.cpp; this header holds their data.
#pragma once

#include <cstdint>
#include <vector>

#include "core/base/alloc.hpp"

namespace mfree {

// Dummy particles are appended to the fluid's particle set: nodes of the MLS
// approximation (velocity parameters zero: the wall is at rest and no-slip) and quadrature
// points of the momentum equation, with the pressure extrapolated from the fluid
// hydrostatically, p_w = sum_f W_wf (p_f + rho_f g.(x_w - x_f)) / sum_f W_wf. The node
// arrays below hold the fluid's n values followed by the n_dummy dummies'.
struct DummyWall {
  int32_t n = 0;             // dummy count
  HVec<double> xd;           // dummy positions (dim each), copied at set-up
  std::vector<double> x;     // node positions: fluid (refreshed at every prepare), dummies
  std::vector<double> v;     // node velocity parameters: fluid, then zeros
  std::vector<double> rho;   // node densities: fluid, then extrapolated
  std::vector<double> rho0;  // node rest densities: fluid, then the neighbours' average
  std::vector<double> mass;  // node masses: fluid, then rho_w V_w (body force only)
  std::vector<double> p;     // node pressures (scratch of the extrapolation)
  std::vector<int> level;    // extrapolation pass that filled a node (0: none yet)
  // share[k] = sum over fluid nodes j of N_j(x_k), for the fluid quadrature points: the
  // lumped mass of a fluid node is sum_k N_i(x_k) M_k / share[k], so that the fluid nodes
  // carry the whole fluid mass (the dummies' part of the partition of unity is the wall's).
  std::vector<double> share;
  std::vector<double> xi;        // consistent-integration corrections of the fluid nodes
  std::vector<double> blend;     // their completeness blends (see vci_setup)
  std::vector<double> grad_rho;  // MLS density gradients at the nodes (density diffusion)
};

}  // namespace mfree
