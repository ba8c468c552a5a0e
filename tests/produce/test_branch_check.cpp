// The branch check (produce/branch_check.hpp): the trapezoid rule along grid edges finds where
// data jump between two branches and stays quiet on smooth data.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>

#include "produce/branch_check.hpp"

using namespace yarnhom::yarn;

namespace {
struct Grid {
  std::vector<Eigen::VectorXd> t, g;
  std::vector<double> psi;
  std::vector<bool> ok;
};
// An m x m grid on [-1, 1]^2 of a smooth energy; nodes with a > cut (when cut < 1) lie on a
// second branch, the same energy shifted by `gap` (gradients unchanged: the envelope theorem
// gives each branch's own slope, and the two are parallel here).
Grid grid2(int m, double cut = 2, double gap = 0) {
  Grid G;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      const double a = -1 + 2.0 * i / (m - 1), b = -1 + 2.0 * j / (m - 1);
      Eigen::VectorXd t(2), g(2);
      t << a, b;
      g << 2 * a + 0.5 * b + 0.3 * std::cos(a), 2 * b + 0.5 * a;
      G.t.push_back(t);
      G.g.push_back(g);
      G.psi.push_back(a * a + b * b + 0.5 * a * b + 0.3 * std::sin(a) + (a > cut ? gap : 0));
      G.ok.push_back(true);
    }
  return G;
}
}  // namespace

TEST(BranchCheck, SmoothDataHaveNoInconsistentEdge) {
  const Grid G = grid2(31);
  const auto edges = grid_edges(2, 31, G.t, G.psi, G.g, G.ok);
  EXPECT_EQ(edges.size(), 2u * 31 * 30);
  EXPECT_TRUE(inconsistent_edges(edges, 0.01).empty());
  // The trapezoid rule is exact for a quadratic: only the sine leaves a residue, O(h^3).
  double worst = 0;
  for (const auto& e : edges) worst = std::max(worst, e.relative);
  EXPECT_LT(worst, 1e-3);
}

TEST(BranchCheck, FindsExactlyTheEdgesBetweenTwoBranches) {
  const int m = 11;
  const Grid G = grid2(m, 0.3, 0.05);  // rows with a > 0.3 (i >= 7) on the second branch
  const auto bad = inconsistent_edges(grid_edges(2, m, G.t, G.psi, G.g, G.ok), 0.05);
  ASSERT_EQ(bad.size(), size_t(m));
  for (const auto& e : bad) {
    EXPECT_EQ(e.axis, 0);
    EXPECT_EQ(e.a / m, 6);
    EXPECT_EQ(e.b / m, 7);
    EXPECT_EQ(e.a % m, e.b % m);
  }
}

TEST(BranchCheck, OneDimensionalAndUnusableNodes) {
  // Psi = t^3 on 21 nodes with a jump after node 14; node 3 is unusable (its edges are skipped).
  const int m = 21;
  std::vector<Eigen::VectorXd> t, g;
  std::vector<double> psi;
  std::vector<bool> ok;
  for (int i = 0; i < m; ++i) {
    const double x = -1 + 2.0 * i / (m - 1);
    t.push_back(Eigen::VectorXd::Constant(1, x));
    g.push_back(Eigen::VectorXd::Constant(1, 3 * x * x));
    psi.push_back(x * x * x + (i > 14 ? 0.2 : 0));
    ok.push_back(i != 3);
  }
  const auto edges = grid_edges(1, m, t, psi, g, ok);
  EXPECT_EQ(edges.size(), size_t(m - 1 - 2));
  const auto bad = inconsistent_edges(edges, 0.05);
  ASSERT_EQ(bad.size(), 1u);
  EXPECT_EQ(bad[0].a, 14);
  EXPECT_EQ(bad[0].b, 15);
  EXPECT_THROW(grid_edges(1, m + 1, t, psi, g, ok), std::invalid_argument);
  EXPECT_THROW(grid_edges(3, m, t, psi, g, ok), std::invalid_argument);
}
