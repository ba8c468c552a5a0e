// The safeguard outside the box (spec section 8): continuity checked numerically from both sides
// of every border, third derivatives in 1D, finite and growing energy far outside, and the
// stored coefficients evaluated by the formulas of docs/bake.md alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "bake/bake_table.hpp"
#include "bake/baked_eval.hpp"
#include "tests/bake/bake_test_util.hpp"

using namespace yarnhom;

namespace {

struct Case {
  const char* name;
  std::vector<double> lo, hi;
};

}  // namespace

// Value, f' and f'' continuous at both ends (C2); f''' exactly 0 outside.
TEST(Safeguard, OneDimensionalIsC2AndQuadratic) {
  for (unsigned seed : {1u, 2u, 3u}) {
    ModelNetwork net = test::random_model_network("5", {-230.0}, {230.0}, seed);
    BakedTerm t = make_baked_term(bake_network(net, 200, 100));
    const double W = 460, delta = 1e-7 * W;
    for (double X : {-230.0, 230.0}) {
      double a[4], b[4];
      const double xa = X - delta, xb = X + delta;
      eval_baked_jet(t, &xa, 3, a);
      eval_baked_jet(t, &xb, 3, b);
      // Inside side (a when X is the upper end) and outside side.
      const double* in = X > 0 ? a : b;
      const double* out = X > 0 ? b : a;
      EXPECT_NEAR(in[0], out[0], 4 * delta * std::abs(in[1]) + 1e-13 * (1 + std::abs(in[0])));
      EXPECT_NEAR(in[1], out[1], 4 * delta * std::abs(in[2]) + 1e-10 * std::abs(in[1]) + 1e-16);
      EXPECT_NEAR(in[2], out[2], 4 * delta * std::abs(in[3]) + 1e-8 * std::abs(in[2]) + 1e-18);
      EXPECT_EQ(out[3], 0.0);
    }
    for (double x : {-1e4, -500.0, -231.0, 231.0, 700.0, 1e5}) {
      double j[4];
      eval_baked_jet(t, &x, 3, j);
      EXPECT_EQ(j[3], 0.0);
      EXPECT_TRUE(std::isfinite(j[0]));
    }
  }
}

// Value and gradient continuous across the box boundary and across every border between
// sectors: points on the four lines x = lower/upper, y = lower/upper, extended a box width
// beyond the box on both sides, evaluated just on either side of the line.
TEST(Safeguard, TwoDimensionalIsC1AcrossEveryBorder) {
  const std::vector<Case> cases = {{"02", {-0.2, -0.2}, {1.0, 1.0}},
                                   {"13", {-0.7, -170.0}, {0.7, 170.0}},
                                   {"25", {-0.2, -230.0}, {1.0, 230.0}}};
  unsigned seed = 20;
  int checked = 0;
  for (const Case& c : cases) {
    ModelNetwork net = test::random_model_network(c.name, c.lo, c.hi, seed++);
    BakedTerm t = make_baked_term(bake_network(net, 200, 60));
    const double W[2] = {c.hi[0] - c.lo[0], c.hi[1] - c.lo[1]};
    for (int axis = 0; axis < 2; ++axis)
      for (double X : {c.lo[axis], c.hi[axis]}) {
        const int along = 1 - axis;
        const double delta = 1e-7 * W[axis];
        for (int k = 0; k <= 300; ++k) {
          const double y = c.lo[along] - W[along] + 3 * W[along] * (k + 0.5) / 301;
          double pa[2], pb[2];
          pa[axis] = X - delta;
          pb[axis] = X + delta;
          pa[along] = pb[along] = y;
          double a[10], b[10];
          eval_baked_jet(t, pa, 2, a);
          eval_baked_jet(t, pb, 2, b);
          EXPECT_NE(baked_sector(t, pa), baked_sector(t, pb));
          // Hessian entries d2f/ds_i ds_axis on either side bound the gradient's change.
          auto H = [&](const double* j, int i, int m) { return std::abs(j[jet_ch2(2, std::min(i, m), std::max(i, m))]); };
          const double tol0 = 4 * delta * std::max(std::abs(a[1 + axis]), std::abs(b[1 + axis])) +
                              1e-12 * (1 + std::abs(a[0]));
          EXPECT_NEAR(a[0], b[0], tol0) << c.name << " axis " << axis << " X " << X << " y " << y;
          for (int i = 0; i < 2; ++i) {
            const double tol = 4 * delta * std::max(H(a, i, axis), H(b, i, axis)) + 1e-9 * std::abs(a[1 + i]) + 1e-15;
            EXPECT_NEAR(a[1 + i], b[1 + i], tol) << c.name << " grad " << i << " axis " << axis << " X " << X << " y " << y;
          }
          ++checked;
        }
      }
  }
  EXPECT_EQ(checked, 3 * 4 * 301);
}

// Every sector is reached, and a pure Taylor corner would NOT be C1: the cubic corner terms
// matter (guards against "simplifying" them away).
TEST(Safeguard, SectorsAndCornerCubicTerms) {
  test::Poly p;  // f = x^2 y: f_xxy = 2 at every corner
  p.c[2][1] = 1.0;
  BakedTerm t = make_baked_term(bake_function(term_by_name("01"), {-1, -1}, {1, 1}, {9, 9}, test::poly_function(p, 2)));
  int seen[9] = {};
  for (double x : {-2.0, 0.0, 2.0})
    for (double y : {-2.0, 0.0, 2.0}) {
      const double s[2] = {x, y};
      seen[baked_sector(t, s)]++;
    }
  for (int k = 0; k < 9; ++k) EXPECT_EQ(seen[k], 1) << "sector " << k;
  // Corner (upper, upper) at (1,1), 1 beyond in x and 0.5 in y: the extension there is
  // f + f_x dx + f_y dy + (f_xx dx^2 + 2 f_xy dx dy + f_yy dy^2)/2 + f_xxy dx^2 dy/2 + f_xyy dx dy^2/2.
  const double dx = 1.0, dy = 0.5;
  const double f = 1, fx = 2, fy = 1, fxx = 2, fxy = 2, fyy = 0, fxxy = 2, fxyy = 0;
  const double s[2] = {1 + dx, 1 + dy};
  double j[10];
  eval_baked_jet(t, s, 3, j);
  EXPECT_NEAR(j[0], f + fx * dx + fy * dy + 0.5 * (fxx * dx * dx + 2 * fxy * dx * dy + fyy * dy * dy) +
                        0.5 * fxxy * dx * dx * dy + 0.5 * fxyy * dx * dy * dy, 1e-12);
  EXPECT_NEAR(j[7], fxxy, 1e-12);  // f_xxy constant in a corner
}

// Far outside: finite for random networks; growing along every outward ray for a function
// whose boundary data grow outward (f' . n > 0 and f'' > 0 on the boundary, no mixed third
// derivatives), which is what the strain-concentration loss trains for.
TEST(Safeguard, FiniteAndGrowingFarOutside) {
  ModelNetwork net = test::random_model_network("23", {-0.2, -200.0}, {1.0, 200.0}, 31);
  BakedTerm t = make_baked_term(bake_network(net, 200, 50));
  for (double x : {-1e3, -5.0, 0.4, 7.0, 1e4})
    for (double y : {-1e6, -900.0, 0.0, 500.0, 1e5}) {
      BakedJet2 r = eval_baked_2d(t, {x, y});
      EXPECT_TRUE(std::isfinite(r.f) && r.g.allFinite() && r.H.allFinite()) << x << " " << y;
    }
  test::Poly p;  // x^2 + x y/2 + y^2 + 0.1 (x^3 + y^3) on [-1, 1]^2
  p.c[2][0] = 1; p.c[1][1] = 0.5; p.c[0][2] = 1; p.c[3][0] = 0.1; p.c[0][3] = 0.1;
  BakedTerm q = make_baked_term(bake_function(term_by_name("01"), {-1, -1}, {1, 1}, {21, 21}, test::poly_function(p, 2)));
  for (int k = 0; k < 64; ++k) {
    const double ang = 2 * M_PI * (k + 0.3) / 64, cx = std::cos(ang), cy = std::sin(ang);
    double prev = -1e300;
    for (int r = 0; r <= 400; ++r) {
      const double rad = 0.05 * r;  // out to 20 box half-widths
      const double f = eval_baked_2d(q, {rad * cx, rad * cy}).f;
      if (rad > 1.5) {
        EXPECT_GT(f, prev) << "ray " << k << " radius " << rad;
      }
      prev = f;
    }
  }
  test::Poly p1;  // 1D: x^2 + 0.2 x^3 on [-1, 2]: f' n > 0 and f'' > 0 at both ends
  p1.c[2][0] = 1; p1.c[3][0] = 0.2;
  BakedTerm q1 = make_baked_term(bake_function(term_by_name("0"), {-1}, {2}, {50}, test::poly_function(p1, 1)));
  double lo_prev = -1e300, hi_prev = -1e300;
  for (int r = 0; r < 200; ++r) {
    const double a = -1 - 0.5 * r, b = 2 + 0.5 * r;
    const double fa = eval_baked_1d(q1, a).f, fb = eval_baked_1d(q1, b).f;
    EXPECT_GT(fa, lo_prev);
    EXPECT_GT(fb, hi_prev);
    lo_prev = fa;
    hi_prev = fb;
  }
}

// The stored coefficients, evaluated with the formulas of docs/bake.md (written out here
// independently of the evaluator), give the evaluator's values outside the box.
TEST(Safeguard, StoredCoefficientsReproduceTheExtension) {
  ModelNetwork n1 = test::random_model_network("1", {-0.7}, {0.7}, 41);
  BakedTable t1 = bake_network(n1, 200, 100);
  BakedTerm e1 = make_baked_term(t1);
  for (double x : {-3.0, -0.71, 0.75, 4.0}) {
    const auto& c = x < 0 ? t1.safeguard_lower : t1.safeguard_upper;
    EXPECT_NEAR(eval_baked_1d(e1, x).f, c[0] * x * x + c[1] * x + c[2], 1e-10 * (1 + std::abs(c[2])));
  }
  ModelNetwork n2 = test::random_model_network("15", {-0.7, -200.0}, {0.7, 200.0}, 42);
  BakedTable t2 = bake_network(n2, 200, 40);
  BakedTerm e2 = make_baked_term(t2);
  // Edge x_upper at a knot y_j: F = g0 + g1 t + g2 t^2/2, t = x - upper_x.
  const int j = 17;
  const double y = knot_position(-200, 200, 40, j), tt = 0.3;
  const double* g = t2.edges[1].data() + 6 * j;
  EXPECT_NEAR(eval_baked_2d(e2, {0.7 + tt, y}).f, g[0] + g[2] * tt + 0.5 * g[4] * tt * tt, 1e-10 * (1 + std::abs(g[0])));
  // Its derivative along the edge: g0' + g1' t + g2' t^2/2.
  EXPECT_NEAR(eval_baked_2d(e2, {0.7 + tt, y}).g[1], g[1] + g[3] * tt + 0.5 * g[5] * tt * tt, 1e-8 * (1 + std::abs(g[1])));
  // Between edge knots each g_k is the cubic Hermite interpolant of (g_k, g_k') (docs/bake.md):
  // evaluated from the stored columns alone, at a third of the way from knot j to j + 1.
  {
    const double hy = 400.0 / 39, v = 1.0 / 3;
    const double H00 = 1 - 3 * v * v + 2 * v * v * v, H10 = v - 2 * v * v + v * v * v, H01 = 3 * v * v - 2 * v * v * v,
                 H11 = v * v * v - v * v;
    const double* g1 = t2.edges[1].data() + 6 * (j + 1);
    double gk[3];
    for (int k = 0; k < 3; ++k)
      gk[k] = H00 * g[2 * k] + hy * H10 * g[2 * k + 1] + H01 * g1[2 * k] + hy * H11 * g1[2 * k + 1];
    const double ref = gk[0] + gk[1] * tt + 0.5 * gk[2] * tt * tt;
    EXPECT_NEAR(eval_baked_2d(e2, {0.7 + tt, y + v * hy}).f, ref, 1e-10 * (1 + std::abs(ref)));
  }
  // Corner (lower, upper): x below, y above.
  const auto& a = t2.corners[2];
  const double dx = -0.4, dy = 55;
  const double ref = a[0] + a[1] * dx + a[2] * dy + 0.5 * a[3] * dx * dx + a[4] * dx * dy + 0.5 * a[5] * dy * dy +
                     0.5 * a[6] * dx * dx * dy + 0.5 * a[7] * dx * dy * dy;
  EXPECT_NEAR(eval_baked_2d(e2, {-0.7 + dx, 200 + dy}).f, ref, 1e-10 * (1 + std::abs(ref)));
}

// A tampered coefficient is refused, with the file and the table named.
TEST(Safeguard, TamperedCoefficientsRefused) {
  ModelNetwork n = test::random_model_network("02", {-0.2, -0.2}, {1.0, 1.0}, 43);
  BakedTable t = bake_network(n, 200, 20);
  t.corners[3][0] *= 1.001;
  try {
    make_baked_term(t, "run/baked.h5");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("run/baked.h5"), std::string::npos) << m;
    EXPECT_NE(m.find("/tables/02"), std::string::npos) << m;
    EXPECT_NE(m.find("corner_upper_upper"), std::string::npos) << m;
  }
}

// A diverging simulation may pass NaN or infinite strains: the result is NaN or infinite, never
// a crash or a read out of the table.
TEST(Safeguard, NonFiniteStrainsGiveNonFiniteResults) {
  ModelNetwork n2 = test::random_model_network("02", {-0.2, -0.2}, {1.0, 1.0}, 44);
  BakedTerm t2 = make_baked_term(bake_network(n2, 200, 20));
  ModelNetwork n1 = test::random_model_network("0", {-0.2}, {1.0}, 45);
  BakedTerm t1 = make_baked_term(bake_network(n1, 50, 20));
  const double nan = std::nan(""), inf = INFINITY;
  EXPECT_TRUE(std::isnan(eval_baked_2d(t2, {nan, 0.3}).f));
  EXPECT_TRUE(std::isnan(eval_baked_2d(t2, {0.3, nan}).g[1]));
  EXPECT_FALSE(std::isfinite(eval_baked_2d(t2, {inf, 0.3}).f));
  EXPECT_TRUE(std::isnan(eval_baked_1d(t1, nan).f));
  EXPECT_FALSE(std::isfinite(eval_baked_1d(t1, -inf).f));
}

// ---- The safeguard rises outward by construction (issue 12) ----------------------------------

namespace {

// Walks outward rays of a baked 2D term from its boundary to the box scaled 3x about its
// centre and checks, along each, that the energy and its slope along the ray never decrease
// and that the slope is never negative. An outward ray starts at a boundary point and goes in a
// direction of the normal cone there: the outward normal on an edge, any direction between the
// two normals at a corner. Every point outside the box lies on exactly one such ray (the one from
// its nearest boundary point), so these rays sweep all eight sectors. Returns the number of rays.
int check_outward_rays_2d(const BakedTerm& t, int rays, unsigned seed, const std::string& what) {
  // A slope scale of the table, per unit ray parameter (the ray directions are half-widths long).
  double slope_scale = 0;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const double s[2] = {t.lo[0] + (t.hi[0] - t.lo[0]) * i / 20, t.lo[1] + (t.hi[1] - t.lo[1]) * j / 20};
      double jet[3];
      eval_baked_jet(t, s, 1, jet);
      slope_scale = std::max(slope_scale, std::abs(jet[1]) * 0.5 * (t.hi[0] - t.lo[0]) + std::abs(jet[2]) * 0.5 * (t.hi[1] - t.lo[1]));
    }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double H[2] = {0.5 * (t.hi[0] - t.lo[0]), 0.5 * (t.hi[1] - t.lo[1])};
  const int steps = 200;
  int failures = 0;
  for (int r = 0; r < rays; ++r) {
    double p[2], v[2];
    if (r % 5 == 0) {  // a corner, a direction of its quadrant
      const int c = int(U(rng) * 4) & 3;
      const double sx = (c & 1) ? 1 : -1, sy = (c & 2) ? 1 : -1, ang = 0.5 * M_PI * U(rng);
      p[0] = sx > 0 ? t.hi[0] : t.lo[0];
      p[1] = sy > 0 ? t.hi[1] : t.lo[1];
      v[0] = sx * H[0] * std::cos(ang);
      v[1] = sy * H[1] * std::sin(ang);
    } else {  // an edge point (never a corner), its outward normal
      const int e = int(U(rng) * 4) & 3, axis = e / 2, along = 1 - axis;
      const double sgn = (e % 2) ? 1 : -1;
      p[axis] = sgn > 0 ? t.hi[axis] : t.lo[axis];
      p[along] = t.lo[along] + (t.hi[along] - t.lo[along]) * (0.001 + 0.998 * U(rng));
      v[axis] = sgn * H[axis];
      v[along] = 0;
    }
    // Ray parameter s in [0, smax]: the point p + s v reaches the 3x box when one coordinate
    // is 2 half-widths beyond the box.
    double smax = 1e300;
    for (int k = 0; k < 2; ++k)
      if (v[k] != 0) smax = std::min(smax, 2 * H[k] / std::abs(v[k]));
    std::vector<double> F(steps + 1), S(steps + 1);
    double scaleF = 0, scaleS = 0;
    for (int k = 0; k <= steps; ++k) {
      const double s = smax * k / steps;
      BakedJet2 j = eval_baked_2d(t, {p[0] + s * v[0], p[1] + s * v[1]});
      F[k] = j.f;
      S[k] = j.g[0] * v[0] + j.g[1] * v[1];  // d F / d s
      scaleF = std::max(scaleF, std::abs(F[k]));
      scaleS = std::max(scaleS, std::abs(S[k]));
    }
    // Rounding: the repaired boundary slope is 0 to within the table's arithmetic.
    const double tolF = 1e-11 * (1 + scaleF), tolS = 1e-9 * scaleS + 1e-10 * slope_scale;
    bool ok = true;
    for (int k = 0; k <= steps; ++k) {
      ok = ok && S[k] >= -tolS;
      if (k > 0) ok = ok && F[k] >= F[k - 1] - tolF && S[k] >= S[k - 1] - tolS;
    }
    if (!ok && ++failures <= 3)
      ADD_FAILURE() << what << ": ray " << r << " from (" << p[0] << ", " << p[1] << ") along (" << v[0] << ", " << v[1]
                    << "): energy or outward slope decreases (slope at the boundary " << S[0] << ")";
  }
  EXPECT_EQ(failures, 0) << what;
  return rays;
}

// Both ends of a 1D term, to 3x the box.
void check_outward_1d(const BakedTerm& t, const std::string& what) {
  const double H = 0.5 * (t.hi[0] - t.lo[0]);
  double slope_scale = 0;
  for (int i = 0; i <= 100; ++i) slope_scale = std::max(slope_scale, std::abs(eval_baked_1d(t, t.lo[0] + 2 * H * i / 100).df));
  for (int e = 0; e < 2; ++e) {
    const double sgn = e ? 1 : -1, X = e ? t.hi[0] : t.lo[0];
    double Fp = -1e300, Sp = -1e300;
    for (int k = 0; k <= 1000; ++k) {
      const BakedJet1 j = eval_baked_1d(t, X + sgn * 2 * H * k / 1000);
      const double S = sgn * j.df;
      const double tol = 1e-9 * std::abs(S) + 1e-10 * slope_scale;
      EXPECT_GE(S, -tol) << what << " end " << e << " step " << k;
      EXPECT_GE(S, Sp - tol) << what << " end " << e << " step " << k;
      EXPECT_GE(j.f, Fp - 1e-11 * (1 + std::abs(j.f))) << what << " end " << e << " step " << k;
      EXPECT_GE(j.d2f, -1e-9 * slope_scale / H) << what << " end " << e << " step " << k;
      Fp = j.f;
      Sp = S;
    }
  }
}

}  // namespace

// Random networks of the paper's size over the boxes of real terms: their boundaries have
// inward slopes and negative curvatures somewhere (checked: the bake reports departures), and
// the baked energy still rises outward along 1,000 rays per table, in all eight sectors.
TEST(Safeguard, RisesOutwardAlongEveryRayForRandomNetworks) {
  const std::vector<Case> cases2 = {{"01", {-0.2, -0.7}, {1.0, 0.7}},
                                    {"13", {-0.7, -170.0}, {0.7, 170.0}},
                                    {"25", {-0.2, -230.0}, {1.0, 230.0}}};
  int departed = 0, repaired = 0;
  unsigned seed = 100;
  for (const Case& c : cases2)
    for (int k = 0; k < 2; ++k) {
      ModelNetwork net = test::random_model_network(c.name, c.lo, c.hi, seed++);
      BakeReport rep;
      BakedTerm t = make_baked_term(bake_network(net, 200, 40, &rep));
      departed += rep.departures.any();
      repaired += rep.repair.changed();
      check_outward_rays_2d(t, 1000, seed, std::string(c.name) + " seed " + std::to_string(seed));
    }
  for (const char* name : {"0", "3"})
    for (unsigned s = 0; s < 4; ++s) {
      const std::vector<double> lo = name[0] == '0' ? std::vector<double>{-0.2} : std::vector<double>{-200.0};
      const std::vector<double> hi = name[0] == '0' ? std::vector<double>{1.0} : std::vector<double>{170.0};
      ModelNetwork net = test::random_model_network(name, lo, hi, 200 + s);
      BakeReport rep;
      BakedTerm t = make_baked_term(bake_network(net, 200, 40, &rep));
      departed += rep.departures.any();
      repaired += rep.repair.changed();
      check_outward_1d(t, std::string(name) + " seed " + std::to_string(200 + s));
    }
  // The test means something only if the networks needed the safeguard's care.
  EXPECT_GE(departed + repaired, 4);
  EXPECT_GE(repaired, 2);
}

// Where the boundary already rises outward with positive curvature, nothing departs from the
// paper's continuation: the band curvature is the table's d2f/dn2 and the table is untouched.
TEST(Safeguard, PaperContinuationWhereTheBoundaryIsAlreadySafe) {
  test::Poly p;  // x^2 + x y/2 + y^2 + 0.1 (x^3 + y^3) on [-1, 1]^2: outward slopes > 0, curvatures > 0
  p.c[2][0] = 1; p.c[1][1] = 0.5; p.c[0][2] = 1; p.c[3][0] = 0.1; p.c[0][3] = 0.1;
  BakeReport rep;
  BakedTable tb = bake_function(term_by_name("01"), {-1, -1}, {1, 1}, {21, 21}, test::poly_function(p, 2), &rep);
  EXPECT_FALSE(rep.repair.changed());
  EXPECT_FALSE(rep.departures.any()) << rep.summary(tb);
  EXPECT_EQ(rep.summary(tb), "the paper's continuation");
  // Band curvature = d2f/dx2 = 2 + 0.6 x on the x edges.
  for (int j = 0; j < 21; ++j) {
    EXPECT_NEAR(tb.edges[0][6 * j + 4], 2 - 0.6, 1e-9);
    EXPECT_NEAR(tb.edges[1][6 * j + 4], 2 + 0.6, 1e-9);
  }
  BakedTerm t = make_baked_term(tb);
  check_outward_rays_2d(t, 1000, 7, "polynomial");
}

// A 1D end whose curvature is negative (the quadratic would turn down): the table is repaired
// in its outer 5 %, keeping C2 with the (repaired) table, and the energy rises to 3x the box.
TEST(Safeguard, NegativeEndCurvatureIsRepairedInTheTable) {
  test::Poly p;  // f = x - 0.3 x^3 on [-1, 1]: f'(1) = 0.1 > 0 but f''(1) = -1.8 < 0; f'(-1) = 0.1 (outward -0.1)
  p.c[1][0] = 1; p.c[3][0] = -0.3;
  BakeReport rep;
  BakedTable tb = bake_function(term_by_name("0"), {-1}, {1}, {200}, test::poly_function(p, 1), &rep);
  ASSERT_EQ(rep.repair.sides.size(), 2u);
  EXPECT_TRUE(rep.repair.sides[1].curvature_raised);
  EXPECT_TRUE(rep.repair.sides[0].repaired);  // the lower end's outward slope was -0.1
  // Untouched away from the ends, by design: the layer is 5 % of the box wide.
  BakedTable raw = bake_function(term_by_name("0"), {-1}, {1}, {200}, test::poly_function(p, 1), nullptr, false);
  int changed_inside = 0;
  for (int k = 0; k < 200; ++k) {
    const double x = knot_position(-1, 1, 200, k);
    if (std::abs(x) < 0.9 - 1e-12) changed_inside += tb.f[k] != raw.f[k] || tb.f_x[k] != raw.f_x[k];
  }
  EXPECT_EQ(changed_inside, 0);
  EXPECT_LT(rep.repair.max_change, 0.01 * rep.repair.range);
  BakedTerm t = make_baked_term(tb);
  check_outward_1d(t, "x - 0.3 x^3");
  // C2 at the ends with the repaired table.
  for (double X : {-1.0, 1.0}) {
    const double d = 1e-7;
    const BakedJet1 in = eval_baked_1d(t, X - (X > 0 ? d : -d)), out = eval_baked_1d(t, X + (X > 0 ? d : -d));
    EXPECT_NEAR(in.d2f, out.d2f, 1e-4 * (1 + std::abs(in.d2f)));
    EXPECT_NEAR(in.df, out.df, 1e-5);
  }
}

// The 2D repair: after it, the outward slope is >= 0 along every edge, between knots too; the
// knots farther than the layer from every edge are untouched.
TEST(Safeguard, TwoDimensionalRepairMakesEveryOutwardSlopeNonNegative) {
  ModelNetwork net = test::random_model_network("12", {-0.7, -0.2}, {0.7, 1.0}, 77);
  BakeReport rep;
  BakedTable tb = bake_network(net, 200, 60, &rep);
  BakedTable raw = bake_network(net, 200, 60, nullptr, false);
  EXPECT_TRUE(rep.repair.changed()) << "the test needs a network with an inward slope somewhere";
  BakedTerm t = make_baked_term(tb);
  const double lo[2] = {-0.7, -0.2}, hi[2] = {0.7, 1.0};
  for (int e = 0; e < 4; ++e) {
    const int axis = e / 2, along = 1 - axis;
    const double sgn = e % 2 ? 1 : -1;
    for (int k = 0; k <= 2000; ++k) {
      double s[2];
      s[axis] = sgn > 0 ? hi[axis] : lo[axis];
      s[along] = lo[along] + (hi[along] - lo[along]) * k / 2000.0;
      double j[6];
      eval_baked_jet(t, s, 1, j);
      EXPECT_GE(sgn * j[1 + axis], -1e-10) << "edge " << e << " at " << s[along];
    }
  }
  int changed_inside = 0;
  for (int i = 0; i < 60; ++i)
    for (int jj = 0; jj < 60; ++jj) {
      const double x = knot_position(-0.7, 0.7, 60, i), y = knot_position(-0.2, 1.0, 60, jj);
      const bool deep = x > -0.7 + 0.07 + 1e-12 && x < 0.7 - 0.07 - 1e-12 && y > -0.2 + 0.06 + 1e-12 && y < 1.0 - 0.06 - 1e-12;
      const size_t q = size_t(i) * 60 + jj;
      if (deep) changed_inside += tb.f[q] != raw.f[q] || tb.f_x[q] != raw.f_x[q] || tb.f_y[q] != raw.f_y[q] || tb.f_xy[q] != raw.f_xy[q];
    }
  EXPECT_EQ(changed_inside, 0);
}
