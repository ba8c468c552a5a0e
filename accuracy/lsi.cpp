#include "accuracy/lsi.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace yarnhom {

Eigen::VectorXd nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  const int n = int(A.cols());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(n, false);  // P: variables free to move; Z: held at 0
  const double tol = 1e-12 * std::max(1.0, A.cwiseAbs().maxCoeff()) * std::max(1.0, b.cwiseAbs().maxCoeff());
  // The outer loop adds the most promising held variable; the inner loop steps back along the
  // segment to the unconstrained optimum on P until every passive variable stays positive.
  for (int outer = 0; outer < 3 * n + 10; ++outer) {
    const Eigen::VectorXd w = A.transpose() * (b - A * x);  // negative gradient
    int best = -1;
    double wmax = tol;
    for (int j = 0; j < n; ++j)
      if (!passive[j] && w[j] > wmax) { wmax = w[j]; best = j; }
    if (best < 0) break;  // Kuhn-Tucker conditions hold
    passive[best] = true;
    for (int inner = 0; inner < 3 * n + 10; ++inner) {
      std::vector<int> P;
      for (int j = 0; j < n; ++j)
        if (passive[j]) P.push_back(j);
      Eigen::MatrixXd AP(A.rows(), P.size());
      for (size_t k = 0; k < P.size(); ++k) AP.col(k) = A.col(P[k]);
      const Eigen::VectorXd zP = AP.colPivHouseholderQr().solve(b);
      bool all_positive = true;
      for (size_t k = 0; k < P.size(); ++k) all_positive = all_positive && zP[k] > 0;
      if (all_positive) {
        x.setZero();
        for (size_t k = 0; k < P.size(); ++k) x[P[k]] = zP[k];
        break;
      }
      double alpha = std::numeric_limits<double>::infinity();
      for (size_t k = 0; k < P.size(); ++k)
        if (zP[k] <= 0) alpha = std::min(alpha, x[P[k]] / (x[P[k]] - zP[k]));
      for (size_t k = 0; k < P.size(); ++k) x[P[k]] += alpha * (zP[k] - x[P[k]]);
      for (size_t k = 0; k < P.size(); ++k)
        if (x[P[k]] <= 1e-15 * std::max(1.0, std::abs(zP[k]))) { passive[P[k]] = false; x[P[k]] = 0; }
    }
  }
  return x;
}

LsiResult solve_lsi(const Eigen::MatrixXd& E, const Eigen::VectorXd& f, const Eigen::MatrixXd& G,
                    const Eigen::VectorXd& h) {
  const int n = int(E.cols());
  if (E.rows() < n) throw std::invalid_argument("solve_lsi: fewer equations than unknowns");
  if (G.cols() != n || G.rows() != h.size()) throw std::invalid_argument("solve_lsi: constraint shapes");
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(E);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
  const Eigen::VectorXd c = (qr.householderQ().transpose() * f).head(n);
  auto Rinv_solve = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return R.triangularView<Eigen::Upper>().solve(v);
  };
  LsiResult res;
  res.x = Rinv_solve(c);  // the unconstrained optimum
  if (G.rows() == 0) return res;
  // Gt = G R^-1 (rows), i.e. Gt^T = R^-T G^T.
  const Eigen::MatrixXd GtT = R.transpose().triangularView<Eigen::Lower>().solve(G.transpose());
  const Eigen::VectorXd ht = h - GtT.transpose() * c;
  if ((ht.array() <= 0).all()) return res;  // z = 0 is feasible: the optimum is unconstrained
  const int m = int(G.rows());
  Eigen::MatrixXd A(n + 1, m);
  A.topRows(n) = GtT;
  A.row(n) = ht.transpose();
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n + 1);
  b[n] = 1;
  const Eigen::VectorXd u = nnls(A, b);
  const Eigen::VectorXd r = A * u - b;
  if (r.norm() < 1e-12) {
    res.feasible = false;
    return res;
  }
  const Eigen::VectorXd z = -r.head(n) / r[n];
  res.x = Rinv_solve(z + c);
  return res;
}

}  // namespace yarnhom
