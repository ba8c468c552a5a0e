// Strip mechanics (yarn/strip/strip_problem.hpp, strip_solve.hpp, strip_stretch.hpp): exact
// derivatives, a convex projected model, and the stretch test's physics: the two clamps'
// forces balance, the reported force is the derivative of the equilibrium energy with respect
// to the clamp separation (envelope theorem), a rigid motion of the whole strip changes
// nothing, and a run resumed from a step file gives the same force curve.
//
// The strip: stocktiny, a wale strip three courses high whose top and bottom courses are in
// the clamps. The tiny patterns' rest state is a straight yarn, and an unclamped edge course of
// it pulls its loops out of the next one (docs/strip.md, section 6); clamped, it holds.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <filesystem>
#include <map>
#include <limits>
#include <random>

#include "tests/common/yarn_support.hpp"
#include "yarn/rod/generate.hpp"
#include "yarn/strip/strip_generate.hpp"
#include "yarn/strip/strip_io.hpp"
#include "yarn/strip/strip_stretch.hpp"

using namespace yarnhom::yarn;
using yarnhom::numerics::closest_pair;
using yarnhom::numerics::ClosestPair;
using yarnhom::yarn::testing::rel_err;
using yarnhom::yarn::testing::shared_pattern;

namespace {

const StripTile& tile() {
  static const StripTile t = rest_tile(yarnhom::yarn::testing::have_shared_patterns() ? read_pyp(shared_pattern("stocktiny"))
                                                                                      : generate_stockinette({}),
                                       Material{});
  return t;
}

Strip test_strip() {
  StripSpec spec;
  spec.axis = StripAxis::kWale;
  spec.width = 2.43 * tile().lattice(0, 0);
  spec.length = 3.07 * tile().lattice(1, 1);
  return generate_strip(tile(), spec);
}
double band() { return 1.02 * tile().lattice(1, 1); }

StripSolveOptions solve_options() {
  StripSolveOptions o;
  o.tolerance = 1e-12;
  return o;
}

// Relax at 100 %, then the given stretches; results and final state.
struct StretchRun {
  std::vector<StretchStep> steps;
  StripState state;
};
StretchRun run(const StripStretch& S, const std::vector<double>& stretches, StripState st) {
  StretchRun r;
  double from = 1.0;
  for (double to : stretches) {
    r.steps.push_back(S.step(st, from, to, solve_options()));
    EXPECT_TRUE(r.steps.back().solve.converged()) << to << ": " << r.steps.back().solve.summary();
    from = to;
  }
  r.state = std::move(st);
  return r;
}

// The reference run, shared by the tests below (relaxing is the slow part).
struct Reference {
  Strip strip = test_strip();
  std::vector<signed char> clamp = clamp_flags(strip, band());
  StripProblem P{strip, Material{}, clamp};
  StripStretch S{P, strip.long_axis(), strip.x};
  StretchRun result = run(S, {1.0, 1.05, 1.1}, P.initial_state());
};
const Reference& reference() {
  static const Reference r;
  return r;
}

}  // namespace

TEST(StripProblem, GradientAndHessianMatchFiniteDifferences) {
  const Strip s = test_strip();
  // Clamp one end only, so that clamped, free and mixed elements all occur.
  std::vector<signed char> clamp = clamp_flags(s, band());
  for (auto& c : clamp) c = c > 0 ? 1 : 0;
  const StripProblem P(s, Material{}, clamp);
  StripState st = P.initial_state();
  std::mt19937 rng(7);
  std::normal_distribution<double> N(0, 0.03 * s.radius);
  for (int v = 0; v < s.size(); ++v)
    if (!clamp[v]) st.x[v] += Eigen::Vector3d(N(rng), N(rng), N(rng));
  for (auto& t : st.theta) t += N(rng) / s.radius;
  ASSERT_LT(P.min_distance(st), 1.0) << "contact is active";
  // Push one free segment toward its closest neighbour until the pair is at 0.35 x 2r, inside
  // the barrier's reach (d_hat 0.5 x 2r): the barrier's terms are then checked too.
  {
    const double two_r = 2 * s.radius;
    double best = std::numeric_limits<double>::infinity();
    int ba = -1, bb = -1;
    for (int ea = 0; ea < s.num_edges(); ++ea)
      for (int eb = ea + 1; eb < s.num_edges(); ++eb) {
        if (P.excluded(ea, eb) || clamp[eb] || clamp[s.next(eb)]) continue;
        const double d = segment_distance(st.x[ea], st.x[s.next(ea)], st.x[eb], st.x[s.next(eb)]);
        if (d < best) best = d, ba = ea, bb = eb;
      }
    ASSERT_GE(bb, 0);
    const int na = s.next(ba), nb = s.next(bb);
    const ClosestPair c = closest_pair(st.x[ba], st.x[na], st.x[bb], st.x[nb]);
    const Eigen::Vector3d pa = st.x[ba] + c.s * (st.x[na] - st.x[ba]), pb = st.x[bb] + c.t * (st.x[nb] - st.x[bb]);
    const Eigen::Vector3d shift = (pa - pb).normalized() * (best - 0.35 * two_r);
    st.x[bb] += shift;
    st.x[nb] += shift;
    EnergyParts parts;
    ASSERT_TRUE(std::isfinite(P.evaluate(st, nullptr, nullptr, &parts)));
    ASSERT_GT(parts.barrier, 0) << "the barrier is active";
  }

  Eigen::VectorXd g;
  BlockHessian B = P.make_hessian();
  std::vector<Eigen::Vector3d> vg;
  P.evaluate(st, &g, &B, nullptr, &vg);
  auto E_at = [&](const Eigen::VectorXd& y) {
    StripState t = st;
    P.apply_step(y, 1.0, t);
    return P.evaluate(t);
  };
  const int n = P.num_dofs();
  Eigen::VectorXd h(n);
  for (int i = 0; i < n; ++i) h[i] = P.force_scale()[i] == 1.0 ? 1e-9 : 1e-6;
  // A random sample of the unknowns (every kind of element is among them).
  std::vector<int> sample;
  for (int k = 0; k < 120; ++k) sample.push_back(rng() % n);
  Eigen::VectorXd fd(sample.size()), gs(sample.size());
  for (size_t k = 0; k < sample.size(); ++k) {
    const int i = sample[k];
    Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
    y[i] = h[i];
    const double ep = E_at(y);
    y[i] = -h[i];
    fd[k] = (ep - E_at(y)) / (2 * h[i]);
    gs[k] = g[i];
  }
  EXPECT_LT(rel_err(gs, fd), 1e-6);

  // Hessian columns against differences of the gradient (a random sample of columns).
  const Eigen::MatrixXd H = Eigen::MatrixXd(Eigen::SparseMatrix<double>(B.matrix().selfadjointView<Eigen::Lower>()));
  for (int k = 0; k < 40; ++k) {
    const int i = rng() % n;
    StripState a = st, b = st;
    Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
    y[i] = h[i];
    P.apply_step(y, 1.0, a);
    P.apply_step(y, -1.0, b);
    Eigen::VectorXd ga, gb;
    P.evaluate(a, &ga);
    P.evaluate(b, &gb);
    EXPECT_LT(rel_err(H.col(i), (ga - gb) / (2 * h[i]), 1e-30), 2e-5) << "column " << i;
  }

  // dE/dx of the clamped vertices (the clamp reactions) against moving them.
  for (int v = 0; v < s.size(); v += 7) {
    if (!clamp[v]) continue;
    for (int c = 0; c < 3; ++c) {
      StripState a = st, b = st;
      a.x[v][c] += 1e-9;
      b.x[v][c] -= 1e-9;
      EXPECT_NEAR(vg[v][c], (P.evaluate(a) - P.evaluate(b)) / 2e-9, 1e-6 * (vg[v].norm() + 1e-3));
    }
  }
}

TEST(StripProblem, ProjectedHessianIsPositiveSemiDefinite) {
  const Strip s = test_strip();
  const StripProblem P(s, Material{}, clamp_flags(s, band()));
  StripState st = P.initial_state();
  std::mt19937 rng(8);
  std::normal_distribution<double> N(0, 0.1 * s.radius);
  for (int v = 0; v < s.size(); ++v)
    if (!P.clamp()[v]) st.x[v] += Eigen::Vector3d(N(rng), N(rng), N(rng));
  BlockHessian B = P.make_hessian();
  auto eig = [&](bool project) {
    P.evaluate(st, nullptr, &B, nullptr, nullptr, project ? StripProblem::Projection::kAll : StripProblem::Projection::kNone);
    const Eigen::MatrixXd H = Eigen::MatrixXd(Eigen::SparseMatrix<double>(B.matrix().selfadjointView<Eigen::Lower>()));
    const Eigen::VectorXd d = H.diagonal().cwiseAbs().cwiseSqrt().cwiseInverse();
    return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(d.asDiagonal() * H * d.asDiagonal()).eigenvalues();
  };
  EXPECT_LT(eig(false)[0], -1e-3) << "the exact Hessian is indefinite here (the check can fail)";
  EXPECT_GT(eig(true)[0], -1e-10);
}

TEST(StripStretch, ClampForcesBalanceAndTheStripPullsBack) {
  const Reference& R = reference();
  for (const StretchStep& st : R.result.steps) {
    EXPECT_LT(std::abs(st.force_low + st.force_high), 1e-7 * std::abs(st.force)) << st.stretch;
    EXPECT_GT(st.min_distance, 0.5) << "no yarn passed through another";
    // The topology certificate: every move since the generated strip (Newton steps,
    // predictors) was checked by CCD and kept every pair above d_min.
    EXPECT_TRUE(st.certificate.valid) << st.certificate.failure;
    EXPECT_GT(st.certificate.moves, 0);
    EXPECT_GT(st.certificate.min_distance, R.P.contact().dmin());
  }
  // Stretched enough, the strip pulls the clamps in, the harder the further they are apart,
  // and its energy grows. (At 100 % it pushes them apart: stocktiny's rest state is a straight
  // yarn, and once cut free its loops relax and lengthen the strip, docs/strip.md section 6;
  // the generated strip itself carries no bulk stress: StripGenerate.StressFreeTile...)
  const auto& s = R.result.steps;
  EXPECT_GT(s[1].force, s[0].force);
  EXPECT_GT(s[2].force, 0);
  EXPECT_GT(s[2].force, s[1].force);
  EXPECT_GT(s[2].energy, s[1].energy);
  EXPECT_NEAR(s[2].tension, s[2].force / R.strip.width, 1e-12 * std::abs(s[2].tension));
  // The push at 100 % is stocktiny's: the built-in stockinette's strip pulls (+3.6e-4 N).
  YARN_REQUIRE_SHARED_PATTERNS() << " (" << shared_pattern("stocktiny")
                                 << " missing; the push at 100 % is stocktiny's)";
  EXPECT_LT(s[0].force, 0);
}

TEST(StripStretch, ForceIsTheDerivativeOfTheEquilibriumEnergy) {
  // Envelope theorem: with the frames fixed (as within one load step), the equilibrium energy
  // E*(lambda) has dE*/d(separation) = (F_high - F_low) / 2, the separation growing by L per
  // unit of lambda.
  const Reference& R = reference();
  const double lam = 1.1, h = 2e-4;
  auto equilibrium = [&](double to) {
    StripState st = R.result.state;  // converged at 1.1, frames re-based there
    R.S.predict(st, lam, to);
    const StripSolveReport rep = solve_strip(R.P, st, solve_options());
    EXPECT_TRUE(rep.converged()) << rep.summary();
    return R.S.measure(st, to);
  };
  const StretchStep mid = equilibrium(lam);
  const double dE = (equilibrium(lam + h).energy - equilibrium(lam - h).energy) / (2 * h * R.strip.length);
  EXPECT_NEAR(dE, mid.force, 1e-4 * std::abs(mid.force));
  EXPECT_GT(std::abs(mid.force), 0);
}

TEST(StripStretch, RigidMotionOfTheWholeStripChangesNothing) {
  const Reference& R = reference();
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.01, -0.02, 0.005);
  Strip moved = R.strip;
  for (auto& x : moved.x) x = Q * x + t;
  for (auto& d : moved.ref_d1) d = Q * d;
  const StripProblem P(moved, Material{}, R.clamp);
  const StripStretch S(P, Q * R.strip.long_axis(), moved.x);
  const StretchRun r = run(S, {1.0, 1.05, 1.1}, P.initial_state());
  for (size_t k = 0; k < r.steps.size(); ++k) {
    EXPECT_NEAR(r.steps[k].force, R.result.steps[k].force, 1e-7 * std::abs(R.result.steps[k].force)) << k;
    EXPECT_NEAR(r.steps[k].energy, R.result.steps[k].energy, 1e-9 * R.result.steps[k].energy) << k;
  }
  double dx = 0;
  for (int v = 0; v < moved.size(); ++v)
    dx = std::max(dx, (r.state.x[v] - (Q * R.result.state.x[v] + t)).norm());
  EXPECT_LT(dx, 1e-6 * R.strip.radius);
}

TEST(StripStretch, ResumingFromAStepFileGivesTheSameForceCurve) {
  // Kill after the second step (its step file is what survives), resume from the file.
  const Reference& R = reference();
  const std::string path = (std::filesystem::temp_directory_path() / ("yarnhom_strip_step_" + std::to_string(::getpid()) + ".h5")).string();
  const StretchRun first = run(R.S, {1.0, 1.05}, R.P.initial_state());
  write_step(path, R.strip, first.steps.back(), first.state);
  StripState resumed;
  const StretchStep last = read_step(path, R.P, resumed);
  std::filesystem::remove(path);
  EXPECT_EQ(last.force, first.steps.back().force);
  EXPECT_EQ(last.stretch, 1.05);
  // The topology certificate is carried on: a resumed run certifies its whole path.
  EXPECT_TRUE(resumed.certificate.valid) << resumed.certificate.failure;
  EXPECT_EQ(resumed.certificate.moves, first.state.certificate.moves);
  EXPECT_EQ(resumed.certificate.min_distance, first.state.certificate.min_distance);
  EXPECT_EQ(resumed.certificate.dmin, R.P.contact().dmin());
  StripState st = resumed;
  const StretchStep third = R.S.step(st, 1.05, 1.1, solve_options());
  for (size_t k = 0; k < 2; ++k) EXPECT_EQ(first.steps[k].force, R.result.steps[k].force) << "deterministic";
  EXPECT_EQ(third.force, R.result.steps[2].force);
  EXPECT_EQ(third.energy, R.result.steps[2].energy);
}

TEST(StripStretch, PredictorNeverBringsPointsCloser) {
  const Reference& R = reference();
  StripState st = R.result.steps.empty() ? R.P.initial_state() : R.result.state;
  const StripState before = st;
  R.S.predict(st, 1.1, 1.3);
  std::mt19937 rng(1);
  for (int k = 0; k < 2000; ++k) {
    const int a = rng() % st.x.size(), b = rng() % st.x.size();
    EXPECT_GE((st.x[a] - st.x[b]).norm(), (before.x[a] - before.x[b]).norm() * (1 - 1e-14));
  }
  for (int v = 0; v < R.strip.size(); ++v)
    if (R.clamp[v]) { EXPECT_NEAR((st.x[v] - R.strip.x[v]).dot(R.strip.long_axis()), R.clamp[v] * 0.5 * (1.3 - 1.0) * R.strip.length, 1e-15); }
}

TEST(StripProblem, BothHessiansInOnePassAreTheExactAndTheProjectedOne) {
  // The trust-region solver assembles the exact and the projected Hessian in one pass (the
  // projected one as the exact one plus the corrections of the non-convex elements).
  const Strip s = test_strip();
  const StripProblem P(s, Material{}, clamp_flags(s, band()));
  StripState st = P.initial_state();
  std::mt19937 rng(9);
  std::normal_distribution<double> N(0, 0.1 * s.radius);
  for (int v = 0; v < s.size(); ++v)
    if (!P.clamp()[v]) st.x[v] += Eigen::Vector3d(N(rng), N(rng), N(rng));
  BlockHessian exact = P.make_hessian(), projected = P.make_hessian(), both = P.make_hessian(), both_p = P.make_hessian();
  Eigen::VectorXd g1, g2;
  P.evaluate(st, &g1, &exact);
  P.evaluate(st, nullptr, &projected, nullptr, nullptr, StripProblem::Projection::kAll);
  P.evaluate(st, &g2, &both, nullptr, nullptr, StripProblem::Projection::kNone, &both_p);
  auto dense = [](const BlockHessian& B) {
    return Eigen::MatrixXd(Eigen::SparseMatrix<double>(B.matrix().selfadjointView<Eigen::Lower>()));
  };
  const Eigen::MatrixXd He = dense(exact), Hp = dense(projected);
  EXPECT_LT(rel_err(dense(both), He), 1e-14);
  EXPECT_LT(rel_err(dense(both_p), Hp), 1e-12);
  EXPECT_GT(rel_err(Hp, He), 1e-6) << "some elements are not convex here (the check can fail)";
  EXPECT_EQ(g1, g2);
}

TEST(StripProblem, HessianMarginChangesThePatternNotTheValues) {
  // Pairs beyond the contact's reach add zeros to the pattern, nothing else: the strip's default
  // margin 0 (the smaller factor) and the RVE's 0.5 radii give the same matrix.
  const Strip s = test_strip();
  StripOptions wide;
  wide.hessian_margin = 0.5;
  const StripProblem P(s, Material{}, clamp_flags(s, band())), Pw(s, Material{}, clamp_flags(s, band()), wide);
  ASSERT_EQ(StripOptions{}.hessian_margin, 0.0);
  StripState st = P.initial_state();
  std::mt19937 rng(11);
  std::normal_distribution<double> N(0, 0.05 * s.radius);
  for (int v = 0; v < s.size(); ++v)
    if (!P.clamp()[v]) st.x[v] += Eigen::Vector3d(N(rng), N(rng), N(rng));
  BlockHessian B = P.make_hessian(), Bw = Pw.make_hessian();
  P.evaluate(st, nullptr, &B);
  Pw.evaluate(st, nullptr, &Bw);
  EXPECT_LT(B.matrix().nonZeros(), Bw.matrix().nonZeros()) << "the margin adds pairs here (the check can fail)";
  auto dense = [](const BlockHessian& H) { return Eigen::MatrixXd(H.matrix()); };
  EXPECT_LT(rel_err(dense(B), dense(Bw)), 1e-14);
}

TEST(StripSolve, TrustRegionAndSwitchedNewtonReachTheSameEquilibrium) {
  // The trust region, the switched method, and the trust region handing over to the switched
  // method after its first iteration (as it does when it stalls) from the same start.
  const Reference& R = reference();
  StretchStep r[3];
  for (int k = 0; k < 3; ++k) {
    StripState st = R.result.state;  // converged at 1.1
    StripSolveOptions o = solve_options();
    o.method = k == 1 ? StripSolveOptions::Method::kSwitched : StripSolveOptions::Method::kTrustRegion;
    if (k == 2) o.trust_stall_iterations = 1;
    r[k] = R.S.step(st, 1.1, 1.13, o);
    EXPECT_TRUE(r[k].solve.converged()) << k << ": " << r[k].solve.summary();
    EXPECT_TRUE(r[k].certificate.valid) << k << ": " << r[k].certificate.failure;
    if (k < 2) { EXPECT_FALSE(r[k].solve.fallback) << k; }
  }
  for (int k : {0, 2}) {
    EXPECT_NEAR(r[k].energy, r[1].energy, 1e-10 * r[1].energy) << k;
    EXPECT_NEAR(r[k].force, r[1].force, 1e-7 * std::abs(r[1].force)) << k;
  }
  // The hand-over happens on stocktiny's step; on the built-in stockinette's the trust region
  // converges without stalling, so k = 2 does not test it.
  YARN_REQUIRE_SHARED_PATTERNS() << " (" << shared_pattern("stocktiny")
                                 << " missing; the built-in stockinette's step never stalls the trust region)";
  EXPECT_TRUE(r[2].solve.fallback) << r[2].solve.summary();
}
