#include "accuracy/middle_width.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace yarnhom {

MiddleWidth middle_width(const Eigen::Matrix3Xd& P, double half_band) {
  MiddleWidth r;
  if (P.cols() == 0) return r;
  const Eigen::Vector3d lo = P.rowwise().minCoeff(), hi = P.rowwise().maxCoeff();
  r.long_axis = (hi[0] - lo[0]) >= (hi[1] - lo[1]) ? 0 : 1;
  const int a = r.long_axis, c = 1 - a;
  const double mid = 0.5 * (lo[a] + hi[a]);
  std::vector<double> across;
  for (Eigen::Index k = 0; k < P.cols(); ++k)
    if (std::abs(P(a, k) - mid) <= half_band) across.push_back(P(c, k));
  r.points = int(across.size());
  if (across.size() < 2) return r;
  const auto [mn, mx] = std::minmax_element(across.begin(), across.end());
  r.width = *mx - *mn;
  return r;
}

}  // namespace yarnhom
