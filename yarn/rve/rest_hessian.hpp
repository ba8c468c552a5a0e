#pragma once
// The Hessian of the homogenized energy at rest, d2Psi/ds2 at s = 0 (6 x 6), measured on the RVE.
//
// Why: the dataset's grid resolves the energy's shape, not its curvature at the origin. A knit's
// stress-strain curve is stiffest in its first per cent (the built-in stockinette: d2Psi/ds_x2 is
// 60 J/m^2 at rest and 14 as the central difference over its quick grid's +-0.06), and the rest
// stability of the fitted material (positive definite d2Psi/ds2 at s = 0) is decided by exactly
// that number against the couplings' mixed derivatives. So produce measures it directly and the
// training holds the networks to it (train/trainer.cpp, train/polish.cpp).
//
// How: central differences of the envelope gradient (yarn/rve/energy_density.hpp), each column from
// two solves at s = +-h e_i started from the rest equilibrium; error O(h^2) plus the solves'
// tolerance. Column i of H is (dPsi/ds(+h e_i) - dPsi/ds(-h e_i)) / (2 h_i). A Hessian is
// symmetric, so the asymmetry |H - H^T| measures the error of the whole measurement, and the
// symmetric part is returned.
#include <array>
#include <string>

#include "yarn/rve/newton.hpp"
#include "yarn/rve/rve.hpp"

namespace yarnhom::yarn {

struct RestHessian {
  bool ok = false;                    // every solve converged
  std::string failure;                // why not
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();  // symmetric part
  double asymmetry = 0;               // max |H_ij - H_ji| / sqrt(|H_ii H_jj|) over i != j
  std::array<double, 6> step{};       // h per strain index (strain: 1; II: 1/m)
  int solves = 0;
  double seconds = 0;
};

// h: the in-plane step (strain); the bending steps are h / L, L the longer lattice vector of
// the relaxed tile, so that the tile's rotation across its period is h too.
RestHessian rest_hessian(const RveProblem& rve, const RveState& rest, const SolveOptions& opt = {}, double h = 1e-3);

}  // namespace yarnhom::yarn
