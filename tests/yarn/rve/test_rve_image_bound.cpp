// The broad phases' image bound (RveProblem::image_bound, yarn/rve/rve_pairs.cpp): the in-plane
// box it gives an image holds every mapped point of that image, segments' far ends included, under
// stretch, shear, compression and curvature; it skips the far images of a patch; and the contact
// pairs found with it are those of the full scan of all 25 images, image by image as before (the
// assembly sums in pair order; produce's datasets keep their bits: docs/rve.md section 5).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <tuple>
#include <vector>

#include "tests/common/yarn_support.hpp"
#include "yarn/rod/generate.hpp"
#include "yarn/rve/relax.hpp"
#include "yarn/rve/rve.hpp"

using namespace yarnhom::yarn;

using yarnhom::yarn::testing::strain;

namespace {

Pattern small_knit() {
  if (yarnhom::yarn::testing::have_shared_patterns())
    return read_pyp(yarnhom::yarn::testing::shared_pattern("stocktiny"));
  static const Pattern relaxed = relax_pattern(generate_stockinette({}), Material{});
  return relaxed;
}

// Fluctuations of up to `amp` yarn radii in every direction (the bound's |u| term is exercised).
RveState shaken(const RveProblem& rve, unsigned seed, double amp) {
  RveState st = rve.initial_state();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  for (auto& u : st.u) u += amp * rve.radius() * Eigen::Vector3d(U(rng), U(rng), U(rng));
  return st;
}

const std::vector<Strain>& strains() {
  static const std::vector<Strain> s = {strain(0, 0, 0, 0, 0, 0), strain(0.3, 0.2, -0.1, 0, 0, 0),
                                        strain(-0.2, -0.5, 0.4, 150, -60, 90), strain(0.1, 0.7, -0.3, -200, 80, 230)};
  return s;
}

// The candidate pairs as the broad phase found them before the bound: every one of the 25
// images mapped, its box against the base tile's, then each segment pair's boxes (all pairs, no
// grid: the order is image, then image segment, then base segment).
std::vector<std::tuple<int, int, int, int>> full_scan(const RveProblem& rve, const Strain& s, const RveState& st,
                                                      double reach) {
  const int n = rve.pattern().size();
  const Topology& t = rve.topo();
  auto box = [&](int v, Eigen::Vector2i o, Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
    const Eigen::Vector3d a = rve.position(s, st, v, o), b = rve.position(s, st, t.next[v], o + t.offset[v]);
    lo = a.cwiseMin(b);
    hi = a.cwiseMax(b);
  };
  auto apart = [reach](const Eigen::Vector3d& l1, const Eigen::Vector3d& h1, const Eigen::Vector3d& l2,
                       const Eigen::Vector3d& h2) {
    return ((l1.array() - reach) > h2.array()).any() || ((h1.array() + reach) < l2.array()).any();
  };
  std::vector<Eigen::Vector3d> blo(n), bhi(n);
  Eigen::Vector3d alo = Eigen::Vector3d::Constant(1e300), ahi = -alo;
  for (int v = 0; v < n; ++v) {
    box(v, {0, 0}, blo[v], bhi[v]);
    alo = alo.cwiseMin(blo[v]);
    ahi = ahi.cwiseMax(bhi[v]);
  }
  std::vector<std::tuple<int, int, int, int>> out;
  for (int ox = -2; ox <= 2; ++ox)
    for (int oy = -2; oy <= 2; ++oy) {
      const Eigen::Vector2i o(ox, oy);
      std::vector<Eigen::Vector3d> lo(n), hi(n);
      Eigen::Vector3d ilo = Eigen::Vector3d::Constant(1e300), ihi = -ilo;
      for (int w = 0; w < n; ++w) {
        box(w, o, lo[w], hi[w]);
        ilo = ilo.cwiseMin(lo[w]);
        ihi = ihi.cwiseMax(hi[w]);
      }
      if (apart(ilo, ihi, alo, ahi)) continue;
      for (int w = 0; w < n; ++w)
        for (int v = 0; v < n; ++v) {
          if (v > w || (v == w && (ox < 0 || (ox == 0 && oy <= 0)))) continue;
          if (rve.excluded(v, w, o) || apart(blo[v], bhi[v], lo[w], hi[w])) continue;
          out.emplace_back(v, w, ox, oy);
        }
    }
  return out;
}

}  // namespace

TEST(RveImageBound, HoldsEveryPointOfEveryImage) {
  const Pattern p = small_knit();
  for (int copies : {1, 2}) {
    const RveProblem rve(copies == 1 ? p : tile(p, 2, 2), Material{});
    const Topology& t = rve.topo();
    for (unsigned seed : {1u, 2u}) {
      const RveState st = shaken(rve, seed, 0.4);
      for (const Strain& s : strains()) {
        const RveProblem::ImageBound b = rve.image_bound(s, st);
        for (int ox = -3; ox <= 3; ++ox)
          for (int oy = -3; oy <= 3; ++oy) {
            const Eigen::Vector2i o(ox, oy);
            Eigen::Vector2d lo, hi;
            b.image_box(o, lo, hi);
            for (int v = 0; v < rve.pattern().size(); ++v)
              for (const Eigen::Vector3d& x :
                   {rve.position(s, st, v, o), rve.position(s, st, t.next[v], o + t.offset[v])}) {
                EXPECT_TRUE((x.head<2>().array() >= lo.array()).all() && (x.head<2>().array() <= hi.array()).all())
                    << "copies " << copies << " vertex " << v << " image " << ox << "," << oy << " strain "
                    << s.transpose() << ": " << x.head<2>().transpose() << " outside [" << lo.transpose() << "] - ["
                    << hi.transpose() << "]";
              }
          }
      }
    }
  }
}

TEST(RveImageBound, ContactPairsAreTheFullScansInItsOrderAndFarImagesAreSkipped) {
  const Pattern p = small_knit();
  for (int copies : {1, 2}) {
    const RveProblem rve(copies == 1 ? p : tile(p, 2, 2), Material{});
    for (const Strain& s : strains())
      for (double margin : {0.0, 0.5 * rve.radius()}) {
        const RveState st = shaken(rve, 7, 0.05);
        std::vector<std::tuple<int, int, int, int>> got;
        for (const auto& pr : rve.contact_pairs(s, st, margin)) got.emplace_back(pr.a, pr.b, pr.o[0], pr.o[1]);
        auto want = full_scan(rve, s, st, 2 * rve.radius() + margin);
        EXPECT_FALSE(want.empty());
        // Image by image, segment by segment of the image (the base segments of one come in the
        // hash grid's order, which the bound does not touch).
        auto key = [](const std::tuple<int, int, int, int>& q) {
          return std::make_tuple(std::get<2>(q), std::get<3>(q), std::get<1>(q));
        };
        EXPECT_TRUE(std::is_sorted(got.begin(), got.end(), [&](auto& x, auto& y) { return key(x) < key(y); }));
        std::sort(got.begin(), got.end());
        std::sort(want.begin(), want.end());
        EXPECT_EQ(got, want) << "copies " << copies << " strain " << s.transpose() << " margin " << margin;
      }
    // The 2 x 2 patch at rest: the images two patches away are out of reach, and the bound says
    // so without mapping them (the ring of 16 of the 25).
    if (copies == 2) {
      const RveState st = rve.initial_state();
      const Strain s0 = Strain::Zero();
      const RveProblem::ImageBound b = rve.image_bound(s0, st);
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
      for (int v = 0; v < rve.pattern().size(); ++v) {
        lo = lo.cwiseMin(rve.position(s0, st, v, {0, 0}));
        hi = hi.cwiseMax(rve.position(s0, st, v, {0, 0}));
      }
      int skipped = 0;
      for (int ox = -2; ox <= 2; ++ox)
        for (int oy = -2; oy <= 2; ++oy) skipped += !b.may_reach({ox, oy}, lo, hi, 2 * rve.radius());
      EXPECT_GE(skipped, 16);
    }
  }
}
