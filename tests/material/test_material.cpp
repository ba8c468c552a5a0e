// The full material (spec section 8b) from baked tables of random networks: the value against an
// independent eigen-decomposition, the gradient against central differences of the value and the
// Hessian against central differences of the gradient (in double), at generic points, on and
// near umbilic points (II_x = II_y, II_a = 0), across the switch to the umbilic series, and
// outside the boxes.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cstring>
#include <random>

#include "bake/bake_table.hpp"
#include "material/material.hpp"
#include "tests/common/bake_test_util.hpp"

using namespace yarnhom;

namespace {

// Widths used to put all six strains on one scale in the comparisons.
const double kWidth[6] = {1.2, 1.4, 1.2, 400, 400, 400};

const BakedModel& random_baked() {
  static const BakedModel m = [] {
    Model model;
    unsigned seed = 100;
    for (const Term& t : all_terms()) {
      std::vector<double> lo, hi;
      for (int i : t.indices) {
        Range r = default_range(i, 200, 200);
        lo.push_back(r.lower);
        hi.push_back(r.upper);
      }
      model.networks.push_back(test::random_model_network(t.name, lo, hi, seed++));
    }
    return bake_model(model, "model.h5", 200, 40, 0.01, true);
  }();
  return m;
}

const BakedMaterial& material() {
  static const BakedMaterial mat = make_baked_material(random_baked());
  return mat;
}

// Central differences of the value (gradient) and of the analytic gradient (Hessian), compared
// in units normalized by kWidth.
void check_derivatives(const Strain6& s, const std::string& where) {
  const BakedMaterial& mat = material();
  const MaterialEval e = eval_material(mat, s);
  ASSERT_TRUE(std::isfinite(e.psi) && e.grad.allFinite() && e.hess.allFinite()) << where;
  Strain6 g_fd, gn;
  Eigen::Matrix<double, 6, 6> H_fd, Hn;
  for (int i = 0; i < 6; ++i) {
    // h2 not smaller: the gradient carries rounding of order eps |g| / r near umbilic points,
    // which a smaller step would amplify in the difference quotient.
    const double h1 = 1e-6 * kWidth[i], h2 = 1e-5 * kWidth[i];
    Strain6 a = s, b = s;
    a[i] += h1;
    b[i] -= h1;
    g_fd[i] = (eval_material(mat, a).psi - eval_material(mat, b).psi) / (2 * h1) * kWidth[i];
    gn[i] = e.grad[i] * kWidth[i];
    a = s;
    b = s;
    a[i] += h2;
    b[i] -= h2;
    const Strain6 dg = (eval_material(mat, a).grad - eval_material(mat, b).grad) / (2 * h2);
    for (int j = 0; j < 6; ++j) {
      H_fd(j, i) = dg[j] * kWidth[i] * kWidth[j];
      Hn(j, i) = e.hess(j, i) * kWidth[i] * kWidth[j];
    }
  }
  EXPECT_LT((g_fd - gn).cwiseAbs().maxCoeff(), 1e-6 * (1 + gn.cwiseAbs().maxCoeff()))
      << where << "\nanalytic " << gn.transpose() << "\nfd       " << g_fd.transpose();
  EXPECT_LT((H_fd - Hn).cwiseAbs().maxCoeff(), 1e-5 * (1 + Hn.cwiseAbs().maxCoeff()))
      << where << "\nanalytic\n" << Hn << "\nfd\n" << H_fd;
  EXPECT_LT((e.hess - e.hess.transpose()).cwiseAbs().maxCoeff(), 1e-12 * (1 + e.hess.cwiseAbs().maxCoeff()));
}

}  // namespace

// B_3[g] = c2 g(l1) + (1 - c2) g(l2) by an independent eigen-decomposition, and the whole
// material as the sum of its terms; on the axes (II_a = 0) bending reduces to Psi_3(II_x) +
// Psi_5(II_y).
TEST(Material, ValueMatchesEigenDecomposition) {
  const BakedModel& bm = random_baked();
  const BakedMaterial& mat = material();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int k = 0; k < 50; ++k) {
    Strain6 s;
    s << 0.4 + 0.6 * U(rng), 0.7 * U(rng), 0.4 + 0.6 * U(rng), 200 * U(rng), 150 * U(rng), 200 * U(rng);
    Eigen::Matrix2d K;
    K << s[3], s[4], s[4], s[5];
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(K);
    const double l1 = es.eigenvalues()[1], l2 = es.eigenvalues()[0];
    const double c2 = es.eigenvectors()(0, 1) * es.eigenvectors()(0, 1);
    double ref = bm.psi0;
    for (const BakedTable& tb : bm.tables) {
      BakedTerm t = make_baked_term(tb);
      const auto& idx = tb.term.indices;
      auto g = [&](double lam) {
        double v[2] = {idx.size() == 2 ? s[idx[0]] : lam, lam};
        double j[10];
        eval_baked_jet(t, idx.size() == 2 ? v : &lam, 0, j);
        return j[0];
      };
      if (idx.back() == 3) ref += c2 * g(l1) + (1 - c2) * g(l2);
      else if (idx.back() == 5) ref += c2 * g(l2) + (1 - c2) * g(l1);
      else {
        double v[2] = {s[idx[0]], idx.size() == 2 ? s[idx[1]] : 0};
        double j[10];
        eval_baked_jet(t, v, 0, j);
        ref += j[0];
      }
    }
    EXPECT_NEAR(eval_material(mat, s).psi, ref, 1e-11 * (1 + std::abs(ref)));
  }
  // On the axes.
  const BakedTerm t3 = make_baked_term(*bm.find("3")), t5 = make_baked_term(*bm.find("5"));
  for (double a : {-150.0, 30.0, 120.0})
    for (double c : {-90.0, 30.0, 180.0}) {
      EXPECT_NEAR(eval_bending(t3, 3, 0, a, 0, c).value, eval_baked_1d(t3, a).f, 1e-12 * (1 + std::abs(eval_baked_1d(t3, a).f)));
      EXPECT_NEAR(eval_bending(t5, 5, 0, a, 0, c).value, eval_baked_1d(t5, c).f, 1e-12 * (1 + std::abs(eval_baked_1d(t5, c).f)));
    }
}

TEST(Material, DerivativesAtGenericPoints) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int k = 0; k < 30; ++k) {
    Strain6 s;
    s << 0.4 + 0.6 * U(rng), 0.7 * U(rng), 0.4 + 0.6 * U(rng), 200 * U(rng), 150 * U(rng), 200 * U(rng);
    check_derivatives(s, "generic " + std::to_string(k));
  }
}

TEST(Material, DerivativesOutsideTheBoxes) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int k = 0; k < 15; ++k) {
    Strain6 s;
    s << 0.4 + 1.2 * U(rng), 1.4 * U(rng), 0.4 + 1.2 * U(rng), 400 * U(rng), 300 * U(rng), 400 * U(rng);
    check_derivatives(s, "outside " + std::to_string(k));
  }
}

// Umbilic points (l1 = l2: II_x = II_y, II_a = 0) and their neighbourhood, including both sides
// of the switch to the series (r = 1e-2 knot spacings: 0.0201/m for the 1D tables at 200 knots,
// 0.1026/m for the 2D ones at 40).
TEST(Material, DerivativesAtAndNearUmbilicPoints) {
  std::mt19937 rng(10);
  std::uniform_real_distribution<double> U(-1, 1);
  const double radii[] = {0.0, 1e-12, 1e-8, 1e-4, 0.0200, 0.0202, 0.1020, 0.1030, 0.5, 3.0};
  for (int k = 0; k < 4; ++k) {
    const double m = 150 * U(rng), ang = M_PI * U(rng);
    for (double r : radii) {
      // K = m I + r [[cos 2t, sin 2t], [sin 2t, -cos 2t]]: eigenvalues m +- r.
      Strain6 s;
      s << 0.4 + 0.6 * U(rng), 0.7 * U(rng), 0.4 + 0.6 * U(rng), m + r * std::cos(ang), r * std::sin(ang), m - r * std::cos(ang);
      check_derivatives(s, "umbilic m=" + std::to_string(m) + " r=" + std::to_string(r));
    }
  }
  // Exactly at the rest state.
  check_derivatives(Strain6::Zero(), "rest");
}

// Value, gradient and Hessian continuous across the switch to the series.
TEST(Material, SeriesSwitchIsContinuous) {
  const BakedModel& bm = random_baked();
  for (const char* name : {"3", "5", "13", "25"}) {
    const BakedTerm t = make_baked_term(*bm.find(name));
    const int which = name[std::strlen(name) - 1] - '0';
    const double tau = 1e-2 / t.inv_h[t.dim - 1];
    for (double m : {-120.3, 17.7, 88.1}) {
      const double ang = 0.7;
      auto at = [&](double r) {
        return eval_bending(t, which, 0.31, m + r * std::cos(ang), r * std::sin(ang), m - r * std::cos(ang));
      };
      const BendingEval a = at(tau * (1 - 1e-9)), b = at(tau * (1 + 1e-9));
      const double gs = 1 + a.grad.cwiseAbs().maxCoeff() * 400, hs = 1 + a.hess.cwiseAbs().maxCoeff() * 400 * 400;
      EXPECT_NEAR(a.value, b.value, 1e-10 * (1 + std::abs(a.value))) << name;
      EXPECT_LT((a.grad - b.grad).cwiseAbs().maxCoeff() * 400, 1e-7 * gs) << name;
      // The series is exact for one cubic cell; across a knot within tau its Hessian misses the
      // jump of h''' there times tau, relative ~1e-5 for these random tables (3.9e-4 of hs = 37
      // on term 13 since 2D terms are baked as the network's axis projection, whose y-variation
      // adds N(0, y)'s): 2e-5.
      EXPECT_LT((a.hess - b.hess).cwiseAbs().maxCoeff() * 400 * 400, 2e-5 * hs) << name << "\n" << a.hess << "\n" << b.hess;
    }
  }
}

// With the same table for terms 3 and 5, B_3 + B_5 = tr g(K) = g(l1) + g(l2): invariant under
// rotations of the curvature tensor, as a frame-independent bending model must be.
TEST(Material, SameBendingTablesGiveARotationInvariant) {
  test::Poly p;  // g(l) = l^2/2 + l^3/300 (cubic: reproduced exactly by the table)
  p.c[2][0] = 0.5;
  p.c[3][0] = 1.0 / 300;
  BakedModel m;
  for (const char* name : {"3", "5"})
    m.tables.push_back(bake_function(term_by_name(name), {-200}, {200}, {50}, test::poly_function(p, 1)));
  std::string missing;
  const BakedMaterial mat = make_baked_material(m, "", &missing);
  EXPECT_EQ(missing, "0 1 2 01 02 03 05 12 13 15 23 25");
  for (double th : {0.0, 0.3, 1.1, 2.0}) {
    const double l1 = 120, l2 = -40, c = std::cos(th), s = std::sin(th);
    Strain6 e = Strain6::Zero();
    e[3] = c * c * l1 + s * s * l2;  // R diag(l1, l2) R^T
    e[4] = c * s * (l1 - l2);
    e[5] = s * s * l1 + c * c * l2;
    const double expect = p(l1, 0, 0, 0) + p(l2, 0, 0, 0);
    EXPECT_NEAR(eval_material(mat, e).psi, expect, 1e-9 * std::abs(expect)) << th;
  }
}
