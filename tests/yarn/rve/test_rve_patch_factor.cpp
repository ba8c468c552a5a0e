// The sparse factorization of a patch RVE's Newton system (yarn/rve/newton.hpp,
// numerics/hessian_factor.hpp): the height term kept apart and solved by Woodbury gives the
// dense factorization's Newton step and the same answer on definiteness; a pattern kept across
// changing contact pairs is still correct; whole solves on both paths reach the same equilibrium.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>
#include <vector>

#include "numerics/hessian_factor.hpp"
#include "tests/common/yarn_support.hpp"
#include "yarn/rod/generate.hpp"
#include "yarn/rve/energy_density.hpp"
#include "yarn/rve/newton.hpp"
#include "yarn/rve/relax.hpp"

using namespace yarnhom::yarn;
using yarnhom::numerics::HessianFactor;

namespace {

Strain strain(double a, double b, double c, double d, double e, double f) {
  Strain s;
  s << a, b, c, d, e, f;
  return s;
}

// The 2 x 2 patch of the paper's tiny stockinette relaxed at rest (as produce --tile 2,2 makes
// it), or of the generated stockinette relaxed where the shared patterns are absent.
const RestTile& patch() {
  static const RestTile t = [] {
    const Pattern p = yarnhom::yarn::testing::have_shared_patterns()
                          ? read_pyp(yarnhom::yarn::testing::shared_pattern("stocktiny"))
                          : relax_pattern(generate_stockinette({}), Material{});
    return repeat_rest(p, relax_tile(p, Material{}), 2, 2);
  }();
  return t;
}

// The rest state moved by a random step of `size` yarn radii (positions) per unknown.
RveState moved(const RveProblem& rve, const RveState& from, double size, unsigned seed) {
  RveState st = from;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd d(rve.num_dofs());
  for (int i = 0; i < d.size(); ++i) d[i] = U(rng) * size * (rve.force_scale()[i] == 1.0 ? rve.radius() : 1.0);
  rve.apply_step(d, 1.0, st);
  return st;
}

struct Step {
  bool ok = false;
  Eigen::VectorXd d;
};

// The dense path as every RVE solve up to this change assembled it: the height term among the triplets.
Step dense_step(const RveProblem& rve, const Strain& s, const RveState& st, double mu) {
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd g;
  rve.evaluate(s, st, &g, &trip);
  HessianFactor H(rve.num_dofs(), 1000000);
  H.assemble(trip);
  Step r;
  r.ok = H.factor(mu);
  if (r.ok) r.d = H.solve(-g);
  return r;
}

Step sparse_step(HessianFactor& H, const RveProblem& rve, const Strain& s, const RveState& st, double mu,
                 size_t* triplets = nullptr) {
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd g;
  RveProblem::HeightTerm height;
  rve.evaluate_hessian(s, st, &g, &trip, &height);
  if (triplets) *triplets = trip.size();
  H.assemble(trip, height.U, height.C);
  Step r;
  r.ok = H.factor(mu);
  if (r.ok) r.d = H.solve(-g);
  return r;
}

double rel(const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return (a - b).norm() / b.norm(); }

}  // namespace

TEST(RvePatchFactor, SparsePathGivesTheDenseNewtonStep) {
  const RveProblem& rve = patch().rve;
  ASSERT_GT(rve.num_dofs(), 150);
  // Stretch and shear (flat), bending; at the rest state and moved from it. The shift grows as
  // in a solve (0, then 1e-4 x 10^k) until the dense factorization accepts: the sparse one must
  // refuse and accept at the same shifts, and give the same step there.
  int refused = 0, compared = 0;
  for (const Strain& s : {strain(0.1, 0.05, 0, 0, 0, 0), strain(0, 0.2, -0.05, 0, 0, 0), strain(0.05, 0, 0, 60, 0, -40)})
    for (double size : {0.0, 0.05}) {
      const RveState st = moved(rve, patch().state, size, 11);
      HessianFactor H(rve.num_dofs(), 0, true);
      for (double mu = 0; mu < 1e3; mu = mu == 0 ? 1e-4 : 10 * mu) {
        const Step ref = dense_step(rve, s, st, mu);
        const Step got = sparse_step(H, rve, s, st, mu);
        ASSERT_EQ(got.ok, ref.ok) << s.transpose() << " size " << size << " mu " << mu;
        if (!ref.ok) {
          ++refused;
          continue;
        }
        EXPECT_LT(rel(got.d, ref.d), 1e-10) << s.transpose() << " size " << size << " mu " << mu;
        ++compared;
        break;
      }
    }
  EXPECT_EQ(compared, 6);
  EXPECT_GT(refused, 0) << "some of these systems need the shift: the definiteness test is exercised";
}

TEST(RvePatchFactor, AnalysisKeptAcrossChangingContactPairsStaysCorrect) {
  const RveProblem& rve = patch().rve;
  // Three states whose candidate contact pairs differ (a large shear moves the yarns past one
  // another), factored in turn by one HessianFactor that keeps its pattern, twice over: each
  // step must be the dense one of its own state (with a shift that makes all three definite),
  // and the second round, whose entries the pattern already holds, adds no analysis.
  const std::vector<std::pair<Strain, double>> states = {
      {strain(0.05, 0, 0, 0, 0, 0), 0.0}, {strain(0.3, 0.3, -0.1, 0, 0, 0), 0.02}, {strain(0, 0, 0.2, 30, 0, 0), 0.0}};
  const double mu = 1.0;
  HessianFactor H(rve.num_dofs(), 0, true);
  std::vector<size_t> triplets;
  int analyses_first_round = 0;
  for (int round = 0; round < 2; ++round) {
    for (const auto& [s, size] : states) {
      const RveState st = moved(rve, patch().state, size, 5);
      const Step ref = dense_step(rve, s, st, mu);
      size_t nt = 0;
      const Step got = sparse_step(H, rve, s, st, mu, &nt);
      ASSERT_TRUE(ref.ok && got.ok) << s.transpose();
      EXPECT_LT(rel(got.d, ref.d), 1e-10) << "round " << round << " strain " << s.transpose();
      if (round == 0) triplets.push_back(nt);
    }
    if (round == 0) analyses_first_round = H.analyses();
  }
  EXPECT_EQ(H.analyses(), analyses_first_round);
  EXPECT_GE(analyses_first_round, 2) << "the contact pairs changed between the states";
  EXPECT_NE(triplets[0], triplets[1]);
}

TEST(RvePatchFactor, SparseAndDenseSolvesReachTheSameEquilibrium) {
  const RveProblem& rve = patch().rve;
  for (const Strain& s : {strain(0.2, 0.1, 0, 0, 0, 0), strain(0.05, 0, 0.05, 80, 0, 0)}) {
    DensityResult r[2];
    RveState st[2] = {patch().state, patch().state};
    for (int k = 0; k < 2; ++k) {
      SolveOptions opt;
      opt.dense_limit = k == 0 ? 1000000 : 0;
      r[k] = energy_density(rve, s, st[k], opt);
      ASSERT_TRUE(r[k].report.converged()) << (k ? "sparse " : "dense ") << r[k].report.summary();
    }
    EXPECT_EQ(r[1].report.analyses > 0, true);
    EXPECT_NEAR(r[1].psi, r[0].psi, 1e-10 * r[0].psi) << s.transpose();
    EXPECT_LT((r[1].grad - r[0].grad).norm(), 1e-7 * r[0].grad.norm()) << s.transpose();
    EXPECT_LT(std::abs(r[1].report.iterations - r[0].report.iterations), 2) << s.transpose();
  }
}
