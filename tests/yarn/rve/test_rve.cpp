// The RVE problem: exact reduced gradient and Hessian (finite differences), dE/ds at fixed
// unknowns, invariance under rigid motions, equilibrium and local minimality of the relaxed
// rest state, tiling invariance, the envelope theorem, warm starts, zero modes, failure status.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <omp.h>
#include <random>
#include <set>
#include <tuple>
#include <Eigen/Eigenvalues>

#include "tests/common/yarn_support.hpp"
#include "yarn/rve/energy_density.hpp"
#include "yarn/rod/generate.hpp"
#include "yarn/rve/relax.hpp"

using namespace yarnhom::yarn;
using yarnhom::yarn::testing::rel_err;
using yarnhom::yarn::testing::shared_pattern;

using yarnhom::yarn::testing::strain;

namespace {

// A state near equilibrium but not at it: the pattern's own state with small perturbations.
RveState perturbed(const RveProblem& rve, unsigned seed) {
  RveState st = rve.initial_state();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd d(rve.num_dofs());
  for (int i = 0; i < d.size(); ++i) d[i] = U(rng) * 0.05 * rve.radius() / rve.force_scale()[i] * (rve.force_scale()[i] == 1.0 ? 1.0 : 1.0 / rve.radius());
  rve.apply_step(d, 1.0, st);
  return st;
}

Eigen::MatrixXd dense_hessian(const RveProblem& rve, const Strain& s, const RveState& st) {
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd g;
  rve.evaluate(s, st, &g, &trip);
  Eigen::SparseMatrix<double> H(rve.num_dofs(), rve.num_dofs());
  for (const auto& t : trip) EXPECT_GE(t.row(), t.col()) << "only the lower triangle is assembled";
  H.setFromTriplets(trip.begin(), trip.end());
  const Eigen::SparseMatrix<double> full = H.selfadjointView<Eigen::Lower>();
  return Eigen::MatrixXd(full);
}

// The paper's tiny stockinette when the shared patterns are there, else the generated one
// relaxed (as stocktiny is): these tests run everywhere. Not the generated geometry itself:
// it is an initial guess (generate.hpp) whose closest centrelines are 0.28 x 2r apart, just
// above the barrier's d_min (0.25 x 2r), so a shear of 0.3 or a perturbation of 0.05 r from
// it crosses d_min and the energy is +inf (the relaxed one: 0.89 x 2r, stocktiny 0.85 x 2r).
Pattern small_knit(const char* shared = "stocktiny") {
  if (yarnhom::yarn::testing::have_shared_patterns()) return read_pyp(shared_pattern(shared));
  static const Pattern relaxed = relax_pattern(generate_stockinette({}), Material{});
  return relaxed;
}

double step_for(const RveProblem& rve, int i) { return rve.force_scale()[i] == 1.0 ? 1e-9 : 1e-6; }

Pattern rotated90(const Pattern& p) {
  Pattern q = p;
  q.px = p.py;
  q.py = p.px;
  for (auto& x : q.x) x = Eigen::Vector3d(-x[1], x[0], x[2]);
  for (auto& d : q.ref_d1) d = Eigen::Vector3d(-d[1], d[0], d[2]);
  for (auto& e : q.edges) e = {e.v0, e.v1, -e.dy, e.dx};
  return q;
}

}  // namespace

TEST(Rve, ReducedGradientAndHessianMatchFiniteDifferences) {
  const RveProblem rve(small_knit(), Material{});
  const RveState st = perturbed(rve, 1);
  for (const Strain& s : {Strain(Strain::Zero()), strain(0.1, 0.2, -0.05, 50, 20, -30)}) {
    Eigen::VectorXd g;
    EnergyParts parts;
    rve.evaluate(s, st, &g, nullptr, &parts);
    ASSERT_GT(parts.contact, 0) << "the test needs active contacts";
    const int N = rve.num_dofs();
    Eigen::VectorXd gfd(N);
    Eigen::MatrixXd Hfd(N, N);
    for (int i = 0; i < N; ++i) {
      const double h = step_for(rve, i);
      Eigen::VectorXd e = Eigen::VectorXd::Zero(N);
      e[i] = 1;
      RveState p = st, m = st;
      rve.apply_step(e, h, p);
      rve.apply_step(e, -h, m);
      Eigen::VectorXd gp, gm;
      const double Ep = rve.evaluate(s, p, &gp), Em = rve.evaluate(s, m, &gm);
      gfd[i] = (Ep - Em) / (2 * h);
      Hfd.col(i) = (gp - gm) / (2 * h);
    }
    EXPECT_LT(rel_err(g, gfd), 1e-6);
    const Eigen::MatrixXd H = dense_hessian(rve, s, st);
    EXPECT_LT(rel_err(H, Hfd), 1e-5);
    EXPECT_LT((H - H.transpose()).norm(), 1e-12 * H.norm());
  }
}

TEST(Rve, StrainDerivativeAtFixedUnknownsMatchesFiniteDifferences) {
  const RveProblem rve(small_knit(), Material{});
  const RveState st = perturbed(rve, 2);
  const Strain s = strain(0.15, -0.1, 0.05, -40, 25, 60);
  Strain dE;
  rve.evaluate(s, st, nullptr, nullptr, nullptr, &dE);
  for (int k = 0; k < 6; ++k) {
    const double h = k < 3 ? 1e-6 : 1e-3;
    Strain sp = s, sm = s;
    sp[k] += h;
    sm[k] -= h;
    const double fd = (rve.evaluate(sp, st) - rve.evaluate(sm, st)) / (2 * h);
    EXPECT_NEAR(dE[k], fd, 1e-6 * dE.norm()) << "component " << k;
  }
}

TEST(Rve, EnergyInvariantUnderRigidMotionOfTheWholeRve) {
  const Pattern p = small_knit();
  const RveProblem rve(p, Material{});
  // Translation: shifting the whole pattern (in-plane and along the normal) translates every
  // vertex and every image rigidly under a flat strain.
  Pattern shifted = p;
  for (auto& x : shifted.x) x += Eigen::Vector3d(2e-4, -1e-4, 3e-5);
  const RveProblem rve_t(shifted, Material{});
  // Rotation: the pattern turned by 90 degrees about the normal, under the strain turned with
  // it (s_x <-> s_y, s_a -> -s_a, II likewise), is the same RVE rotated rigidly by a
  // strain-dependent rotation about the normal. The rods' reference directors are parallel
  // transported from the rest tangents, which does not commute with that rotation, so the
  // material frames differ by a twist that the twist angles absorb: the minimum, Psi, agrees.
  const RveProblem rve_r(rotated90(p), Material{});
  for (const Strain& s : {strain(0.1, 0.3, -0.1, 0, 0, 0), strain(0.2, -0.2, 0.3, 80, -50, 30)}) {
    RveState a = rve.initial_state();
    const double E = rve.evaluate(s, a);
    if (s.tail<3>().isZero()) {
      EXPECT_NEAR(rve_t.evaluate(s, rve_t.initial_state()), E, 1e-12 * E);
    }
    const Strain sr = strain(s[2], -s[1], s[0], s[5], -s[4], s[3]);
    RveState b = rve_r.initial_state();
    const DensityResult ra = energy_density(rve, s, a), rb = energy_density(rve_r, sr, b);
    ASSERT_TRUE(ra.report.converged() && rb.report.converged());
    EXPECT_NEAR(rb.psi, ra.psi, 1e-9 * ra.psi);
    // dPsi/ds turns with the strain.
    const Strain gr = strain(ra.grad[2], -ra.grad[1], ra.grad[0], ra.grad[5], -ra.grad[4], ra.grad[3]);
    EXPECT_LT((rb.grad - gr).norm(), 1e-5 * gr.norm());
  }
  // Any rigid rotation in 3D: element-level tests (test_rod.cpp, test_contact.cpp).
}

TEST(Rve, RelaxedRestIsAnEquilibriumAndALocalMinimum) {
  const RveProblem rve(small_knit(), Material{});
  RveState st = rve.initial_state();
  const DensityResult r0 = energy_density(rve, Strain::Zero(), st);
  ASSERT_TRUE(r0.report.converged()) << r0.report.summary();
  EXPECT_LT(r0.report.residual, 1e-10);
  // Local minimum in the unknowns: the unshifted Hessian is positive definite...
  const Eigen::MatrixXd H = dense_hessian(rve, Strain::Zero(), st);
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues();
  EXPECT_GT(ev.minCoeff(), 0.0);
  // ... and the energy rises along random directions.
  std::mt19937 rng(4);
  std::normal_distribution<double> N01;
  for (int k = 0; k < 10; ++k) {
    Eigen::VectorXd d(rve.num_dofs());
    for (int i = 0; i < d.size(); ++i) d[i] = N01(rng) * 1e-3 * rve.radius() / rve.force_scale()[i];
    RveState a = st;
    rve.apply_step(d, 1.0, a);
    EXPECT_GT(rve.evaluate(Strain::Zero(), a), r0.report.energy);
  }
  // In strain space: the tile of a stored pattern is not stress free (dPsi/ds(0) != 0; the
  // period is imposed), so Psi(s) >= Psi(0) cannot hold for all small s. What minimality
  // means there: Psi lies above its tangent plane at 0 for small strains in every direction.
  for (int k = 0; k < 6; ++k)
    for (double sign : {-1.0, 1.0}) {
      Strain s = Strain::Zero();
      s[k] = sign * (k < 3 ? 2e-3 : 2.0);
      RveState w = st;
      const DensityResult r = energy_density(rve, s, w);
      ASSERT_TRUE(r.report.converged());
      EXPECT_GE(r.psi - r0.psi - r0.grad.dot(s), -1e-12 * r0.psi) << "direction " << k << " sign " << sign;
    }
}

// The 1 x 1 equilibrium repeated over a 2 x 1 tile is an equilibrium of the 2 x 1 RVE with the
// same Psi and dPsi/ds (periodicity is implemented right). We start the larger tile from the
// repeated state rather than cold: with the default material the larger tile has other,
// lower minima that the small one cannot represent (stocktiny at rest: Psi 1.20564 against
// 1.20575 J/m^2 cold from the pattern, a period-doubled state; docs/rve.md section 6), and
// which minimum a cold solve finds is not what this test is about.
TEST(Rve, TwoByOneTilingGivesTheSamePsi) {
  const Pattern p = small_knit();
  const RveProblem one(p, Material{}), two(tile(p, 2, 1), Material{});
  RveState a = one.initial_state();
  for (const Strain& s : {Strain(Strain::Zero()), strain(0.2, 0.1, -0.05, 0, 0, 0), strain(0.1, 0, 0.1, 30, 0, 0)}) {
    const DensityResult ra = energy_density(one, s, a);
    RveState b = tile_state(a, 2);
    const DensityResult rb = energy_density(two, s, b);
    ASSERT_TRUE(ra.report.converged() && rb.report.converged());
    // Flat strains: the same equilibrium (no Newton step needed), identical up to round-off.
    // With curvature the mid-surface's metric drifts away from the centre (docs/rve.md
    // section 2), so a tile twice as wide sees slightly different strains: a looser bound.
    const bool flat = s.tail<3>().isZero();
    EXPECT_NEAR(rb.psi, ra.psi, (flat ? 1e-8 : 2e-2) * ra.psi) << s.transpose();
    if (flat) {
      EXPECT_LE(rb.report.iterations, 1) << s.transpose();
      EXPECT_LT((rb.grad - ra.grad).norm(), 1e-6 * ra.grad.norm());
    }
  }
}

TEST(Rve, EnvelopeGradientMatchesFiniteDifferencesOfPsi) {
  const RveProblem rve(small_knit(), Material{});
  RveState st = rve.initial_state();
  SolveOptions opt;
  opt.tolerance = 1e-13;
  const Strain s0 = strain(0.1, 0.05, 0.05, 30, 10, -20);
  const DensityResult r = energy_density(rve, s0, st, opt);
  ASSERT_TRUE(r.report.converged());
  for (int k = 0; k < 6; ++k) {
    // Richardson-extrapolated central differences (steps h and h/2): O(h^4), so that the
    // comparison does not depend on how curved Psi is at this strain.
    const double h = k < 3 ? 1e-4 : 0.1;
    auto central = [&](double step) {
      Strain sp = s0, sm = s0;
      sp[k] += step;
      sm[k] -= step;
      RveState a = st, b = st;
      const DensityResult rp = energy_density(rve, sp, a, opt), rm = energy_density(rve, sm, b, opt);
      EXPECT_TRUE(rp.report.converged() && rm.report.converged());
      return (rp.psi - rm.psi) / (2 * step);
    };
    const double fd = (4 * central(h / 2) - central(h)) / 3;
    EXPECT_NEAR(r.grad[k], fd, 1e-7 * r.grad.norm() + 1e-6 * std::abs(fd)) << "component " << k;
  }
}

TEST(Rve, WarmStartReachesTheSameSolutionInFewerIterations) {
  const RveProblem rve(small_knit(), Material{});
  RveState rest = rve.initial_state();
  ASSERT_TRUE(solve(rve, Strain::Zero(), rest).converged());
  const Strain s = strain(0.3, 0, 0, 0, 0, 0), near = strain(0.28, 0, 0, 0, 0, 0);
  RveState cold = rest, warm = rest;
  const DensityResult rc = energy_density(rve, s, cold);
  ASSERT_TRUE(solve(rve, near, warm).converged());
  const DensityResult rw = energy_density(rve, s, warm);
  ASSERT_TRUE(rc.report.converged() && rw.report.converged());
  EXPECT_NEAR(rw.psi, rc.psi, 1e-9 * rc.psi);
  EXPECT_LT(rw.report.iterations, rc.report.iterations);
}

TEST(Rve, ZeroModesAreExactAndPinned) {
  const RveProblem rve(small_knit(), Material{});
  const RveState st = perturbed(rve, 3);
  const Strain s = strain(0.1, 0.1, 0.1, 0, 0, 0);
  const double E = rve.evaluate(s, st);
  // Uniform twist rotation of a yarn with zero rest curvature: an exact zero mode, pinned.
  RveState t = st;
  for (double& th : t.theta) th += 0.3;
  EXPECT_NEAR(rve.evaluate(s, t), E, 1e-12 * E);
  EXPECT_EQ(rve.twist_pinned().size(), rve.topo().yarns.size());
  EXPECT_LT(rve.theta_index(rve.twist_pinned()[0]), 0);
  // Translation of the whole RVE under a flat strain: exact zero mode, pinned by vertex 0.
  RveState u = st;
  for (auto& x : u.u) x += Eigen::Vector3d(1e-5, -2e-5, 3e-5);
  EXPECT_NEAR(rve.evaluate(s, u), E, 1e-12 * E);
  EXPECT_EQ(rve.pos_count(rve.pinned_vertex()), 1) << "its height only, and that follows the others'";
  // With the modes pinned, the relaxed Hessian is positive definite (checked above); without
  // the twist pin it would be singular: the zero mode's direction has zero curvature.
  RveState rest = rve.initial_state();
  ASSERT_TRUE(solve(rve, s, rest).converged());
  RveState a = rest, b = rest;
  for (double& th : a.theta) th += 1e-4;
  for (double& th : b.theta) th -= 1e-4;
  const double E0 = rve.evaluate(s, rest);
  EXPECT_NEAR(rve.evaluate(s, a) + rve.evaluate(s, b) - 2 * E0, 0.0, 1e-12 * E0);
}

// Under curvature the yarns must not slide through the thickness: the mid-surface is where
// they are on average. With one vertex's height pinned instead, the stretched, bent tile moved
// towards the centre of curvature, where its yarns are shorter (the paper's basket at s_x 0.3,
// II_x 100 /m: 1.4 mm, more than a yarn radius, Psi 2.47 -> 2.20 J/m^2 below the flat tile's).
TEST(Rve, BentTileKeepsTheYarnsMeanHeightOnTheMidSurface) {
  const RveProblem rve(small_knit(), Material{});
  for (const Strain& s : {strain(0.3, 0, 0, 150, 0, 0), strain(0.2, 0.1, 0.1, -80, 20, 120)}) {
    RveState st = rve.initial_state();
    ASSERT_TRUE(solve(rve, s, st).converged());
    EXPECT_NEAR(rve.mean_height(st), 0.0, 1e-12 * rve.radius());
    EXPECT_NEAR(st.u[rve.pinned_vertex()][2], rve.dependent_height(st), 1e-15);
    EXPECT_TRUE(st.u[rve.pinned_vertex()].head<2>().isZero(0.0));
    // The pinned vertex is free to move with the rest: its height is not held at zero.
    EXPECT_GT(std::abs(st.u[rve.pinned_vertex()][2]), 1e-3 * rve.radius());
  }
}

TEST(Rve, FailureIsReportedNotHidden) {
  const RveProblem rve(small_knit(), Material{});
  RveState st = rve.initial_state();
  SolveOptions opt;
  opt.max_iterations = 1;
  const SolveReport rep = solve(rve, strain(0.5, 0.3, 0.2, 0, 0, 0), st, opt);
  EXPECT_FALSE(rep.converged());
  EXPECT_EQ(rep.status, SolveStatus::kMaxIterations);
  EXPECT_NE(rep.summary().find("max_iterations"), std::string::npos);
  EXPECT_GT(rep.residual, opt.tolerance);
}

TEST(Rve, BroadPhaseFindsExactlyTheInteractingPairsOfAllPairs) {
  const RveProblem rve(small_knit("stocktiniest"), Material{});
  const RveState st = perturbed(rve, 5);
  const Strain s = strain(-0.15, 0.4, -0.1, 100, 0, -50);
  const int n = rve.pattern().size();
  const ContactParams c{rve.radius(), 1.0, 4};
  // Brute force over all pairs and images within 2 tiles: every pair with non-zero contact
  // energy must be in the broad phase's list.
  std::set<std::tuple<int, int, int, int>> found;
  for (const auto& p : rve.contact_pairs(s, st, 0.0)) found.insert({p.a, p.b, p.o[0], p.o[1]});
  int interacting = 0;
  for (int a = 0; a < n; ++a)
    for (int b = a; b < n; ++b)
      for (int ox = -2; ox <= 2; ++ox)
        for (int oy = -2; oy <= 2; ++oy) {
          const Eigen::Vector2i o(ox, oy);
          if (a == b && (ox < 0 || (ox == 0 && oy <= 0))) continue;
          if (rve.excluded(a, b, o)) continue;
          const auto& t = rve.topo();
          Vec12 q;
          q << rve.position(s, st, a, {0, 0}), rve.position(s, st, t.next[a], t.offset[a]),
              rve.position(s, st, b, o), rve.position(s, st, t.next[b], o + t.offset[b]);
          if (segment_contact_energy(q, 1, 1, c, nullptr, nullptr) > 0) {
            ++interacting;
            EXPECT_TRUE(found.count({a, b, ox, oy})) << a << " " << b << " " << ox << " " << oy;
          }
        }
  EXPECT_GT(interacting, 5);
  EXPECT_LT(found.size(), size_t(n * n * 25 / 2));  // not all pairs
}

TEST(Rve, ParallelAssemblyMatchesSerial) {
  // 208 vertices: above the size where evaluate() splits its sums over threads.
  const RveProblem rve(tile(small_knit(), 4, 4), Material{});
  const RveState st = perturbed(rve, 9);
  const Strain s = strain(0.1, 0.2, -0.05, 50, 20, -30);
  auto run = [&](int threads, Eigen::VectorXd& g, Eigen::MatrixXd& H, Strain& d) {
    const int before = omp_get_max_threads();
    omp_set_num_threads(threads);
    std::vector<Eigen::Triplet<double>> trip;
    const double E = rve.evaluate(s, st, &g, &trip, nullptr, &d);
    Eigen::SparseMatrix<double> M(rve.num_dofs(), rve.num_dofs());
    M.setFromTriplets(trip.begin(), trip.end());
    H = Eigen::MatrixXd(M);
    omp_set_num_threads(before);
    return E;
  };
  Eigen::VectorXd g1, g2;
  Eigen::MatrixXd H1, H2;
  Strain d1, d2;
  const double E1 = run(1, g1, H1, d1), E2 = run(2, g2, H2, d2);
  EXPECT_NEAR(E2, E1, 1e-13 * E1);
  EXPECT_LT((g2 - g1).norm(), 1e-12 * g1.norm());
  EXPECT_LT((H2 - H1).norm(), 1e-12 * H1.norm());
  EXPECT_LT((d2 - d1).norm(), 1e-12 * d1.norm());
}
