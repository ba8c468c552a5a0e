#pragma once
// Is the baked material's rest a stable, stress-free state? At s = 0 the in-plane stress
// dPsi/ds_(x,a,y) should vanish (the dataset's rest is the stress-free tile: docs/rve.md) and the
// Hessian d2Psi/ds2 should be positive definite, or the relaxed cloth shears or buckles by
// itself. (A bending moment dPsi/dII at rest is physical: a stockinette curls.)
//
// The fit limits of train-all are relative to a term's whole data range, which jamming and
// large stretch dominate; a network can pass them and still have the wrong sign of curvature
// at rest, where the data's energy is 1e-5 of the range (basket's shear term: curvature -0.087
// J/m^2 at s_a = 0 against the data's +0.05; its continuum strip shears to s_a = -0.09 at rest,
// docs/accuracy_rows.md, "A material unstable at rest"). This check sees that.
//
// Definiteness is judged on the Hessian scaled to unit diagonal magnitude (core/scaled_eigen.hpp),
// as the RVE's own rest Hessian is (yarn/rve/rest_hessian.hpp, the dataset's /rest hessian).
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "material/material.hpp"

namespace yarnhom {

struct RestCheck {
  Strain6 grad = Strain6::Zero();                        // dPsi/ds at s = 0
  Eigen::Matrix<double, 6, 6> hess = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> scaled_eigenvalues = Eigen::Matrix<double, 6, 1>::Zero();  // ascending
  Strain6 weakest = Strain6::Zero();  // the unit eigenvector of the smallest scaled eigenvalue (scaled strains)
  bool stable = true;                 // every scaled eigenvalue >= -tolerance
  std::string summary() const;        // one line: "rest: stable ..." or "rest: UNSTABLE ..."
};

RestCheck check_rest(const BakedMaterial& mat, double tolerance = 1e-9);

// What the RVE itself says, for the line beside the material's: "; the RVE's own rest ..." from a
// dataset's measured rest Hessian ([36], Dataset::rest_hessian; yarn/rve/rest_hessian.hpp), or ""
// when it has none. A material that is unstable where the RVE is stable is a fit error; one that
// follows an unstable RVE is the pattern's physics.
std::string rve_rest_note(const std::vector<double>& rest_hessian);

}  // namespace yarnhom
