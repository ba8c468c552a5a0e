#pragma once
// Helpers of the hand-written derivative code: the cross-product matrix, and the second
// derivative of a bilinear form whose two arguments are differences of element vertices.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace yarnhom::numerics {

// [v]x with [v]x u = v x u.
inline Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// For S = u^T M r with u = sum_i alpha_i y_i and r = sum_j beta_j y_j (y_i the 3-vectors of
// the element's vertices), adds d2S/dy dy^T to H: block (i, j) gets alpha_i beta_j M +
// beta_i alpha_j M^T. K vertices, H of size 3K.
template <int K, class Mat>
inline void add_bilinear(Mat& H, const Eigen::Matrix3d& M, const double (&alpha)[K], const double (&beta)[K],
                         double scale = 1.0) {
  for (int i = 0; i < K; ++i)
    for (int j = 0; j < K; ++j) {
      const double ab = alpha[i] * beta[j], ba = beta[i] * alpha[j];
      if (ab == 0 && ba == 0) continue;
      H.template block<3, 3>(3 * i, 3 * j) += scale * (ab * M + ba * M.transpose());
    }
}

}  // namespace yarnhom::numerics
