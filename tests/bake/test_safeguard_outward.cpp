// The safeguard that is physically safe (spec section 8, docs/bake.md): 2D tables equal to the
// network up to the boundary, and the TOTAL energy (pair planes, the full strain space) rising
// outward with a non-decreasing slope along outward rays; the 1D end repairs and older files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "bake/bake_table.hpp"
#include "bake/bake_accuracy.hpp"
#include "material/baked_eval.hpp"
#include "bake/corner_twist.hpp"
#include "material/material.hpp"
#include "bake/pair_check.hpp"
#include "cpu/network_eval.hpp"
#include "tests/common/bake_test_util.hpp"
#include "tests/common/outward_rays.hpp"

using namespace yarnhom;

// ---- A safeguard that is physically safe (issue 12) ------------------------------------------

namespace {

struct PairCase {
  const char *pair, *first, *second;
  std::vector<double> lo, hi;
};

const std::vector<PairCase> kPairCases = {{"01", "0", "1", {-0.2, -0.7}, {1.0, 0.7}},
                                          {"02", "0", "2", {-0.2, -0.2}, {1.0, 1.0}},
                                          {"13", "1", "3", {-0.7, -170.0}, {0.7, 170.0}},
                                          {"25", "2", "5", {-0.2, -230.0}, {1.0, 230.0}}};

// The direction of corner c's quadrant along which the total's curvature
// K_I c^2 + 2 T c s + K_J s^2 is smallest when T < 0 (c/s = -T/K_I for K_I > 0, else s/c = -T/K_J),
// in physical units and of unit length, and that curvature.
double worst_corner_direction(const PairCheck& pc, int q, double v[2]) {
  const double a = std::max(pc.k_first[q], 0.0), b = std::max(pc.k_second[q], 0.0), T = pc.twist[q];
  double c = 1, s = 1;
  if (a > 0) c = -T / a;
  else if (b > 0) s = -T / b;
  const double n = std::hypot(c, s);
  c /= n;
  s /= n;
  v[0] = (q & 1 ? 1 : -1) * c;
  v[1] = (q & 2 ? 1 : -1) * s;
  return a * c * c + 2 * T * c * s + b * s * s;
}

}  // namespace

// (a) Inside the box a 2D table is the network's: no boundary layer. Its knots are the network's
// jets bit for bit (whatever the network's outward slopes), and in the outer 5 % of the box
// (where the former per-term repair rewrote inward slopes) the table follows the network as
// closely as deep inside: only the Hermite interpolation error, far below the 1e-3 of the range
// that a repair of the measured size would leave.
TEST(Safeguard, TwoDimensionalTablesAreTheNetworkUpToTheBoundary) {
  unsigned seed = 300;
  for (const PairCase& c : kPairCases) {
    ModelNetwork net = test::random_model_network(c.pair, c.lo, c.hi, seed++);
    BakeReport rep;
    const BakedTable tb = bake_network(net, 200, 60, &rep);
    const BakedTable raw = bake_network(net, 200, 60, nullptr, false);
    EXPECT_FALSE(rep.repair.changed()) << c.pair;
    EXPECT_EQ(tb.f, raw.f) << c.pair;
    EXPECT_EQ(tb.f_x, raw.f_x) << c.pair;
    EXPECT_EQ(tb.f_y, raw.f_y) << c.pair;
    EXPECT_EQ(tb.f_xy, raw.f_xy) << c.pair;
    // Boundary knots against the network's own jet.
    int inward = 0;
    for (int j = 0; j < 60; ++j) {
      const double s[2] = {c.hi[0], knot_position(c.lo[1], c.hi[1], 60, j)};
      const auto ref = material_function(net)(s, 1, 1);  // the network's axis projection
      const size_t q = size_t(59) * 60 + j;
      EXPECT_NEAR(tb.f[q], ref[0], 1e-12 * (1 + std::abs(ref[0])));
      EXPECT_NEAR(tb.f_x[q], ref[1], 1e-9 * (1 + std::abs(ref[1])));
      inward += ref[1] < 0;
    }
    const BakedTerm t = make_baked_term(tb);
    const BakeDeviation whole = bake_deviation(material_function(net), baked_function(t), 2, c.lo, c.hi, 121);
    double layer_max = 0;
    for (int e = 0; e < 4; ++e) {
      const int axis = e / 2;
      std::vector<double> lo = c.lo, hi = c.hi;
      const double w = 0.05 * (c.hi[axis] - c.lo[axis]);
      if (e % 2) lo[axis] = hi[axis] - w;
      else hi[axis] = lo[axis] + w;
      layer_max = std::max(layer_max, bake_deviation(material_function(net), baked_function(t), 2, lo, hi, 61).max_abs);
    }
    EXPECT_LT(layer_max, 1e-4 * whole.range) << c.pair << " (the whole box: " << whole.max_rel << ")";
    std::printf("%s: inward slopes at %d of 60 x-upper knots; max |baked - net| / range: box %.2e, outer 5%% %.2e\n",
                c.pair, inward, whole.max_rel, layer_max / whole.range);
  }
}

// (b) In the plane of each pair (the other strains 0) the total is Psi_I + Psi_J + Psi_IJ. For
// random networks of the paper's size for all three terms over real boxes, 1,000 outward rays
// per pair (one in five from a corner) to 3x the box: the total's outward slope never
// decreases, and never turns negative where it starts non-negative. Corners the pair check
// reports (T^2 > K_I K_J with a negative twist) are skipped, and the report is checked to be
// true: along its worst direction the slope does fall. Then the three networks are baked as one
// material (bake_model: the 1D curvature floors, the corner twist repair and the edge slope
// repair, docs/bake.md): no corner is reported any more, the same 1,000 rays are walked with
// none skipped and none starting to fall, the total's outward slope is >= 0 on every edge of
// the box itself, and far out (1000x the box) every corner's worst diagonal rises.
TEST(Safeguard, TotalEnergyRisesOutwardInEveryPairPlane) {
  unsigned seed = 400;
  int start_falling = 0, corner_rays = 0, skipped = 0, reported_corners = 0, reported_edges = 0, repaired = 0, floors = 0,
      edges_repaired = 0;
  for (const PairCase& c : kPairCases)
    for (int k = 0; k < 3; ++k, seed += 3) {
      BakedTable table2 = bake_network(test::random_model_network(c.pair, c.lo, c.hi, seed), 200, 40);
      const BakedTerm t2 = make_baked_term(table2);
      const BakedTerm ti = make_baked_term(bake_network(test::random_model_network(c.first, {c.lo[0]}, {c.hi[0]}, seed + 1), 200, 40));
      const BakedTerm tj = make_baked_term(bake_network(test::random_model_network(c.second, {c.lo[1]}, {c.hi[1]}, seed + 2), 200, 40));
      const PairCheck pc = check_pair(t2, &ti, &tj);
      const test::RayTally r = test::pair_plane_rays(t2, &ti, &tj, pc, 1000, seed);
      const std::string what = std::string(c.pair) + " seed " + std::to_string(seed) + ": " + pc.summary();
      EXPECT_EQ(r.rays + r.skipped, 1000) << what;
      EXPECT_EQ(r.slope_falls, 0) << what;
      EXPECT_EQ(r.turns_back, 0) << what;
      start_falling += r.start_falling;
      corner_rays += r.corner_rays;
      skipped += r.skipped;
      for (int e = 0; e < 4; ++e) reported_edges += pc.falling[e] > 0;
      // A reported corner really bends the total down.
      for (int q = 0; q < 4; ++q) {
        if (!pc.corner_bends[q]) continue;
        ++reported_corners;
        double v[2];
        const double curv = worst_corner_direction(pc, q, v);
        EXPECT_LT(curv, 0) << what;
        // A corner within rounding of the limit bends too little to see along one ray.
        if (curv > -1e-6 * (std::abs(pc.twist[q]) + std::abs(pc.k_first[q]) + std::abs(pc.k_second[q]))) continue;
        const std::vector<double> p = {q & 1 ? t2.hi[0] : t2.lo[0], q & 2 ? t2.hi[1] : t2.lo[1]};
        test::RayTally one;
        test::RayEnergy E = [&](const std::vector<double>& x, const std::vector<double>& d, double& F, double& S) {
          const BakedJet2 j = eval_baked_2d(t2, {x[0], x[1]});
          const BakedJet1 a = eval_baked_1d(ti, x[0]), b = eval_baked_1d(tj, x[1]);
          F = j.f + a.f + b.f;
          S = (j.g[0] + a.df) * d[0] + (j.g[1] + b.df) * d[1];
        };
        const double H = std::min(t2.hi[0] - t2.lo[0], t2.hi[1] - t2.lo[1]);
        test::walk_ray(E, p, {v[0], v[1]}, H, 0.0, one);
        EXPECT_EQ(one.slope_falls, 1) << what << " corner " << q;
      }
      // The three networks baked as one material (bake_model: curvature floors, corner twists).
      Model model;
      model.networks = {test::random_model_network(c.pair, c.lo, c.hi, seed),
                        test::random_model_network(c.first, {c.lo[0]}, {c.hi[0]}, seed + 1),
                        test::random_model_network(c.second, {c.lo[1]}, {c.hi[1]}, seed + 2)};
      std::vector<BakeReport> reps;
      const BakedModel bm = bake_model(model, "", 200, 40, 0.0, false, &reps);
      const BakedTerm r2 = make_baked_term(bm.tables[0]), ri = make_baked_term(bm.tables[1]),
                      rj = make_baked_term(bm.tables[2]);
      const PairCheck rc = check_pair(r2, &ri, &rj);
      for (int q = 0; q < 4; ++q) {
        EXPECT_FALSE(rc.corner_bends[q]) << what << " corner " << q;
        repaired += reps[0].corners.repaired[q];
      }
      for (int e = 0; e < 2; ++e) floors += reps[1].repair.sides[e].floor_raised + reps[2].repair.sides[e].floor_raised;
      // A raised 1D end is still C2 with its quadratic, whose curvature is the floor.
      for (const BakedTerm* t1 : {&ri, &rj}) {
        const BakeReport& r1 = reps[t1 == &ri ? 1 : 2];
        for (int e = 0; e < 2; ++e) {
          if (!r1.repair.sides[e].floor_raised) continue;
          const double X = e ? t1->hi[0] : t1->lo[0], d = 1e-7 * (t1->hi[0] - t1->lo[0]) * (e ? 1 : -1);
          // Inside, the end cell's curvature is linear: extrapolated to X from two points.
          const double in = 2 * eval_baked_1d(*t1, X - d).d2f - eval_baked_1d(*t1, X - 2 * d).d2f;
          const double out = eval_baked_1d(*t1, X + d).d2f;
          EXPECT_NEAR(out, r1.repair.sides[e].curvature_floor, 1e-6 * r1.repair.sides[e].curvature_floor) << what;
          EXPECT_NEAR(in, out, 1e-6 * out) << what;
        }
      }
      const test::RayTally rr = test::pair_plane_rays(r2, &ri, &rj, rc, 1000, seed);
      EXPECT_EQ(rr.rays, 1000) << what;
      EXPECT_EQ(rr.skipped, 0) << what;
      EXPECT_EQ(rr.slope_falls, 0) << what;
      EXPECT_EQ(rr.turns_back, 0) << what;
      auto total = [&](double x, double y, double vx, double vy, double& S) {
        const BakedJet2 j = eval_baked_2d(r2, {x, y});
        const BakedJet1 a = eval_baked_1d(ri, x), b = eval_baked_1d(rj, y);
        S = (j.g[0] + a.df) * vx + (j.g[1] + b.df) * vy;
        return j.f + a.f + b.f;
      };
      // The literal criterion: no ray starts falling, and the total's outward slope is >= 0 on
      // the boundary itself (the edge slope repair), so along every edge ray it is >= 0 from the
      // boundary on.
      EXPECT_EQ(rr.start_falling, 0) << what;
      for (int e = 0; e < 4; ++e) edges_repaired += reps[0].edges.knots_raised[e] > 0;
      for (int e = 0; e < 4; ++e) {
        const int axis = e / 2, along = 1 - axis;
        const double sg = e % 2 ? 1 : -1;
        for (int m = 0; m <= 400; ++m) {
          double p[2], v[2] = {0, 0}, S;
          p[axis] = sg > 0 ? r2.hi[axis] : r2.lo[axis];
          p[along] = r2.lo[along] + (r2.hi[along] - r2.lo[along]) * m / 400;
          v[axis] = sg;
          total(p[0], p[1], v[0], v[1], S);
          EXPECT_GE(S, -1e-9 * rc.slope_scale) << what << " edge " << e << " point " << m;
        }
      }
      // Far out (1000x the box) every corner's worst diagonal rises above the corner's energy.
      for (int q = 0; q < 4; ++q) {
        double v[2];
        worst_corner_direction(rc, q, v);
        const double H = std::max(r2.hi[0] - r2.lo[0], r2.hi[1] - r2.lo[1]);
        const double x0 = q & 1 ? r2.hi[0] : r2.lo[0], y0 = q & 2 ? r2.hi[1] : r2.lo[1];
        double S0, S;
        const double F0 = total(x0, y0, v[0], v[1], S0);
        const double F = total(x0 + 1000 * H * v[0], y0 + 1000 * H * v[1], v[0], v[1], S);
        EXPECT_GT(S, 0) << what << " corner " << q;
        EXPECT_GT(F, F0) << what << " corner " << q;
      }
    }
  // The test means something only if the data fell outward somewhere and corners were walked.
  EXPECT_GT(start_falling, 0);
  EXPECT_GT(reported_edges, 0);
  EXPECT_GT(corner_rays - skipped, 500);
  EXPECT_GT(reported_corners, 0);
  EXPECT_GT(repaired, 0);
  EXPECT_GT(floors, 0);
  EXPECT_GT(edges_repaired, 0);
  std::printf("pair planes: %d rays started falling (reported), %d corner rays walked, %d skipped at %d reported corners; "
              "as one material: %d corners repaired, %d 1D end curvatures raised, %d edges' slopes raised\n", start_falling,
              corner_rays - skipped, skipped, reported_corners, repaired, floors, edges_repaired);
}

// (b) The full strain space (s_x, s_a, s_y, II_x, II_y; II_a = 0, where bending is B_3[g] =
// g(II_x), B_5[g] = g(II_y)): random networks for all 14 terms over a common box per strain, the
// material a simulator evaluates, 1,000 outward rays from the box boundary to 3x the box: from
// a face point (one strain on its bound) along its normal, or from a point with two strains on
// their bounds in a random direction of their quadrant (skipped where that pair's corner is
// reported). The total's outward slope never decreases, and never turns negative.
TEST(Safeguard, TotalMaterialRisesOutwardInTheStrainSpace) {
  const double lo6[6] = {-0.2, -0.7, -0.2, -200, -50, -230}, hi6[6] = {1.0, 0.7, 1.0, 170, 50, 230};
  Model model;
  unsigned seed = 500;
  for (const Term& term : all_terms()) {
    std::vector<double> lo, hi;
    for (int i : term.indices) {
      lo.push_back(lo6[i]);
      hi.push_back(hi6[i]);
    }
    model.networks.push_back(test::random_model_network(term.name, lo, hi, seed++));
  }
  // bake_model: the 1D end repair and the corner twist repair, as `yarnhom bake` does.
  const BakedModel m = bake_model(model, "", 100, 30, 0.0, false);
  const BakedMaterial mat = make_baked_material(m);
  const std::vector<PairCheck> pcs = check_pairs(m);
  auto pair_of = [&](int i, int j, bool& swapped) -> const PairCheck* {
    for (size_t k = 0; k < m.tables.size(); ++k) {
      const auto& ix = m.tables[k].term.indices;
      if (ix.size() != 2) continue;
      if (ix[0] == i && ix[1] == j) { swapped = false; return &pcs[k]; }
      if (ix[0] == j && ix[1] == i) { swapped = true; return &pcs[k]; }
    }
    return nullptr;
  };
  test::RayEnergy E = [&](const std::vector<double>& x, const std::vector<double>& v, double& F, double& S) {
    Strain6 s, d;
    for (int i = 0; i < 6; ++i) { s[i] = x[i]; d[i] = v[i]; }
    const MaterialEval e = eval_material(mat, s);
    F = e.psi;
    S = e.grad.dot(d);
  };
  const int moving[5] = {0, 1, 2, 3, 5};
  double H[6];
  for (int i = 0; i < 6; ++i) H[i] = 0.5 * (hi6[i] - lo6[i]);
  double slope_scale = 0;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < 200; ++k) {
    std::vector<double> x(6, 0.0);
    for (int i : moving) x[i] = lo6[i] + 2 * H[i] * U(rng);
    for (int i : moving) {
      std::vector<double> v(6, 0.0);
      v[i] = H[i];
      double F, S;
      E(x, v, F, S);
      slope_scale = std::max(slope_scale, std::abs(S));
    }
  }
  test::RayTally tally;
  int two = 0, skipped = 0;
  for (int r = 0; r < 1000; ++r) {
    std::vector<double> p(6, 0.0), v(6, 0.0);
    for (int i : moving) p[i] = lo6[i] + 2 * H[i] * (0.001 + 0.998 * U(rng));
    const int a = moving[int(U(rng) * 5) % 5];
    int b = a;
    if (r % 3 == 0)
      while (b == a) b = moving[int(U(rng) * 5) % 5];
    const double sa = U(rng) < 0.5 ? -1 : 1, sb = U(rng) < 0.5 ? -1 : 1, ang = 0.5 * M_PI * U(rng);
    p[a] = sa > 0 ? hi6[a] : lo6[a];
    if (b == a) {
      v[a] = sa * H[a];
    } else {
      ++two;
      p[b] = sb > 0 ? hi6[b] : lo6[b];
      v[a] = sa * H[a] * std::cos(ang);
      v[b] = sb * H[b] * std::sin(ang);
      bool sw = false;
      if (const PairCheck* pc = pair_of(a, b, sw)) {
        const bool up0 = (sw ? sb : sa) > 0, up1 = (sw ? sa : sb) > 0;
        if (pc->corner_bends[(up0 ? 1 : 0) + (up1 ? 2 : 0)]) {
          ++skipped;
          continue;
        }
      }
    }
    double tmax = 1e300;
    for (int i : moving)
      if (v[i] != 0) tmax = std::min(tmax, 2 * H[i] / std::abs(v[i]));
    test::walk_ray(E, p, v, tmax, slope_scale, tally);
  }
  EXPECT_EQ(tally.slope_falls, 0);
  EXPECT_EQ(tally.turns_back, 0);
  EXPECT_EQ(skipped, 0);  // the corner twist repair leaves no corner that bends the total down
  EXPECT_EQ(tally.rays, 1000);
  std::printf("strain space: %d rays (%d from two bounds, %d skipped at reported corners), %d started falling\n",
              tally.rays, two - skipped, skipped, tally.start_falling);
}

// The 1D end repair: where a 1D term's end slope points inward or its curvature is negative
// (a 1D term is the energy along one axis: it must rise), the table's outer 5 % is repaired,
// keeping C2 with the (repaired) table, and the energy rises with a non-decreasing slope to 3x
// the box. Untouched away from the ends; the change is measured.
TEST(Safeguard, NegativeEndCurvatureIsRepairedInTheTable) {
  test::Poly p;  // f = x - 0.3 x^3 on [-1, 1]: f'(1) = 0.1 > 0 but f''(1) = -1.8 < 0; f'(-1) = 0.1 (outward -0.1)
  p.c[1][0] = 1; p.c[3][0] = -0.3;
  BakeReport rep;
  BakedTable tb = bake_function(term_by_name("0"), {-1}, {1}, {200}, test::poly_function(p, 1), &rep);
  ASSERT_EQ(rep.repair.sides.size(), 2u);
  EXPECT_TRUE(rep.repair.sides[1].curvature_raised);
  EXPECT_TRUE(rep.repair.sides[0].repaired);  // the lower end's outward slope was -0.1
  BakedTable raw = bake_function(term_by_name("0"), {-1}, {1}, {200}, test::poly_function(p, 1), nullptr, false);
  int changed_inside = 0;
  for (int k = 0; k < 200; ++k) {
    const double x = knot_position(-1, 1, 200, k);
    if (std::abs(x) < 0.9 - 1e-12) changed_inside += tb.f[k] != raw.f[k] || tb.f_x[k] != raw.f_x[k];
  }
  EXPECT_EQ(changed_inside, 0);
  EXPECT_LT(rep.repair.max_change, 0.01 * rep.repair.range);
  BakedTerm t = make_baked_term(tb);
  test::RayTally r;
  const test::RayEnergy E = [&](const std::vector<double>& x, const std::vector<double>& v, double& F, double& S) {
    const BakedJet1 j = eval_baked_1d(t, x[0]);
    F = j.f;
    S = j.df * v[0];
  };
  test::walk_ray(E, {1.0}, {1.0}, 2.0, 2.0, r, 1000);
  test::walk_ray(E, {-1.0}, {-1.0}, 2.0, 2.0, r, 1000);
  EXPECT_EQ(r.slope_falls, 0);
  EXPECT_EQ(r.turns_back, 0);
  EXPECT_EQ(r.start_falling, 0);
  // C2 at the ends with the repaired table.
  for (double X : {-1.0, 1.0}) {
    const double d = 1e-7;
    const BakedJet1 in = eval_baked_1d(t, X - (X > 0 ? d : -d)), out = eval_baked_1d(t, X + (X > 0 ? d : -d));
    EXPECT_NEAR(in.d2f, out.d2f, 1e-4 * (1 + std::abs(in.d2f)));
    EXPECT_NEAR(in.df, out.df, 1e-5);
  }
}

// Random 1D networks: every end rises outward with a non-decreasing slope after the repair, and
// the repair was needed for some of them (the test means something).
TEST(Safeguard, OneDimensionalEndsRiseForRandomNetworks) {
  int repaired = 0;
  for (const char* name : {"0", "3"})
    for (unsigned s = 0; s < 4; ++s) {
      const std::vector<double> lo = name[0] == '0' ? std::vector<double>{-0.2} : std::vector<double>{-200.0};
      const std::vector<double> hi = name[0] == '0' ? std::vector<double>{1.0} : std::vector<double>{170.0};
      BakeReport rep;
      const BakedTerm t = make_baked_term(bake_network(test::random_model_network(name, lo, hi, 200 + s), 200, 40, &rep));
      repaired += rep.repair.changed();
      const double H = 0.5 * (hi[0] - lo[0]);
      double gmax = 0;
      for (int i = 0; i <= 100; ++i) gmax = std::max(gmax, std::abs(eval_baked_1d(t, lo[0] + 2 * H * i / 100).df) * H);
      test::RayTally r;
      const test::RayEnergy E = [&](const std::vector<double>& x, const std::vector<double>& v, double& F, double& S) {
        const BakedJet1 j = eval_baked_1d(t, x[0]);
        F = j.f;
        S = j.df * v[0];
      };
      test::walk_ray(E, {hi[0]}, {H}, 2.0, gmax, r, 1000);
      test::walk_ray(E, {lo[0]}, {-H}, 2.0, gmax, r, 1000);
      EXPECT_EQ(r.slope_falls + r.turns_back + r.start_falling, 0) << name << " seed " << 200 + s;
    }
  EXPECT_GE(repaired, 2);
}

// Where a 1D end already rises with positive curvature nothing departs from the paper's
// continuation; a 2D table always continues to first order, and says so.
TEST(Safeguard, PaperContinuationWhereTheBoundaryIsAlreadySafe) {
  test::Poly p1;  // x^2 + 0.2 x^3 on [-1, 2]
  p1.c[2][0] = 1; p1.c[3][0] = 0.2;
  BakeReport rep;
  BakedTable tb = bake_function(term_by_name("0"), {-1}, {2}, {50}, test::poly_function(p1, 1), &rep);
  EXPECT_FALSE(rep.repair.changed());
  EXPECT_FALSE(rep.departures.any());
  EXPECT_EQ(rep.summary(tb), "the paper's continuation");
  EXPECT_NEAR(tb.safeguard_upper[0], 0.5 * (2 + 1.2 * 2), 1e-9);  // a = f''(2)/2
  test::Poly p;  // x^2 + x y/2 + y^2 on [-1, 1]^2
  p.c[2][0] = 1; p.c[1][1] = 0.5; p.c[0][2] = 1;
  BakeReport r2;
  BakedTable t2 = bake_function(term_by_name("01"), {-1, -1}, {1, 1}, {21, 21}, test::poly_function(p, 2), &r2);
  EXPECT_TRUE(r2.departures.first_order);
  EXPECT_NE(r2.summary(t2).find("first order outside (boundary curvature up to 2 dropped; negative at 0 of 84"),
            std::string::npos) << r2.summary(t2);
  for (int j = 0; j < 21; ++j) EXPECT_EQ(t2.edges[1][6 * j + 4], 0.0);
}

// A file baked before the first-order continuation (same format, version 1: non-zero band
// curvatures in the curvature columns) is read, and continued to first order.
TEST(Safeguard, OlderFilesWithBandCurvaturesAreRead) {
  ModelNetwork n = test::random_model_network("02", {-0.2, -0.2}, {1.0, 1.0}, 46);
  BakedTable t = bake_network(n, 200, 20);
  const BakedTerm fresh = make_baked_term(t);
  EXPECT_FALSE(fresh.legacy_safeguard);
  for (int e = 0; e < 4; ++e)
    for (size_t j = 0; j < t.edges[e].size() / 6; ++j) t.edges[e][6 * j + 4] = 1.5;
  t.corners[1][3] = 1.5;
  t.corners[1][6] = 0.25;
  const BakedTerm old = make_baked_term(t, "old.h5");
  EXPECT_TRUE(old.legacy_safeguard);
  const BakedJet2 a = eval_baked_2d(old, {1.4, 0.3}), b = eval_baked_2d(fresh, {1.4, 0.3});
  EXPECT_EQ(a.f, b.f);
  t.edges[2][4] = NAN;
  EXPECT_THROW(make_baked_term(t, "old.h5"), std::invalid_argument);
}
