// The HYLC-style spline baseline (accuracy/spline_fit.hpp), the constrained least squares under it
// (accuracy/lsi.hpp) and the linear extrapolation of baked tables (material/baked_eval.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "material/baked_eval.hpp"
#include "accuracy/lsi.hpp"
#include "accuracy/spline_fit.hpp"
#include "core/baked.hpp"
#include "core/jet_layout.hpp"

using namespace yarnhom;

namespace {

// A 1D term sampled from a function with known gradient.
template <class F, class G>
TermData sample_1d(const std::string& name, double lo, double hi, int n, F f, G g) {
  TermData t;
  t.term = term_by_name(name);
  t.n = n;
  t.lower = {lo};
  t.upper = {hi};
  for (int i = 0; i < n; ++i) {
    const double s = lo + (hi - lo) * i / (n - 1);
    t.strain.push_back(s);
    t.energy.push_back(f(s));
    t.gradient.push_back(g(s));
    t.raw.push_back(f(s));
  }
  return t;
}

template <class F>
TermData sample_2d(const std::string& name, double lo0, double hi0, double lo1, double hi1, int n, F f) {
  TermData t;
  t.term = term_by_name(name);
  t.n = n * n;
  t.lower = {lo0, lo1};
  t.upper = {hi0, hi1};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double a = lo0 + (hi0 - lo0) * i / (n - 1), b = lo1 + (hi1 - lo1) * j / (n - 1);
      double v, ga, gb;
      f(a, b, v, ga, gb);
      t.strain.insert(t.strain.end(), {a, b});
      t.energy.push_back(v);
      t.gradient.insert(t.gradient.end(), {ga, gb});
      t.raw.push_back(v);
    }
  return t;
}

double jet_at(const BakedTerm& t, double x, int ch) {
  double j[kMaxJetChannels];
  eval_baked_jet(t, &x, 2, j);
  return j[ch];
}

}  // namespace

TEST(Lsi, NnlsAndInequalityConstrainedLeastSquares) {
  // min |x - (1, -1)|^2, x >= 0  ->  (1, 0).
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(2, 2);
  Eigen::VectorXd b(2);
  b << 1, -1;
  Eigen::VectorXd x = nnls(A, b);
  EXPECT_NEAR(x[0], 1, 1e-12);
  EXPECT_NEAR(x[1], 0, 1e-12);
  // min |x - (2, 2)|^2 s.t. x0 + x1 <= 1 (i.e. -x0 - x1 >= -1)  ->  (0.5, 0.5).
  Eigen::MatrixXd G(1, 2);
  G << -1, -1;
  Eigen::VectorXd h(1);
  h << -1;
  b << 2, 2;
  LsiResult r = solve_lsi(A, b, G, h);
  ASSERT_TRUE(r.feasible);
  EXPECT_NEAR(r.x[0], 0.5, 1e-10);
  EXPECT_NEAR(r.x[1], 0.5, 1e-10);
  // An inactive constraint leaves the unconstrained optimum.
  h << -10;
  r = solve_lsi(A, b, G, h);
  EXPECT_NEAR(r.x[0], 2, 1e-10);
  // Infeasible: x0 >= 1 and -x0 >= 0.
  Eigen::MatrixXd G2(2, 2);
  G2 << 1, 0, -1, 0;
  Eigen::VectorXd h2(2);
  h2 << 1, 0;
  EXPECT_FALSE(solve_lsi(A, b, G2, h2).feasible);
}

TEST(SplineFit, KnotsIncludeZeroAndCoverTheData) {
  KnotAxis a = choose_knots(-0.2, 1.0, 11);
  ASSERT_GE(a.zero, 1);
  EXPECT_NEAR(a.lower + a.zero * a.spacing(), 0.0, 1e-14);
  EXPECT_LE(a.lower, -0.2 + 1e-14);
  EXPECT_GE(a.upper, 1.0 - 1e-14);
  EXPECT_LT(a.upper - a.lower, 1.2 + a.spacing());
  KnotAxis s = choose_knots(-0.7, 0.7, 11);
  EXPECT_EQ(s.zero, 5);
  EXPECT_NEAR(s.lower, -0.7, 1e-14);
  KnotAxis p = choose_knots(0.1, 0.9, 5);
  EXPECT_EQ(p.zero, -1);
  EXPECT_DOUBLE_EQ(p.lower, 0.1);
}

// Data from a cubic that is monotone away from 0: the spline (no smoothing) reproduces it
// exactly, at the knots and between them, and the monotone constraint does not bind.
TEST(SplineFit, CubicDataIsReproducedExactly) {
  auto f = [](double s) { return s * s + 0.5 * s * s * s; };
  auto g = [](double s) { return 2 * s + 1.5 * s * s; };
  TermData d = sample_1d("0", -0.2, 1.0, 41, f, g);
  SplineFitOptions o;
  o.smoothing = 0;
  SplineFitReport rep;
  BakedTable t = fit_spline_term(d, o, &rep);
  EXPECT_EQ(t.extrapolation, kBakedLinear);
  ASSERT_EQ(t.knots[0], 11);
  const double h = t.spacing(0);
  for (int k = 0; k < t.knots[0]; ++k) {
    const double s = t.lower[0] + k * h;
    EXPECT_NEAR(t.f[k], f(s), 1e-9) << "knot " << k;
    EXPECT_NEAR(t.f_x[k], g(s), 1e-8) << "knot " << k;
  }
  const BakedTerm bt = make_baked_term(t);
  for (double s = -0.2; s <= 1.0; s += 0.0137) EXPECT_NEAR(jet_at(bt, s, 0), f(s), 1e-9);
  EXPECT_EQ(rep.minimum_knot, choose_knots(-0.2, 1.0, 11).zero);
  EXPECT_LT(rep.energy_rmse_rel, 1e-9);
  // With the default smoothing the bias stays small.
  BakedTable ts = fit_spline_term(d, SplineFitOptions{}, nullptr);
  const BakedTerm bs = make_baked_term(ts);
  for (double s = -0.2; s <= 1.0; s += 0.05) EXPECT_NEAR(jet_at(bs, s, 0), f(s), 2e-3 * 1.5);
}

// A bicubic that vanishes on both axes is reproduced exactly by the 2D fit when the data
// determine every cell (with too few samples per cell the value-and-gradient data leave twist
// modes free, and the tiny ridge picks one).
TEST(SplineFit, BicubicDataIsReproducedExactly) {
  auto f = [](double x, double y, double& v, double& gx, double& gy) {
    v = x * y * (1 + 0.5 * x - 0.3 * y + 0.2 * x * y);
    gx = y * (1 + x - 0.3 * y + 0.4 * x * y);
    gy = x * (1 + 0.5 * x - 0.6 * y + 0.4 * x * y);
  };
  TermData d = sample_2d("02", -0.2, 1.0, -0.2, 1.0, 31, f);  // the paper preset's 31 x 31
  SplineFitOptions o;
  o.smoothing = 0;
  BakedTable t = fit_spline_term(d, o);
  const BakedTerm bt = make_baked_term(t);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-0.2, 1.0);
  for (int k = 0; k < 200; ++k) {
    Eigen::Vector2d s(U(rng), U(rng));
    double v, gx, gy;
    f(s[0], s[1], v, gx, gy);
    BakedJet2 j = eval_baked_2d(bt, s);
    EXPECT_NEAR(j.f, v, 1e-9);
    EXPECT_NEAR(j.g[0], gx, 1e-8);
    EXPECT_NEAR(j.g[1], gy, 1e-8);
  }
  // Exactly zero on the axes (constrained, not fitted).
  EXPECT_EQ(eval_baked_2d(bt, Eigen::Vector2d(0.0, 0.37)).f, 0.0);
  EXPECT_EQ(eval_baked_2d(bt, Eigen::Vector2d(0.61, 0.0)).f, 0.0);
}

// Non-monotone noisy data: the fit is monotone away from its minimum knot, and so is the linear
// extrapolation (outward slopes >= 0).
TEST(SplineFit, MonotoneAwayFromTheMinimum) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  // A wiggle that makes the data non-monotone around s = 0.39, resolved by the knots.
  auto f = [](double s) { return s * s + 0.5 * s * std::sin(8 * s); };
  auto g = [](double s) { return 2 * s + 0.5 * std::sin(8 * s) + 4 * s * std::cos(8 * s); };
  TermData d = sample_1d("2", -0.2, 1.0, 101, f, g);
  for (int i = 0; i < d.n; ++i) {
    d.energy[i] += 0.01 * noise(rng);
    d.gradient[i] += 0.1 * noise(rng);
  }
  SplineFitReport rep;
  BakedTable t = fit_spline_term(d, SplineFitOptions{}, &rep);
  const BakedTerm bt = make_baked_term(t);
  const double smin = t.lower[0] + rep.minimum_knot * t.spacing(0);
  for (double s = -0.6; s <= 1.6; s += 0.001) {
    const double g = jet_at(bt, s, 1);
    if (s < smin - 1e-9) {
      EXPECT_LE(g, 1e-9) << "s = " << s;
    }
    if (s > smin + 1e-9) {
      EXPECT_GE(g, -1e-9) << "s = " << s;
    }
  }
  // Without the constraint the same data give a non-monotone fit (so the test has teeth).
  SplineFitOptions free;
  free.monotone = false;
  const BakedTerm bf = make_baked_term(fit_spline_term(d, free));
  int wrong = 0;
  for (double s = 0.05; s <= 1.0; s += 0.001) wrong += jet_at(bf, s, 1) < 0;
  EXPECT_GT(wrong, 0);
}

// Linear extrapolation: C1 across the box boundary in 1D, in the edge bands and at the corners;
// zero second derivative along an outside axis; the fit's own basis (hermite_axis_terms) is the
// evaluator's.
TEST(SplineFit, LinearExtrapolationIsC1AndMatchesTheFitBasis) {
  auto f = [](double x, double y, double& v, double& gx, double& gy) {
    v = x * y * (1 + x * x - 0.7 * y) + 0.4 * x * x * y * y * y;
    gx = y * (1 + 3 * x * x - 0.7 * y) + 0.8 * x * y * y * y;
    gy = x * (1 + x * x - 1.4 * y) + 1.2 * x * x * y * y;
  };
  BakedTable t = fit_spline_term(sample_2d("12", -0.7, 0.7, -0.2, 1.0, 9, f), SplineFitOptions{});
  const BakedTerm bt = make_baked_term(t);
  const double eps = 1e-7;
  const double X0 = t.lower[0], X1 = t.upper[0], Y0 = t.lower[1], Y1 = t.upper[1];
  std::vector<Eigen::Vector2d> border = {{X0, 0.3}, {X1, -0.1}, {0.2, Y0}, {-0.3, Y1}, {X0, Y0}, {X1, Y1}, {X0, Y1}, {X1, Y0}};
  for (const auto& p : border) {
    Eigen::Vector2d out = p, in = p;
    for (int k = 0; k < 2; ++k) {
      const double lo = k == 0 ? X0 : Y0, hi = k == 0 ? X1 : Y1;
      if (p[k] == lo) { out[k] -= eps; in[k] += eps; }
      if (p[k] == hi) { out[k] += eps; in[k] -= eps; }
    }
    BakedJet2 a = eval_baked_2d(bt, out), b = eval_baked_2d(bt, in);
    EXPECT_NEAR(a.f, b.f, 1e-5);
    EXPECT_NEAR(a.g[0], b.g[0], 1e-4);
    EXPECT_NEAR(a.g[1], b.g[1], 1e-4);
  }
  // Far outside along x: linear in x.
  BakedJet2 far = eval_baked_2d(bt, Eigen::Vector2d(X1 + 2.0, 0.4));
  EXPECT_EQ(far.H(0, 0), 0.0);
  // The fit's basis is the evaluator's, inside and outside (both axes, corners included).
  KnotAxis ax[2] = {{X0, X1, t.knots[0], -1}, {Y0, Y1, t.knots[1], -1}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1.5, 1.8);
  for (int k = 0; k < 100; ++k) {
    const double s[2] = {U(rng), U(rng)};
    int kn[2][4], ki[2][4];
    double w[2][4];
    const int cx = hermite_axis_terms(ax[0], s[0], 0, kn[0], ki[0], w[0]);
    const int cy = hermite_axis_terms(ax[1], s[1], 0, kn[1], ki[1], w[1]);
    double v = 0;
    const double hx = t.spacing(0), hy = t.spacing(1);
    for (int a = 0; a < cx; ++a)
      for (int b = 0; b < cy; ++b) {
        const size_t q = size_t(kn[0][a]) * t.knots[1] + kn[1][b];
        const double c = ki[0][a] == 0 ? (ki[1][b] == 0 ? t.f[q] : hy * t.f_y[q])
                                        : (ki[1][b] == 0 ? hx * t.f_x[q] : hx * hy * t.f_xy[q]);
        v += w[0][a] * w[1][b] * c;
      }
    EXPECT_NEAR(v, eval_baked_2d(bt, Eigen::Vector2d(s[0], s[1])).f, 1e-10 * (1 + std::abs(v)));
  }
  // 1D: C1 at both ends and linear beyond.
  BakedTable t1 = fit_spline_term(sample_1d("0", -0.2, 1.0, 31, [](double s) { return s * s * (1 + s); },
                                            [](double s) { return 2 * s + 3 * s * s; }),
                                  SplineFitOptions{});
  const BakedTerm b1 = make_baked_term(t1);
  for (double X : {t1.lower[0], t1.upper[0]}) {
    EXPECT_NEAR(jet_at(b1, X - eps, 0), jet_at(b1, X + eps, 0), 1e-5);
    EXPECT_NEAR(jet_at(b1, X - eps, 1), jet_at(b1, X + eps, 1), 1e-4);
  }
  EXPECT_EQ(jet_at(b1, t1.upper[0] + 1, 2), 0.0);
  EXPECT_NEAR(jet_at(b1, t1.upper[0] + 1, 0), jet_at(b1, t1.upper[0], 0) + jet_at(b1, t1.upper[0], 1), 1e-12);
}

// The baked file keeps the extrapolation mode; a linear 1D table whose mode was changed to the
// safeguard is refused by the coefficient check (its stored coefficients are the linear ones).
// In 2D the two modes are now the same first-order continuation (docs/bake.md), so the changed
// mode is read and evaluates identically.
TEST(SplineFit, BakedFileRoundTripAndTamperCheck) {
  Dataset ds;
  ds.pattern = "test";
  ds.source = "synthetic";
  ds.psi0 = 0.25;
  ds.areal_density = 0.3;
  ds.terms.push_back(sample_1d("0", -0.2, 1.0, 21, [](double s) { return s * s; }, [](double s) { return 2 * s; }));
  ds.terms.push_back(sample_2d("01", -0.2, 1.0, -0.7, 0.7, 7, [](double x, double y, double& v, double& gx, double& gy) {
    v = x * y * y;
    gx = y * y;
    gy = 2 * x * y;
  }));
  BakedModel m = fit_splines(ds, "d.h5", SplineFitOptions{});
  const std::string path = (std::filesystem::temp_directory_path() / ("yarnhom_spline_" + std::to_string(::getpid()) + ".h5")).string();
  write_baked(path, m);
  BakedModel r = read_baked(path);
  std::filesystem::remove(path);
  ASSERT_EQ(r.tables.size(), 2u);
  EXPECT_EQ(r.psi0, 0.25);
  EXPECT_EQ(r.areal_density, 0.3);
  for (const BakedTable& t : r.tables) {
    EXPECT_EQ(t.extrapolation, kBakedLinear);
    EXPECT_NO_THROW(make_baked_term(t, path));
    BakedTable bad = t;
    bad.extrapolation = kBakedSafeguard;
    if (t.dim() == 1) {
      EXPECT_THROW(make_baked_term(bad, path), std::invalid_argument) << t.term.name;
    } else {
      const BakedTerm a = make_baked_term(t, path), b = make_baked_term(bad, path);
      for (double x : {-2.0, 0.3, 3.0})
        for (double y : {-2.0, 0.1, 2.0}) EXPECT_EQ(eval_baked_2d(a, {x, y}).f, eval_baked_2d(b, {x, y}).f);
    }
  }
  r.tables[0].extrapolation = "cubic";
  EXPECT_THROW(validate_baked(r, path), std::exception);
}
