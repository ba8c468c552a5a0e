// The knit generator (generate_knit, yarn/rod/gen_knit.cpp): what the stitch chart says shows
// in the tile: one yarn per course, knit legs in front and purl legs behind, a slipped stitch a
// float on its face with the loop below held up through the slipping course.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "yarn/rod/generate.hpp"
#include "yarn/rod/pattern_build.hpp"

using namespace yarnhom::yarn;

namespace {

KnitParams params(std::vector<std::string> chart) {
  const double r = 1e-3;
  KnitParams p;
  p.radius = r;
  p.px = 5.5 * r * chart[0].size();
  p.py = 3.1 * r * chart.size();
  p.chart = std::move(chart);
  p.loop_height = 3.0 * r;
  p.depth = 1.3 * r;
  p.bulb = 1.6;
  p.float_depth = 3.6 * r;
  return p;
}

// The unwrapped centreline of yarn y (vertex positions moved by their tile offsets), in radii.
std::vector<Eigen::Vector3d> yarn_points(const Pattern& p, int y) {
  const Topology t = topology(p);
  std::vector<Eigen::Vector3d> out;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (int v : t.yarns[y]) {
    out.push_back((p.x[v] + shift) / p.radius);
    shift += Eigen::Vector3d(t.offset[v][0] * p.px, t.offset[v][1] * p.py, 0);
  }
  return out;
}

// a - b up to whole periods p: the signed distance to the nearest image.
double off(double a, double b, double p) { return std::remainder(a - b, p); }

double max_y(const std::vector<Eigen::Vector3d>& q) {
  double m = -1e9;
  for (const auto& v : q) m = std::max(m, v[1]);
  return m;
}

}  // namespace

TEST(GenerateKnit, OneClosedYarnPerCourseAlongX) {
  const Pattern p = generate_knit(params({"PS", "KK", "SP", "KK"}));
  const Topology t = topology(p);
  ASSERT_EQ(t.yarns.size(), 4u);
  for (int y = 0; y < 4; ++y) {
    Eigen::Vector2i shift = Eigen::Vector2i::Zero();
    for (int v : t.yarns[y]) shift += t.offset[v];
    EXPECT_EQ(shift, Eigen::Vector2i(1, 0)) << "yarn " << y;
  }
  for (int v = 0; v < p.size(); ++v) {
    EXPECT_GT(stored_edge(p, t, v).norm(), 0.5 * p.radius);
    EXPECT_LT(stored_edge(p, t, v).norm(), 1.5 * p.radius);
  }
}

TEST(GenerateKnit, KnitLegsInFrontPurlLegsBehindFloatsOnTheirFace) {
  // Stockinette (all K) and its reverse (all P): the legs (mid-height of the loop) at +-depth.
  for (char s : {'K', 'P'}) {
    const Pattern p = generate_knit(params({std::string(2, s), std::string(2, s)}));
    const auto q = yarn_points(p, 0);
    const double yk = -p.py / 2 / p.radius + 0.5 * 3.1;  // course 0's mid-height, radii
    double z_mid = 0;
    int n = 0;
    for (const auto& v : q)
      if (std::abs(off(v[1], yk, p.py / p.radius)) < 0.3) z_mid += v[2], ++n;
    ASSERT_GT(n, 0);
    EXPECT_NEAR(z_mid / n, s == 'K' ? 1.3 : -1.3, 0.2) << s;
  }
  // A slipped stitch: the course floats across its wale float_depth or more from the mid-plane,
  // on the face it holds its yarn on: in front (+z) in a purl course, behind (-z) in a knit one.
  for (char s : {'K', 'P'}) {
    const Pattern p = generate_knit(params({std::string(1, s) + "S", "KK"}));
    const auto q = yarn_points(p, 0);
    const double xw = p.px / 4 / p.radius;  // wale 1's centre, radii
    int n = 0;
    for (const auto& v : q)
      if (std::abs(off(v[0], xw, p.px / p.radius)) < 1.0) {
        EXPECT_GT(s == 'P' ? v[2] : -v[2], 3.55) << s;
        ++n;
      }
    EXPECT_GT(n, 0) << s;
  }
}

TEST(GenerateKnit, HeldLoopsLegsAtHeldDepth) {
  // The cartridge belt rib's chart: course 1's knit loop in wale 1 is held through the next
  // repeat's course 0 (which slips wale 1): its legs at +held_depth, in front of that course's
  // float; its loop in wale 0, caught by the next course, has its legs at +depth.
  KnitParams prm = params({"PSPP", "KKKS"});
  prm.held_depth = 5.0 * prm.radius;
  const Pattern p = generate_knit(prm);
  const auto q = yarn_points(p, 1);
  const double w = p.px / 4 / p.radius, period = p.px / p.radius;
  double held = -1e9, worked = -1e9;  // the largest z in wale 1 and in wale 0
  for (const auto& v : q) {
    const double from_left = v[0] + period / 2;  // from wale 0's left edge, radii
    if (std::abs(std::remainder(from_left - 1.5 * w, period)) < 0.3 * w) held = std::max(held, v[2]);
    if (std::abs(std::remainder(from_left - 0.5 * w, period)) < 0.3 * w) worked = std::max(worked, v[2]);
  }
  EXPECT_NEAR(held, 5.0, 0.3);
  EXPECT_NEAR(worked, 1.3, 0.3);
  // The floats, at their wale's centre: course 0's (purl) in front, course 1's (knit) behind.
  const auto z_at = [&](const std::vector<Eigen::Vector3d>& yarn, double x) {
    double best = 1e9, z = 0;
    for (const auto& v : yarn) {
      const double d = std::abs(std::remainder(v[0] + period / 2 - x, period));
      if (d < best) best = d, z = v[2];
    }
    return z;
  };
  EXPECT_NEAR(z_at(yarn_points(p, 0), 1.5 * w), 3.6, 0.1);
  EXPECT_NEAR(z_at(q, 3.5 * w), -3.6, 0.1);
}

TEST(GenerateKnit, SlippedCoursesHoldTheLoopBelowUp) {
  // Course 0's loop in wale 1 is slipped by course 1 and caught by course 2: it reaches one
  // course (3.1 radii) higher than its loop in wale 0.
  const Pattern p = generate_knit(params({"KK", "KS", "KK"}));
  const auto q = yarn_points(p, 0);
  std::vector<Eigen::Vector3d> left, right;
  for (const auto& v : q) (off(v[0], 0, p.px / p.radius) < 0 ? left : right).push_back(v);
  EXPECT_NEAR(max_y(right) - max_y(left), 3.1, 0.3);
}

TEST(GenerateKnit, RefusesBadCharts) {
  EXPECT_THROW(generate_knit(params({"KX", "KK"})), std::invalid_argument);
  EXPECT_THROW(generate_knit(params({"KKK", "KK"})), std::invalid_argument);
  EXPECT_THROW(generate_knit(params({"KS", "KS"})), std::invalid_argument);  // wale 1 never worked
  KnitParams flat = params({"KK"});
  flat.depth = 0;
  EXPECT_THROW(generate_knit(flat), std::invalid_argument);
}

// The cartridge belt rib's held loops are caught by held loops (yarn/rod/generate.cpp): by
// default the head goes to the far face (head_depth on the other side of the catching legs at
// depth); with held_head_gap it stays on its legs' side, that far in front of the catching
// stitch's held legs; held_height lowers it.
TEST(GenerateKnit, HeldHeadGapKeepsTheHeadOfALoopCaughtByAHeldLoopOnItsLegsSide) {
  const double r = 1e-3;
  KnitParams p = params({"PSPP", "KKKS"});
  p.held_depth = 4.0 * r;
  p.head_depth = 2.5 * r;
  // Course 0 purls wale 3 and course 1 slips it: that loop (legs behind, at -held_depth) is held
  // and caught by course 0's next purl in wale 3, held itself. Its head is course 0's highest
  // point.
  const auto head = [](const Pattern& pat) {
    const auto q = yarn_points(pat, 0);
    return *std::max_element(q.begin(), q.end(), [](const auto& a, const auto& b) { return a[1] < b[1]; });
  };
  const Eigen::Vector3d far = head(generate_knit(p));
  EXPECT_NEAR(far[2], 2.5, 0.3);  // the far face
  p.held_head_gap = 2.0 * r;
  const Eigen::Vector3d near = head(generate_knit(p));
  EXPECT_NEAR(near[2], -2.0, 0.3);  // -(held_depth - held_head_gap): the legs' side
  p.held_height = 0.5;
  const Eigen::Vector3d low = head(generate_knit(p));
  EXPECT_NEAR(near[1] - low[1], 0.5 * 3.1, 0.3);  // half a course (3.1 r) lower
}

// leg_spread moves each leg sideways by leg_spread at the loop's mid-height (th = +-pi/2, where
// the loop crosses its course's centre line), keeping its head and sinkers where they were.
TEST(GenerateKnit, LegSpreadWidensTheLegsAtMidHeight) {
  const auto shape = [](double spread) {
    KnitParams p = params({"K"});
    p.leg_spread = spread * p.radius;
    p.edge = 0.2 * p.radius;  // fine sampling: vertices near mid-height
    // One loop from its sinker (th = -pi, the first vertex), loop_height (3 r) below the
    // course's centre line.
    const auto q = yarn_points(generate_knit(p), 0);
    const double mid = q[0][1] + 3.0;
    double lo = 1e9, hi = -1e9, top = -1e9;
    for (const auto& v : q) {
      if (std::abs(v[1] - mid) < 0.3) lo = std::min(lo, v[0]), hi = std::max(hi, v[0]);
      top = std::max(top, v[1] - q[0][1]);
    }
    return Eigen::Vector2d(hi - lo, top);
  };
  const Eigen::Vector2d plain = shape(0), spread = shape(0.5);
  EXPECT_NEAR(spread[0] - plain[0], 1.0, 0.2);  // both legs 0.5 r outward
  EXPECT_NEAR(spread[1], plain[1], 0.05);       // the head as high
}
