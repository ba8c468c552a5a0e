#pragma once
// Central finite differences in double for the sim tests: the gradient of a scalar and the
// Jacobian of a vector function, compared with analytic derivatives relative to their scale.
#include <Eigen/Core>
#include <functional>

namespace yarnhom::test {

inline Eigen::VectorXd fd_gradient(const std::function<double(const Eigen::VectorXd&)>& f, const Eigen::VectorXd& x,
                                   double h) {
  Eigen::VectorXd g(x.size());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd a = x, b = x;
    a[i] += h;
    b[i] -= h;
    g[i] = (f(a) - f(b)) / (2 * h);
  }
  return g;
}

// Column i = d f / d x_i.
inline Eigen::MatrixXd fd_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                   const Eigen::VectorXd& x, double h) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd J(f0.size(), x.size());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd a = x, b = x;
    a[i] += h;
    b[i] -= h;
    J.col(i) = (f(a) - f(b)) / (2 * h);
  }
  return J;
}

// max |a - b| / (1 + max |a|)... scaled by the analytic's own magnitude.
inline double rel_err(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& fd) {
  const double scale = std::max(analytic.cwiseAbs().maxCoeff(), 1e-300);
  return (analytic - fd).cwiseAbs().maxCoeff() / scale;
}

}  // namespace yarnhom::test
