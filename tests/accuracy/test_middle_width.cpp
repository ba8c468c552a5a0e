// The projected width at a strip's middle (accuracy/middle_width.hpp): the long axis is found
// (course strips along x, wale strips along y), only the middle band counts (a strip narrowed in
// its middle, wide at its clamps, gives the middle's width), and a strip curled into an arc is
// narrower by its projection.
#include <gtest/gtest.h>

#include <cmath>

#include "accuracy/middle_width.hpp"

using namespace yarnhom;

namespace {

// A 0.10 x 0.05 m grid strip along x whose half-width at x is w(x)/2, lifted by z(y).
Eigen::Matrix3Xd strip(double (*w)(double), double (*z)(double), bool along_y) {
  const int nx = 101, ny = 21;
  Eigen::Matrix3Xd P(3, nx * ny);
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      const double x = 0.1 * i / (nx - 1), v = -0.5 + double(j) / (ny - 1), y = v * w(x);
      P.col(i * ny + j) = along_y ? Eigen::Vector3d(y, x, z(v)) : Eigen::Vector3d(x, y, z(v));
    }
  return P;
}

double narrowed(double x) { return 0.05 - 0.02 * std::exp(-std::pow((x - 0.05) / 0.01, 2)); }  // 0.03 at the middle
double flat(double) { return 0.0; }
double uniform(double) { return 0.05; }

}  // namespace

TEST(MiddleWidth, FindsTheLongAxisAndMeasuresOnlyTheMiddle) {
  for (bool along_y : {false, true}) {
    const MiddleWidth m = middle_width(strip(narrowed, flat, along_y));
    EXPECT_EQ(m.long_axis, along_y ? 1 : 0);
    EXPECT_GT(m.points, 0);
    // The band +-3 mm about the middle: its rows are 30.0 mm (the middle) to 31.7 mm (3 mm off)
    // wide, the strip's ends 50 mm.
    EXPECT_GE(m.width, narrowed(0.05) - 1e-12) << along_y;
    EXPECT_LE(m.width, narrowed(0.053) + 1e-12) << along_y;
  }
  EXPECT_NEAR(middle_width(strip(uniform, flat, false)).width, 0.05, 1e-12);
  EXPECT_EQ(middle_width(Eigen::Matrix3Xd(3, 0)).points, 0);
}

TEST(MiddleWidth, ACurledStripIsNarrowerByItsProjection) {
  // The 5 cm width bent into a half circle (radius 5 cm / pi): projected width 2 R = 31.8 mm.
  auto curled = [](const Eigen::Matrix3Xd& P) {
    Eigen::Matrix3Xd Q = P;
    const double R = 0.05 / M_PI;
    for (Eigen::Index k = 0; k < P.cols(); ++k) {
      const double phi = P(1, k) / R;  // y in [-0.025, 0.025] -> [-pi/2, pi/2]
      Q(1, k) = R * std::sin(phi);
      Q(2, k) = R * (1 - std::cos(phi));
    }
    return Q;
  };
  EXPECT_NEAR(middle_width(curled(strip(uniform, flat, false))).width, 2 * 0.05 / M_PI, 1e-9);
}
