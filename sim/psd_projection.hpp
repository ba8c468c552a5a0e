#pragma once
// Projection of a symmetric element Hessian onto the positive semi-definite cone (negative
// eigenvalues set to zero), so that the assembled Newton matrix is positive semi-definite and
// every Newton direction descends (the projected Newton method of Teran et al. 2005 and
// IPC). A Cholesky-type test first: most elements near equilibrium need no eigen-decomposition.
#include <Eigen/Core>

namespace yarnhom::sim {

// Returns true when H was changed.
bool project_psd(Eigen::Matrix<double, 18, 18>& H);

}  // namespace yarnhom::sim
