#pragma once
// How wide a stretched strip is at its middle, measured the same way on the yarn centrelines and
// on the continuum surface's vertices, so that the two strips' transverse contraction can be
// compared directly (a continuum that cannot contract like the yarn strip is too stiff: the
// honeycomb's data box, docs/accuracy.md).
//
// The long axis is the in-plane axis (x or y) along which the points extend furthest. The middle
// band holds the points within `half_band` of the midpoint of their extent along it; the width is
// the extent of that band across (a yarn strip's selvedge connectors are its edge). It is a
// projected width: a strip that curls is narrower by it too, which is part of what the comparison
// is for.
#include <Eigen/Core>

namespace yarnhom {

struct MiddleWidth {
  int long_axis = 0;  // 0: x, 1: y
  double width = 0;   // m, across the long axis
  int points = 0;     // in the middle band
};

MiddleWidth middle_width(const Eigen::Matrix3Xd& P, double half_band = 0.003);

}  // namespace yarnhom
