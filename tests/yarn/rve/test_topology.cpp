// Topology-preserving solves (docs/rve.md sections 3 and 5) on a two-yarn scene built for it:
// the barrier's place in the RVE energy (exact gradient and Hessian), a Newton step that would
// pass one yarn through the other unfiltered, the collision filter that keeps them apart, and
// the certificate that tells the two apart, from the solver and from a recorded path.
#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <filesystem>

#include "tests/common/yarn_support.hpp"
#include "yarn/rve/energy_density.hpp"
#include "yarn/rve/rve_ccd.hpp"
#include "yarn/rve/state_io.hpp"

using namespace yarnhom::yarn;
using yarnhom::yarn::testing::rel_err;

namespace {

constexpr int kM = 8;          // vertices per yarn
constexpr double kR = 1e-4;    // yarn radius (m)

// Two periodic yarns in a square tile: B along y at z = +4r, except that its two vertices
// next to the crossing dip to z = `dip`, below A, which runs along x at z = 0. B's rest
// lengths are those of a straight yarn, so B's stretching and bending pull the dip up: from
// below A, that is through A. B is yarn 0 (its first vertex, far from the crossing, is pinned
// in full), A may translate (only its sliding along itself is pinned): A can get out of the
// way upwards, B cannot get out of the way downwards. The start is contact-free (every pair
// more than 2r apart). With these proportions (segments of 3r, B 4r above and the dip 4r
// below A) the first Newton steps carry the dip through A unless they are filtered.
Pattern crossing_yarns(double dip = -4 * kR) {
  Pattern p;
  p.name = "two_crossing_yarns";
  p.radius = kR;
  p.px = p.py = kM * 3 * kR;  // segments of 3r
  for (int j = 0; j < kM; ++j)
    p.x.emplace_back(0.5 * p.px, (j + 0.5) * p.py / kM, (j == kM / 2 - 1 || j == kM / 2) ? dip : 4 * kR);
  for (int i = 0; i < kM; ++i) p.x.emplace_back((i + 0.5) * p.px / kM, 0.5 * p.py, 0.0);
  for (int j = 0; j < kM; ++j) p.edges.push_back({j, (j + 1) % kM, 0, j + 1 == kM ? 1 : 0});
  for (int i = 0; i < kM; ++i) p.edges.push_back({kM + i, kM + (i + 1) % kM, i + 1 == kM ? 1 : 0, 0});
  p.theta.assign(2 * kM, 0.0);
  complete_rest_state(p);
  for (int j = 0; j < kM; ++j) p.rest_length[j] = p.py / kM;  // straight B at rest
  return p;
}

// The scene's proportions were set with these yarn constants (contact stiffness equal to
// Young's modulus); the calibrated default's contact is 10x stiffer relative to the yarn and
// pushes the dip back before a Newton step can carry it through.
const Material& scene_material() {
  static const Material m = load_material("yarnhom-2025");
  return m;
}

// Height of B's dip minus A's height at the crossing: negative while B is still below A.
double dip_below(const RveProblem& rve, const Strain& s, const RveState& st) {
  const auto x = rve.positions(s, st);
  const double zb = 0.5 * (x[kM / 2 - 1][2] + x[kM / 2][2]);
  const double za = 0.5 * (x[kM + kM / 2 - 1][2] + x[kM + kM / 2][2]);
  return zb - za;
}

}  // namespace

TEST(Topology, SceneStartsApartAndBarrierIsInactive) {
  const RveProblem rve(crossing_yarns(), scene_material());
  const RveState st = rve.initial_state();
  EXPECT_TRUE(st.certificate.valid);
  EXPECT_GT(min_separation(rve, Strain::Zero(), st, 10 * kR), 2 * kR);
  EnergyParts parts;
  rve.evaluate(Strain::Zero(), st, nullptr, nullptr, &parts);
  EXPECT_EQ(parts.contact, 0.0);
  EXPECT_EQ(parts.barrier, 0.0);
  EXPECT_GT(parts.stretch, 0.0) << "B's dip is stretched: the scene has somewhere to go";
}

TEST(Topology, RveEnergyWithTheBarrierHasExactGradientAndHessian) {
  // B's dip 0.35 x 2r below A: inside the barrier's reach (0.25 to 0.5 x 2r).
  const RveProblem rve(crossing_yarns(-0.7 * kR), scene_material());
  const RveState st = rve.initial_state();
  for (const Strain& s : {Strain(Strain::Zero()), Strain((Strain() << 0.1, 0.05, -0.05, 300, 100, -200).finished())}) {
    EnergyParts parts;
    Eigen::VectorXd g;
    std::vector<Eigen::Triplet<double>> trip;
    rve.evaluate(s, st, &g, &trip, &parts);
    ASSERT_GT(parts.barrier, 0.0) << "the test needs an active barrier";
    ASSERT_GT(parts.barrier, 0.1 * parts.contact) << "and one that matters";
    const int N = rve.num_dofs();
    Eigen::SparseMatrix<double> Hs(N, N);
    Hs.setFromTriplets(trip.begin(), trip.end());
    const Eigen::MatrixXd H = Eigen::MatrixXd(Eigen::SparseMatrix<double>(Hs.selfadjointView<Eigen::Lower>()));
    Eigen::VectorXd gfd(N);
    Eigen::MatrixXd Hfd(N, N);
    for (int i = 0; i < N; ++i) {
      const double h = rve.force_scale()[i] == 1.0 ? 1e-10 : 1e-6;
      Eigen::VectorXd e = Eigen::VectorXd::Zero(N);
      e[i] = 1;
      RveState p = st, m = st;
      rve.apply_step(e, h, p);
      rve.apply_step(e, -h, m);
      Eigen::VectorXd gp, gm;
      gfd[i] = (rve.evaluate(s, p, &gp) - rve.evaluate(s, m, &gm)) / (2 * h);
      Hfd.col(i) = (gp - gm) / (2 * h);
    }
    EXPECT_LT(rel_err(g, gfd), 1e-6);
    EXPECT_LT(rel_err(H, Hfd), 1e-5);
  }
}

TEST(Topology, UnfilteredNewtonPassesAYarnThroughTheOtherAndTheCertificateSaysSo) {
  const RveProblem rve(crossing_yarns(), scene_material());
  const Strain s = Strain::Zero();
  RveState st = rve.initial_state(true);
  ASSERT_LT(dip_below(rve, s, st), 0);
  SolveOptions opt;
  opt.ccd = false;
  const SolveReport rep = solve(rve, s, st, opt);
  ASSERT_TRUE(rep.converged()) << rep.summary();
  // B's dip ended above A: it went through (the energy is then that of two straight yarns).
  EXPECT_GT(dip_below(rve, s, st), 0);
  EXPECT_FALSE(st.certificate.valid);
  EXPECT_NE(st.certificate.failure.find("Newton step"), std::string::npos) << st.certificate.failure;
  // The recorded path, re-checked from scratch, is refused too.
  EXPECT_FALSE(certify_path(rve, st.path, rve.min_separation()).valid);
}

TEST(Topology, FilteredNewtonKeepsTheYarnsApart) {
  const RveProblem rve(crossing_yarns(), scene_material());
  const Strain s = Strain::Zero();
  RveState st = rve.initial_state(true);
  const SolveReport rep = solve(rve, s, st);
  ASSERT_TRUE(rep.converged()) << rep.summary();
  EXPECT_GT(rep.ccd_limited, 0) << "the filter had to act";
  EXPECT_LT(dip_below(rve, s, st), -rve.min_separation()) << "B is still below A";
  EXPECT_TRUE(st.certificate.valid) << st.certificate.failure;
  EXPECT_GT(st.certificate.min_distance, rve.min_separation());
  EXPECT_GT(min_separation(rve, s, st, 10 * kR), rve.min_separation());
  const ContactCertificate c = certify_path(rve, st.path, rve.min_separation());
  EXPECT_TRUE(c.valid) << c.failure;
  EXPECT_EQ(c.moves + 1, static_cast<int>(st.path.size()));
}

TEST(Topology, CertificateRejectsAForcedCrossingAndSurvivesTheStateFile) {
  const RveProblem rve(crossing_yarns(), scene_material());
  const Strain s = Strain::Zero();
  // Forced: B's dip moved straight up to z = +3r, through A, in one move.
  RveState st = rve.initial_state(true);
  st.u[kM / 2 - 1] = st.u[kM / 2] = Eigen::Vector3d(0, 0, 8 * kR);
  st.path.push_back({s, st.u});
  const ContactCertificate forced = certify_path(rve, st.path, rve.min_separation());
  EXPECT_FALSE(forced.valid);
  EXPECT_GT(min_separation(rve, s, st, 10 * kR), rve.min_separation()) << "the end state alone looks fine";
  // The solver does not start from it: the move from its anchor (the original geometry) is
  // checked first, and the solve starts from the anchor's configuration instead.
  RveState again = rve.initial_state();
  again.u = st.u;
  const SolveReport rep = solve(rve, s, again);
  EXPECT_TRUE(rep.start_reset);
  EXPECT_LT(dip_below(rve, s, again), 0);
  // A strain step that would squeeze B onto its own image (s_x = -0.99: images 0.12 x 2r
  // apart) cannot start at all; the state is left as it was.
  RveState squeezed = rve.initial_state();
  Strain sq = Strain::Zero();
  sq[0] = -0.99;
  EXPECT_EQ(solve(rve, sq, squeezed).status, SolveStatus::kInfeasibleStart);
  EXPECT_TRUE(squeezed.anchor.s.isZero());
  // Round trip through a state file: the certified solution's path re-checks as valid.
  RveState good = rve.initial_state(true);
  const DensityResult r = energy_density(rve, s, good);
  ASSERT_TRUE(r.report.converged());
  const std::string file = (std::filesystem::temp_directory_path() / "yarnhom_test_topology_state.h5").string();
  write_state(file, rve, s, good, r);
  const RveState back = read_state(file, rve);
  std::filesystem::remove(file);
  EXPECT_TRUE(back.certificate.valid);
  EXPECT_EQ(back.path.size(), good.path.size());
  EXPECT_TRUE(certify_path(rve, back.path, rve.min_separation()).valid);
  EXPECT_EQ(back.anchor.u, good.u);
}
