#include "produce/sampling.hpp"

#include <cmath>
#include <deque>
#include <stdexcept>

namespace yarnhom::yarn {

std::vector<double> axis_points(double lower, double upper, int n) {
  if (!(lower < 0 && upper > 0)) throw std::invalid_argument("sampling: a box must contain 0 strictly inside");
  if (n < 3) throw std::invalid_argument("sampling: at least 3 points per axis");
  // Split the n - 1 intervals between the sides in proportion to their lengths, at least one each.
  int neg = static_cast<int>(std::lround((n - 1) * (-lower) / (upper - lower)));
  neg = std::min(std::max(neg, 1), n - 2);
  const int pos = n - 1 - neg;
  std::vector<double> p;
  for (int k = neg; k >= 1; --k) p.push_back(lower * k / neg);
  p.push_back(0.0);
  for (int k = 1; k <= pos; ++k) p.push_back(upper * k / pos);
  return p;
}

std::vector<Eigen::VectorXd> term_nodes(const Term& t, const std::vector<Range>& box, int n) {
  std::vector<Eigen::VectorXd> out;
  if (t.dim() == 1) {
    for (double a : axis_points(box[0].lower, box[0].upper, n)) out.push_back(Eigen::VectorXd::Constant(1, a));
  } else {
    const auto pa = axis_points(box[0].lower, box[0].upper, n), pb = axis_points(box[1].lower, box[1].upper, n);
    for (double a : pa)
      for (double b : pb) {
        Eigen::VectorXd v(2);
        v << a, b;
        out.push_back(v);
      }
  }
  return out;
}

int sector_of(const Eigen::VectorXd& s, int sectors) {
  if (s.norm() == 0) return -1;
  if (s.size() == 1) return s[0] < 0 ? 0 : 1;
  const double ang = std::atan2(s[1], s[0]);  // (-pi, pi]
  int k = static_cast<int>(std::floor((ang + M_PI) / (2 * M_PI) * sectors));
  return std::min(std::max(k, 0), sectors - 1);
}

WarmStartPlan algorithm1(const std::vector<Eigen::VectorXd>& s) {
  const int n = static_cast<int>(s.size());
  WarmStartPlan plan;
  plan.parent.assign(n, -2);  // uninitialized
  for (int i = 0; i < n; ++i) {
    const double ni = s[i].norm();
    if (ni == 0) {
      plan.parent[i] = -1;
      continue;
    }
    int best = -1;
    double bd = 0;
    for (int j = 0; j < n; ++j) {
      if (j == i || !(s[j].norm() < ni)) continue;
      const double d = (s[i] - s[j]).norm();
      if (best < 0 || d < bd) {
        best = j;
        bd = d;
      }
    }
    plan.parent[i] = best;  // -1: no smaller node in the sector, start from the origin
  }
  // Breadth-first from the origin: roots are the nodes whose parent is the origin (-1).
  std::vector<std::vector<int>> children(n);
  std::deque<int> queue;
  for (int i = 0; i < n; ++i) {
    if (plan.parent[i] < 0) queue.push_back(i);
    else children[plan.parent[i]].push_back(i);
  }
  while (!queue.empty()) {
    const int i = queue.front();
    queue.pop_front();
    plan.order.push_back(i);
    for (int c : children[i]) queue.push_back(c);
  }
  return plan;
}

}  // namespace yarnhom::yarn
