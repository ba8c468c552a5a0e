// The collapse guard (material/collapse_guard.hpp): derivatives against finite differences,
// zero inside the box, C2 at its edge, invariant under a rotation of the curvature tensor, and
// what issue 38 asks of a simulated material: towards a sheared-flat triangle, a crushed
// direction and a fold ten times tighter than the box, the energy the simulator loads (a baked
// file, and the same material in HYLC's JSON) rises monotonically, with its gradient, to orders
// of magnitude above anything inside the box.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "core/baked.hpp"
#include "material/collapse_guard.hpp"
#include "material/hylc_material.hpp"
#include "material/material_source.hpp"
#include "tests/common/poly_material.hpp"

namespace yarnhom {
namespace {

namespace fs = std::filesystem;

// A guard with k = 2 J/m^2 around HYLC's default box.
CollapseGuard test_guard() {
  CollapseGuard g;
  g.scale = 2.0;
  g.curvature_limit = 10.5 * g.box.curvature;
  return g;
}

MaterialEval guard_at(const CollapseGuard& g, const Strain6& s) {
  MaterialEval e;
  add_collapse_guard(g, s, e);
  return e;
}

TEST(CollapseGuard, ProfileDerivativesMatchFiniteDifferences) {
  for (double z : {0.01, 0.2, 0.5, 0.8, 0.95}) {
    const double h = 1e-6 * (1 - z);
    const GuardJet p = guard_profile(z), a = guard_profile(z + h), b = guard_profile(z - h);
    EXPECT_NEAR(p.d1, (a.v - b.v) / (2 * h), 1e-6 * (1 + std::abs(p.d1))) << z;
    EXPECT_NEAR(p.d2, (a.d1 - b.d1) / (2 * h), 1e-6 * (1 + std::abs(p.d2))) << z;
    EXPECT_NEAR(p.d3, (a.d2 - b.d2) / (2 * h), 1e-6 * (1 + std::abs(p.d3))) << z;
  }
  const GuardJet zero = guard_profile(0.0), before = guard_profile(-0.3);
  EXPECT_EQ(zero.v, 0.0);
  EXPECT_EQ(zero.d1, 0.0);
  EXPECT_EQ(zero.d2, 0.0);
  EXPECT_EQ(before.v, 0.0);
  EXPECT_NEAR(guard_profile(1e-9).d3, 6.0, 1e-6);  // the third derivative's jump at the edge
  EXPECT_TRUE(std::isinf(guard_profile(1.0).v));
}

TEST(CollapseGuard, ZeroInsideTheBoxWithItsDerivatives) {
  const CollapseGuard g = test_guard();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int n = 0; n < 200; ++n) {
    // Principal curvatures within +-200, any axes.
    const double l1 = 200 * U(rng), l2 = 200 * U(rng), phi = M_PI * U(rng), c = std::cos(phi), sn = std::sin(phi);
    Strain6 s;
    s << 0.4 + 0.6 * U(rng), 0.7 * U(rng), 0.4 + 0.6 * U(rng), c * c * l1 + sn * sn * l2, c * sn * (l1 - l2),
        sn * sn * l1 + c * c * l2;
    const MaterialEval e = guard_at(g, s);
    EXPECT_EQ(e.psi, 0.0) << s.transpose();
    EXPECT_EQ(e.grad.norm(), 0.0);
    EXPECT_EQ(e.hess.norm(), 0.0);
  }
}

TEST(CollapseGuard, GradientAndHessianMatchFiniteDifferencesOutsideTheBox) {
  const CollapseGuard g = test_guard();
  std::vector<Strain6> points;
  Strain6 s;
  s << -0.5, 0.85, 1.6, 0, 0, 0;  // crushed x, sheared, stretched y
  points.push_back(s);
  s << 1.8, -0.8, -0.45, 50, 10, -20;
  points.push_back(s);
  s << 0.1, 0.1, 0.1, 900, 150, -300;  // one principal curvature beyond the bound
  points.push_back(s);
  s << 0.0, 0.0, 0.0, -700, 300, 500;  // both, of opposite signs
  points.push_back(s);
  s << 0.0, 0.0, 0.0, 800, 1e-3, 800;  // next to an umbilic point (the series branch)
  points.push_back(s);
  for (const Strain6& p : points) {
    const MaterialEval e = guard_at(g, p);
    ASSERT_GT(e.psi, 0.0) << p.transpose();
    for (int k = 0; k < 6; ++k) {
      const double h = k < 3 ? 1e-6 : 1e-3;
      Strain6 a = p, b = p;
      a[k] += h;
      b[k] -= h;
      const MaterialEval ea = guard_at(g, a), eb = guard_at(g, b);
      const double gscale = 1e-6 * (1 + e.grad.cwiseAbs().maxCoeff());
      EXPECT_NEAR(e.grad[k], (ea.psi - eb.psi) / (2 * h), gscale) << k << " at " << p.transpose();
      for (int j = 0; j < 6; ++j) {
        const double hs = 1e-5 * (1 + e.hess.cwiseAbs().maxCoeff());
        EXPECT_NEAR(e.hess(j, k), (ea.grad[j] - eb.grad[j]) / (2 * h), hs) << j << "," << k << " at " << p.transpose();
      }
    }
  }
}

TEST(CollapseGuard, ContinuousToSecondOrderAtTheBoxEdge) {
  const CollapseGuard g = test_guard();
  // Just outside each edge the value, gradient and Hessian are O(d^3), O(d^2), O(d).
  const double d = 1e-4;
  Strain6 s = Strain6::Zero();
  s[1] = g.box.hi[1] + d;
  MaterialEval e = guard_at(g, s);
  const double w = 1 - g.box.hi[1];
  EXPECT_NEAR(e.psi, g.scale * std::pow(d / w, 3), 1e-3 * g.scale * std::pow(d / w, 3));
  EXPECT_LT(std::abs(e.grad[1]), 4 * g.scale * d * d / (w * w * w));
  EXPECT_LT(std::abs(e.hess(1, 1)), 7 * g.scale * d / (w * w * w));
  s = Strain6::Zero();
  s[3] = g.box.curvature + 1e-2;  // 1e-2 /m beyond a 200 /m bound
  e = guard_at(g, s);
  const double wc = g.curvature_limit - g.box.curvature, z = 1e-2 / wc;
  EXPECT_GT(e.psi, 0.0);
  EXPECT_NEAR(e.hess(3, 3), g.scale * 6 * z / (wc * wc), 1e-3 * g.scale * 6 * z / (wc * wc));  // psi'' = 6z + O(z^2)
}

TEST(CollapseGuard, CurvaturePartDependsOnThePrincipalCurvaturesOnly) {
  const CollapseGuard g = test_guard();
  const double l1 = 1200, l2 = -350;
  double first = NAN;
  for (double phi : {0.0, 0.3, 1.1, 2.0}) {
    const double c = std::cos(phi), sn = std::sin(phi);
    Strain6 s;
    s << 0, 0, 0, c * c * l1 + sn * sn * l2, c * sn * (l1 - l2), sn * sn * l1 + c * c * l2;
    const double v = guard_at(g, s).psi;
    if (std::isnan(first)) first = v;
    EXPECT_NEAR(v, first, 1e-10 * first) << phi;
  }
  // tr g(K): the two principal curvatures' profiles summed.
  const double w = g.curvature_limit - g.box.curvature;
  const double expect = g.scale * guard_profile((l1 - g.box.curvature) / w).v + g.scale * guard_profile((350 - g.box.curvature) / w).v;
  EXPECT_NEAR(first, expect, 1e-10 * expect);
}

// The material of the simulator's tests (quadratic shear 2 s_a^2: soft, as a knit's), baked,
// written and loaded the way `sim` loads it; and its HYLC export.
struct LoadedPair {
  LoadedMaterial baked, hylc;
  double box_max = 0;  // the largest total energy on a grid of the box (tables alone)
};

LoadedPair load_test_materials() {
  const fs::path dir = fs::temp_directory_path() / ("yarnhom_guard_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  BakedModel m = test::poly_baked_model(test::simple_cloth_terms(), 0.0, 41, 21);
  for (BakedTable& t : m.tables) {  // the provenance a file carries
    t.desc.input_dim = t.dim();
    t.norm.center.assign(t.dim(), 0.0);
    t.norm.halfwidth.assign(t.dim(), 1.0);
  }
  write_baked((dir / "baked.h5").string(), m);
  write_hylc_material((dir / "hylc.json").string(), hylc_from_baked(m, 0.2, 0.0));
  LoadedPair p{load_material((dir / "baked.h5").string()), load_material((dir / "hylc.json").string())};
  fs::remove_all(dir);
  const BakedMaterial tables = make_baked_material(m);
  for (double sx = -0.2; sx <= 1.0 + 1e-9; sx += 0.1)
    for (double sa = -0.7; sa <= 0.7 + 1e-9; sa += 0.1)
      for (double sy = -0.2; sy <= 1.0 + 1e-9; sy += 0.1)
        for (double k : {-200.0, 0.0, 200.0}) {
          Strain6 s;
          s << sx, sa, sy, k, 0, k;
          p.box_max = std::max(p.box_max, eval_material(tables, s).psi);
        }
  return p;
}

// Along s(t) = s0 + t (s1 - s0), t in [0, 1]: the energy and its derivative along the path
// rise monotonically, and at the end the energy is above `factor` times the box's largest.
void expect_rises(const MaterialFn& fn, const Strain6& s0, const Strain6& s1, double box_max, const char* what) {
  const Strain6 dir = s1 - s0;
  double last_psi = -INFINITY, last_slope = -INFINITY;
  for (int i = 0; i <= 400; ++i) {
    const Strain6 s = s0 + (i / 400.0) * dir;
    const MaterialEval e = fn(s);
    const double slope = e.grad.dot(dir);
    ASSERT_TRUE(std::isfinite(e.psi)) << what << " at " << s.transpose();
    EXPECT_GE(e.psi, last_psi - 1e-12 * std::abs(last_psi)) << what << " at " << s.transpose();
    EXPECT_GE(slope, last_slope - 1e-9 * std::abs(last_slope)) << what << " at " << s.transpose();
    last_psi = e.psi;
    last_slope = slope;
  }
  EXPECT_GT(last_psi, 100 * box_max) << what << ": the box's largest energy is " << box_max;
  EXPECT_GT(last_slope, 100 * box_max) << what;
}

TEST(CollapseGuard, LoadedMaterialsRefuseCollapseByTheirEnergy) {
  const LoadedPair p = load_test_materials();
  ASSERT_TRUE(p.baked.guard && p.hylc.guard);
  ASSERT_GT(p.box_max, 1.0);
  for (const LoadedMaterial* m : {&p.baked, &p.hylc}) {
    Strain6 a = Strain6::Zero(), b = Strain6::Zero();
    b[1] = 0.999;
    expect_rises(m->fn, a, b, p.box_max, (m->kind + ": shear towards 0.999").c_str());
    b = Strain6::Zero();
    b[1] = -0.999;
    expect_rises(m->fn, a, b, p.box_max, (m->kind + ": shear towards -0.999").c_str());
    b = Strain6::Zero();
    b[0] = -0.99;
    expect_rises(m->fn, a, b, p.box_max, (m->kind + ": s_x towards -0.99").c_str());
    b = Strain6::Zero();
    b[2] = -0.99;
    expect_rises(m->fn, a, b, p.box_max, (m->kind + ": s_y towards -0.99").c_str());
    b = Strain6::Zero();
    b[3] = 2000;  // 10 x the box's 200 /m
    expect_rises(m->fn, a, b, p.box_max, (m->kind + ": II_x towards 10 x the box").c_str());
    b = Strain6::Zero();
    b[3] = b[5] = -2000;
    expect_rises(m->fn, a, b, p.box_max, (m->kind + ": both curvatures towards -10 x the box").c_str());
  }
}

TEST(CollapseGuard, TheValueAlonePathIsTheMaterialsPsiBitForBit) {
  // material_value (the energy evaluations' path: tables' values, the curvature mixing's value,
  // the guard's) equals the full evaluation's psi exactly, inside and beyond the tables' boxes,
  // at umbilic points (the mixing's series branch), beyond the guard's sides and its curvature
  // bound; HYLC materials have none (the simulator falls back to the full evaluation).
  const LoadedPair p = load_test_materials();
  ASSERT_TRUE(p.baked.value);
  EXPECT_FALSE(p.hylc.value);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> U(-1, 1);
  int beyond = 0;
  for (int i = 0; i < 20000; ++i) {
    const double wide = i % 4 == 0 ? 3.0 : 1.0;  // a quarter beyond the boxes and the guard's sides
    Strain6 s;
    s << 0.3 + 0.6 * wide * U(rng), 0.6 * wide * U(rng), 0.3 + 0.6 * wide * U(rng), 250 * wide * U(rng),
        250 * wide * U(rng), 250 * wide * U(rng);
    s[0] = std::max(s[0], -0.95), s[2] = std::max(s[2], -0.95), s[1] = std::clamp(s[1], -0.98, 0.98);
    if (i % 7 == 0) s[4] = 0, s[5] = s[3];     // umbilic: r = 0
    if (i % 11 == 0) s[5] = s[3] + 1e-9 * U(rng);  // next to it
    const double full = p.baked.fn(s).psi, value = p.baked.value(s);
    if (std::isfinite(full) && (std::abs(s[3]) > 200 || std::abs(s[0]) > 1)) ++beyond;
    if (std::isnan(full)) {
      EXPECT_TRUE(std::isnan(value)) << s.transpose();
    } else {
      ASSERT_EQ(value, full) << s.transpose();
    }
  }
  EXPECT_GT(beyond, 1000);
}

}  // namespace
}  // namespace yarnhom
