#pragma once
// Helpers shared by the yarn tests: where the shared patterns are, finite differences.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "yarn/rod/pattern.hpp"
#include "yarn/rve/rest.hpp"

namespace yarnhom::yarn::testing {

inline std::string shared_pattern(const std::string& name) {
  return std::string(YARNHOM_SOURCE_DIR) + "/../shared/patterns/" + name + ".pyp";
}
inline bool have_shared_patterns() {
  return std::filesystem::exists(shared_pattern("stocktiny"));
}

// Central-difference gradient of f at x with step h (per component).
template <class F>
Eigen::VectorXd fd_gradient(F f, Eigen::VectorXd x, double h) {
  Eigen::VectorXd g(x.size());
  for (int i = 0; i < x.size(); ++i) {
    const double xi = x[i];
    x[i] = xi + h;
    const double fp = f(x);
    x[i] = xi - h;
    const double fm = f(x);
    x[i] = xi;
    g[i] = (fp - fm) / (2 * h);
  }
  return g;
}

// Relative error ||a - b|| / max(||b||, floor).
inline double rel_err(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor = 1e-300) {
  return (a - b).norm() / std::max(b.norm(), floor);
}

// The macroscopic strain (s_x, s_a, s_y, II_x, II_xy, II_y) from its six components.
inline Strain strain(double a, double b, double c, double d, double e, double f) {
  Strain s;
  s << a, b, c, d, e, f;
  return s;
}

}  // namespace yarnhom::yarn::testing

#define YARN_REQUIRE_SHARED_PATTERNS()                                                   \
  if (!yarnhom::yarn::testing::have_shared_patterns())                                   \
  GTEST_SKIP() << "shared patterns not found at " YARNHOM_SOURCE_DIR "/../shared/patterns"
