#pragma once
// Projection of a symmetric matrix onto the positive semi-definite cone (negative eigenvalues
// set to zero), so that the assembled Newton matrix is positive semi-definite and every Newton
// direction descends (the projected Newton method of Teran et al. 2005 and IPC). A
// Cholesky-type test first: most matrices near equilibrium need no eigen-decomposition.
// Sizes: 18 (an element's Hessian, sim/hessian_model.hpp's ProjectedElement) and 6 (the
// material's d2Psi/ds2 and the in-plane curvature term in (f1, f2), the Split model).
#include <Eigen/Core>

namespace yarnhom::sim {

// Returns true when H was changed.
template <int N>
bool project_psd(Eigen::Matrix<double, N, N>& H);

extern template bool project_psd<6>(Eigen::Matrix<double, 6, 6>&);
extern template bool project_psd<18>(Eigen::Matrix<double, 18, 18>&);

}  // namespace yarnhom::sim
