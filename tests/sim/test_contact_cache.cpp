// The step's contact broad phase and the Newton matrix's kept pattern (sim/contact_broad_phase.hpp,
// sim/contact_pattern.hpp): a ContactCache answers every query covered by its region with
// exactly the fresh broad phase's pairs in the same order (so the same pairs within d_hat, the same CCD bound),
// rebuilding only when a query leaves the region, and leaves out of its near and CCD lists only
// pairs whose barrier is zero and whose CCD gives t = 1 (the energy bit for bit); a
// PaddedPattern hands the solver the same matrix on a pattern that changes only when a coupling
// leaves it, and the solve agrees.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <random>
#include <tuple>

#include "numerics/contact_pairs.hpp"
#include "numerics/sparse_cholesky.hpp"
#include "sim/contact.hpp"
#include "sim/contact_pattern.hpp"
#include "sim/integrators.hpp"
#include "sim/rectangle.hpp"
#include "tests/common/sim_contact_checks.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;

namespace {

// Two 2 cm sheets 0.6 mm apart (d_hat 1 mm), the upper one shifted, and a capsule under them.
Problem two_sheets(Eigen::VectorXd& x, Eigen::VectorXd& y) {
  Problem P = test::two_sheets_over_a_capsule(6, 0.1, [](int v) { return Eigen::Vector3d(0.0013, 0.0021, 0.0006 + 0.0001 * (v % 3)); });
  x = flatten(P.mesh.x);
  y = obstacle_positions(P.obstacles, 0);
  return P;
}

using Key = std::tuple<int, int, int, int, int, double, double>;
// The pairs' keys in their order (the cache answers in the fresh broad phase's order).
std::vector<Key> keys(const std::vector<ContactPair>& pairs) {
  std::vector<Key> k;
  for (const ContactPair& c : pairs) k.emplace_back(int(c.kind), c.slot[0], c.slot[1], c.slot[2], c.slot[3], c.dmin, c.mu);
  return k;
}

// Pairs within their barrier's reach at (x, y).
int within_dhat(const Problem& P, const std::vector<ContactPair>& pairs, const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  int n = 0;
  for (const ContactPair& c : pairs) n += numerics::contact_distance(c.kind, pair_coordinates(c, x, y)) < c.dmin + P.dhat;
  return n;
}

}  // namespace

TEST(ContactCache, AnswersEveryCoveredQueryWithTheFreshBroadPhasesPairs) {
  Eigen::VectorXd x, y;
  const Problem P = two_sheets(x, y);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2e-3, 2e-3);  // 2 mm: farther than d_hat
  Eigen::VectorXd dx(x.size()), dy(y.size());
  for (Eigen::Index i = 0; i < dx.size(); ++i) dx[i] = u(rng);
  for (Eigen::Index i = 0; i < dy.size(); ++i) dy[i] = 0.3 * u(rng);
  ContactCache cache;
  // The step's pattern: a move first (the region over it), then static queries and sub-moves in it.
  const Eigen::VectorXd x1 = x + dx, y1 = y + dy;
  EXPECT_EQ(keys(cache.candidates(P, x, x1, y, y1)), keys(contact_candidates(P, x, x1, y, y1)));
  EXPECT_EQ(cache.builds(), 1);
  int close = 0;
  for (double a : {0.0, 0.25, 0.5, 1.0}) {
    const Eigen::VectorXd xa = x + a * dx, ya = y + a * dy;
    const std::vector<ContactPair> fresh = contact_candidates(P, xa, xa, ya, ya);
    const std::vector<ContactPair> cached = cache.candidates(P, xa, xa, ya, ya);
    EXPECT_EQ(keys(cached), keys(fresh)) << "static at " << a;
    EXPECT_EQ(within_dhat(P, cached, xa, ya), within_dhat(P, fresh, xa, ya));
    EXPECT_LT(fresh.size(), cache.region_pairs());  // the region holds more than one position needs
    close += within_dhat(P, fresh, xa, ya);
  }
  EXPECT_GT(close, 20);  // layers and capsule within reach: the comparison has pairs to lose
  const Eigen::VectorXd xa = x + 0.2 * dx, xb = x + 0.7 * dx, ya = y + 0.2 * dy, yb = y + 0.7 * dy;
  EXPECT_EQ(keys(cache.candidates(P, xa, xb, ya, yb)), keys(contact_candidates(P, xa, xb, ya, yb)));
  EXPECT_EQ(cache.builds(), 1);  // all of them served by the one hash
  // A CCD bound and an energy through the cache are the fresh ones (the energy bit for bit: the
  // same pairs in the same order).
  std::vector<int> free(P.mesh.num_vertices());
  for (int v = 0; v < int(free.size()); ++v) free[v] = v;
  EXPECT_EQ(contact_step_bound(P, xa, xb - xa, ya, yb - ya, nullptr, &cache),
            contact_step_bound(P, xa, xb - xa, ya, yb - ya));
  const double E = contact_energy(P, free, x, y);
  ASSERT_GT(E, 0);
  ASSERT_TRUE(std::isfinite(E));
  EXPECT_EQ(contact_energy(P, free, x, y, nullptr, nullptr, &cache), E);
  EXPECT_EQ(cache.builds(), 1);
  // A query beyond the region builds a new one, and is answered as freshly.
  const Eigen::VectorXd x2 = x + 2 * dx;
  EXPECT_EQ(keys(cache.candidates(P, x2, x2, y1, y1)), keys(contact_candidates(P, x2, x2, y1, y1)));
  EXPECT_EQ(cache.builds(), 2);
}

TEST(ContactCache, TheStepsShareOneCacheAndItsBoundsSpareDistances) {
  // The simulation carries its broad phase from step to step (ObstacleMotion::contact_cache):
  // the steps come out bit for bit as with a fresh cache each step, and a step's first region
  // takes the pairs' bounds from the last step's queries instead of computing every distance.
  Eigen::VectorXd x0, y;
  const Problem P = two_sheets(x0, y);
  const DofMap D = make_dof_map(P.mesh.num_vertices(), {});
  const HessianPattern pat = make_hessian_pattern(P.mesh, D);
  LinearSolver sa, sb;
  NewtonSettings opt;
  opt.tol_step = 1e-7;
  const double h = 1.0 / 60;
  ObstacleMotion carried;
  carried.y = carried.target = y;
  Eigen::VectorXd xa = x0, xb = x0, va = Eigen::VectorXd::Zero(x0.size()), vb = va;
  long fresh_distances = 0;
  for (int step = 0; step < 4; ++step) {
    ObstacleMotion fresh;
    fresh.y = fresh.target = y;
    ASSERT_TRUE(linearized_step(P, D, pat, sa, xa, va, xa, h, opt, false, nullptr, NAN, &carried).finite);
    ASSERT_TRUE(linearized_step(P, D, pat, sb, xb, vb, xb, h, opt, false, nullptr, NAN, &fresh).finite);
    ASSERT_TRUE(fresh.contact_cache);
    fresh_distances += fresh.contact_cache->distances();
    EXPECT_EQ(xa, xb) << "step " << step;  // the same pairs and sums: bit for bit
    EXPECT_EQ(va, vb) << "step " << step;
  }
  EXPECT_GT((xa - x0).cwiseAbs().maxCoeff(), 1e-4);  // the sheets moved: the regions changed
  ASSERT_TRUE(carried.contact_cache);
  std::printf("pair distances computed: %ld carried, %ld with a fresh cache each step\n", carried.contact_cache->distances(),
              fresh_distances);
  // (12 % fewer here, where the layers lie within reach; a garment's far pairs keep their bounds)
  EXPECT_LT(double(carried.contact_cache->distances()), 0.95 * double(fresh_distances));
}

namespace {
// Is `part` the list `all` with some pairs left out (order kept)?
bool is_subsequence(const std::vector<ContactPair>& part, const std::vector<ContactPair>& all) {
  size_t k = 0;
  for (const ContactPair& c : all)
    if (k < part.size() && c.kind == part[k].kind && c.slot == part[k].slot) ++k;
  return k == part.size();
}
}  // namespace

TEST(ContactCache, NearPairsLeaveOutOnlyPairsBeyondTheBarrierAndTheCcd) {
  Eigen::VectorXd x, y;
  const Problem P = two_sheets(x, y);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // A move of the whole scene by 3 mm (a translation: no pair's distance changes) plus 0.2 mm of
  // noise per point: the snapshot's bounds carry most pairs from query to query.
  Eigen::VectorXd dx(x.size()), dy(y.size());
  for (Eigen::Index i = 0; i < dx.size(); ++i) dx[i] = 3e-3 * (i % 3 == 0) + 2e-4 * u(rng);
  for (Eigen::Index i = 0; i < dy.size(); ++i) dy[i] = 3e-3 * (i % 3 == 0) + 2e-4 * u(rng);
  std::vector<int> free(P.mesh.num_vertices());
  for (int v = 0; v < int(free.size()); ++v) free[v] = v;
  ContactCache cache;
  const Eigen::VectorXd x1 = x + dx, y1 = y + dy;
  // The move's CCD first (it builds the region and computes every pair's distance once).
  std::vector<ContactHit> hits, hits_fresh;
  EXPECT_EQ(contact_step_bound(P, x, dx, y, dy, &hits, &cache), contact_step_bound(P, x, dx, y, dy, &hits_fresh));
  EXPECT_EQ(hits.size(), hits_fresh.size());
  EXPECT_EQ(cache.distances(), long(cache.region_pairs()));
  for (double a : {1.0, 0.75, 0.5, 0.25, 0.0}) {
    const Eigen::VectorXd xa = x + a * dx, ya = y + a * dy;
    const std::vector<ContactPair> all = cache.candidates(P, xa, xa, ya, ya);  // same region, same order
    const long before = cache.distances();
    const std::vector<ContactPair> near = cache.near(P, xa, ya);
    // Fewer distances than pairs: the bounds carried most of them (the 3 mm translation costs none).
    EXPECT_LT(cache.distances() - before, long(cache.region_pairs()) / 4) << a;
    EXPECT_TRUE(is_subsequence(near, all)) << a;
    EXPECT_LT(near.size(), all.size()) << a;
    EXPECT_EQ(within_dhat(P, near, xa, ya), within_dhat(P, all, xa, ya)) << a;
    EXPECT_GT(within_dhat(P, near, xa, ya), 10) << a;
    // Energy and gradient bit for bit those summed over all the region's candidates (in order).
    Eigen::VectorXd g1 = Eigen::VectorXd::Zero(x.size()), g2 = g1;
    const double E1 = contact_energy(P, free, xa, ya, &g1, nullptr, &cache);
    double E2 = 0;
    for (const ContactPair& c : cache.candidates(P, xa, xa, ya, ya)) {
      numerics::Vec12 g;
      const double e = numerics::contact_barrier_energy(c.kind, pair_coordinates(c, xa, ya), pair_barrier(P, c), &g);
      if (e == 0) continue;
      E2 += e;
      for (int k = 0; k < 4; ++k)
        if (c.slot[k] >= 0) g2.segment<3>(3 * c.slot[k]) += g.segment<3>(3 * k);
    }
    EXPECT_GT(E2, 0);
    EXPECT_EQ(E1, E2) << a;
    EXPECT_EQ((g1 - g2).cwiseAbs().maxCoeff(), 0.0) << a;
    // Sub-moves' CCD: the candidates left out give contact_ccd's t = 1, and the bound is the
    // full set's.
    const double b = a < 0.5 ? a + 0.3 : a - 0.3;  // within the region
    const Eigen::VectorXd xb = x + b * dx, yb = y + b * dy;
    const std::vector<ContactPair> ccd = cache.ccd_candidates(P, xa, xb, ya, yb);
    const std::vector<ContactPair> moved = cache.candidates(P, xa, xb, ya, yb);
    EXPECT_TRUE(is_subsequence(ccd, moved));
    EXPECT_LT(ccd.size(), moved.size());
    for (const ContactPair& c : moved) {
      const auto q0 = pair_coordinates(c, xa, ya), q1 = pair_coordinates(c, xb, yb);
      if (std::find_if(ccd.begin(), ccd.end(), [&](const ContactPair& d) { return d.slot == c.slot && d.kind == c.kind; }) !=
          ccd.end())
        continue;
      EXPECT_EQ(numerics::contact_ccd(c.kind, q0, q1, c.dmin, kContactEta).t, 1.0);
      if (c.slot[0] < 0 || c.slot[2] < 0 || c.slot[3] < 0 || c.slot[1] < 0) {
        EXPECT_EQ(numerics::contact_ccd(c.kind, q0, q1, c.dmin + kObstacleFloor * P.dhat, kContactEta).t, 1.0);
      }
    }
    EXPECT_EQ(contact_step_bound(P, xa, xb - xa, ya, yb - ya, nullptr, &cache),
              contact_step_bound(P, xa, xb - xa, ya, yb - ya));
  }
  EXPECT_EQ(cache.builds(), 1);
  // A query beyond the region rebuilds it and keeps the bounds of the pairs it had: fewer
  // distances than pairs (every one without them; the layers' close pairs are computed either
  // way), and the near list and energy still those of all the candidates.
  const Eigen::VectorXd x2 = x1 + 0.5 * dx, y2 = y1 + 0.5 * dy;
  const long before = cache.distances();
  const std::vector<ContactPair> near2 = cache.near(P, x2, y2);
  EXPECT_EQ(cache.builds(), 2);
  EXPECT_LT(cache.distances() - before, long(cache.region_pairs()) * 9 / 10);
  const std::vector<ContactPair> all2 = contact_candidates(P, x2, x2, y2, y2);
  EXPECT_TRUE(is_subsequence(near2, all2));
  EXPECT_EQ(within_dhat(P, near2, x2, y2), within_dhat(P, all2, x2, y2));
  EXPECT_GT(within_dhat(P, near2, x2, y2), 10);
  EXPECT_EQ(contact_energy(P, free, x2, y2, nullptr, nullptr, &cache), contact_energy(P, free, x2, y2));
}

TEST(ContactCache, PaddedPatternKeepsItsPatternWhileTheCouplingsStayWithinIt) {
  // A 6 x 6 SPD matrix (2 free vertices of 3 unknowns), lower triangle; couplings come and go.
  auto matrix = [](bool coupled, double c) {
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < 6; ++i) t.emplace_back(i, i, 4.0 + i);
    t.emplace_back(1, 0, 0.5);
    if (coupled) t.emplace_back(4, 1, c);
    Eigen::SparseMatrix<double> A(6, 6);
    A.setFromTriplets(t.begin(), t.end());
    return A;
  };
  PaddedPattern kept;
  int pads = 0;
  const PaddedPattern::Pad pad = [&] {
    ++pads;
    return std::vector<std::pair<int, int>>{{1, 0}};  // vertex 1 with vertex 0: the whole block
  };
  const Eigen::SparseMatrix<double> A1 = matrix(false, 0);
  const Eigen::SparseMatrix<double> M1 = kept.embed(A1, pad);
  EXPECT_EQ(kept.rebuilds(), 1);
  EXPECT_EQ(pads, 1);
  EXPECT_GT(M1.nonZeros(), A1.nonZeros());  // the pad's block is held, as explicit zeros
  EXPECT_EQ((Eigen::MatrixXd(M1) - Eigen::MatrixXd(A1)).norm(), 0.0);
  // A coupling inside the kept pattern: same pattern, A's values.
  const Eigen::SparseMatrix<double> A2 = matrix(true, 0.7);
  const Eigen::SparseMatrix<double> M2 = kept.embed(A2, pad);
  EXPECT_EQ(kept.rebuilds(), 1);
  EXPECT_TRUE(std::equal(M1.innerIndexPtr(), M1.innerIndexPtr() + M1.nonZeros(), M2.innerIndexPtr()));
  EXPECT_EQ((Eigen::MatrixXd(M2) - Eigen::MatrixXd(A2)).norm(), 0.0);
  // The solver sees one pattern: one analysis for both, and the solutions of A's own.
  numerics::SparseCholesky padded, plain;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(6, 1, 2);
  ASSERT_TRUE(padded.factorize(M1));
  ASSERT_TRUE(padded.factorize(M2));
  EXPECT_EQ(padded.analyses(), 1);
  ASSERT_TRUE(plain.factorize(A2));
  EXPECT_LT((padded.solve(b) - plain.solve(b)).norm(), 1e-12 * plain.solve(b).norm());
  // A coupling outside it (a new block column): rebuilt with the pad again.
  std::vector<Eigen::Triplet<double>> t = {{0, 0, 4}, {1, 1, 5}, {2, 2, 6}, {3, 3, 7}, {4, 4, 8}, {5, 5, 9}, {2, 1, 0.1}};
  Eigen::SparseMatrix<double> A3(6, 6);
  A3.setFromTriplets(t.begin(), t.end());
  const Eigen::SparseMatrix<double> M3 = kept.embed(A3, pad);
  EXPECT_EQ(kept.rebuilds(), 2);
  EXPECT_EQ(pads, 2);
  EXPECT_EQ((Eigen::MatrixXd(M3) - Eigen::MatrixXd(A3)).norm(), 0.0);
  EXPECT_EQ(kept.uses(), 3);
}

// embed_sum writes H + C straight into the kept pattern: the values of embed(H + C) bit for bit
// (on 1 and 3 threads, 3,600 columns: the threaded pass), and a C with a coupling outside the
// pattern rebuilds it as embed does.
TEST(ContactCache, PaddedPatternSumsIntoTheKeptPatternAsEmbedDoes) {
  const int n = 3600;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  std::vector<Eigen::Triplet<double>> th, tc;
  for (int i = 0; i < n; ++i) {
    th.emplace_back(i, i, 10 + U(rng));
    for (int k = 1; k <= 4 && i + k < n; ++k) th.emplace_back(i + k, i, U(rng));
  }
  for (int k = 0; k < 2000; ++k) {  // contact-like entries: on H's band and farther below it, some repeated
    const int j = int(rng() % (n - 40)), i = j + int(rng() % 40);
    tc.emplace_back(i, j, U(rng));
    if (k % 5 == 0) tc.emplace_back(i, j, U(rng));
  }
  Eigen::SparseMatrix<double> H(n, n), C(n, n);
  H.setFromTriplets(th.begin(), th.end());
  C.setFromTriplets(tc.begin(), tc.end());
  const PaddedPattern::Pad pad = [&] {
    std::vector<std::pair<int, int>> b;
    for (const auto& t : tc)
      if (t.row() / 3 > t.col() / 3) b.emplace_back(t.row() / 3, t.col() / 3);
    return b;
  };
  const Eigen::SparseMatrix<double> sum = Eigen::SparseMatrix<double>(H + C);
  PaddedPattern kept, ref;
  kept.embed(sum, pad);
  const Eigen::SparseMatrix<double> R = ref.embed(sum, pad);
  const int saved = omp_get_max_threads();
  for (int threads : {1, 3}) {
    omp_set_num_threads(threads);
    const Eigen::SparseMatrix<double> M = kept.embed_sum(H, C, pad);
    omp_set_num_threads(saved);
    EXPECT_EQ(kept.rebuilds(), 1);
    ASSERT_EQ(M.nonZeros(), R.nonZeros());
    EXPECT_TRUE(std::equal(M.innerIndexPtr(), M.innerIndexPtr() + M.nonZeros(), R.innerIndexPtr()));
    EXPECT_TRUE(std::equal(M.valuePtr(), M.valuePtr() + M.nonZeros(), R.valuePtr())) << threads;
  }
  // A coupling outside the kept pattern: rebuilt, the values H + C's.
  tc.emplace_back(n - 1, 0, 0.25);
  C.setFromTriplets(tc.begin(), tc.end());
  const Eigen::SparseMatrix<double> M = kept.embed_sum(H, C, pad);
  EXPECT_EQ(kept.rebuilds(), 2);
  EXPECT_EQ(M.coeff(n - 1, 0), 0.25);
  EXPECT_EQ((Eigen::SparseMatrix<double>(M - Eigen::SparseMatrix<double>(H + C))).coeffs().cwiseAbs().maxCoeff(), 0.0);
}

// A rebuilt pattern is exactly the union of the matrix's entries and the pad's full 3 x 3 blocks
// below the diagonal (repeated blocks once, blocks on or above it ignored), the same on 1 and 3
// threads: the pattern a setFromTriplets of both gives.
TEST(ContactCache, PaddedPatternRebuildHoldsTheUnionOfTheMatrixAndThePad) {
  const int n = 3600;  // 1,200 blocks: the threaded pass
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  std::vector<Eigen::Triplet<double>> th;
  for (int i = 0; i < n; ++i) {
    th.emplace_back(i, i, 10 + U(rng));
    for (int k = 1; k <= 5 && i + k < n; ++k) th.emplace_back(i + k, i, U(rng));
  }
  Eigen::SparseMatrix<double> H(n, n);
  H.setFromTriplets(th.begin(), th.end());
  std::vector<std::pair<int, int>> blocks;
  for (int k = 0; k < 3000; ++k) {
    const int fb = int(rng() % (n / 3 - 30)), fa = fb + 1 + int(rng() % 29);
    blocks.emplace_back(fa, fb);
    if (k % 7 == 0) blocks.emplace_back(fa, fb);  // repeated
    if (k % 11 == 0) blocks.emplace_back(fb, fa);  // above the diagonal: not held
  }
  blocks.emplace_back(4, 4);  // on it: not held
  std::vector<Eigen::Triplet<double>> ref = th;
  for (const auto& [fa, fb] : blocks)
    if (fa > fb)
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) ref.emplace_back(3 * fa + r, 3 * fb + c, 0.0);
  Eigen::SparseMatrix<double> R(n, n);
  R.setFromTriplets(ref.begin(), ref.end());
  R.makeCompressed();
  const int saved = omp_get_max_threads();
  for (int threads : {1, 3}) {
    omp_set_num_threads(threads);
    PaddedPattern kept;
    const Eigen::SparseMatrix<double> M = kept.embed(H, [&] { return blocks; });
    omp_set_num_threads(saved);
    EXPECT_EQ(kept.rebuilds(), 1);
    ASSERT_EQ(M.nonZeros(), R.nonZeros()) << threads;
    EXPECT_TRUE(std::equal(M.outerIndexPtr(), M.outerIndexPtr() + n + 1, R.outerIndexPtr()));
    EXPECT_TRUE(std::equal(M.innerIndexPtr(), M.innerIndexPtr() + M.nonZeros(), R.innerIndexPtr()));
    EXPECT_EQ((Eigen::SparseMatrix<double>(M - H)).coeffs().cwiseAbs().maxCoeff(), 0.0);  // H's values, zeros elsewhere
  }
}

// The pair terms (barrier and lagged friction) are evaluated on the OpenMP threads in fixed
// chunks and summed in the pairs' order: energy, gradient and Hessian triplets the same on 1 and
// 3 threads, bit for bit, with hundreds of pairs in reach (the threaded pass).
TEST(ContactCache, PairTermsAreTheSameOnAnyThreadCount) {
  Problem P = test::two_sheets_over_a_capsule(24, 0.3, [](int v) { return Eigen::Vector3d(0.0004, 0.0003, 0.0006 + 0.0001 * (v % 3)); });
  const Eigen::VectorXd x = flatten(P.mesh.x), y = obstacle_positions(P.obstacles, 0);
  std::vector<int> free(P.mesh.num_vertices());
  for (int v = 0; v < int(free.size()); ++v) free[v] = v;
  const std::vector<PairFriction> F = pair_friction_contacts(P, x, y, x, y, nullptr);
  ASSERT_GT(F.size(), 300u);
  Eigen::VectorXd xs = x;  // a slip of the upper sheet
  for (Eigen::Index i = 0; i < xs.size(); i += 3) xs[i] += 1e-5 * std::sin(0.1 * double(i));
  using Result = std::tuple<double, Eigen::VectorXd, std::vector<std::tuple<int, int, double>>>;
  auto run = [&](bool friction) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
    std::vector<Eigen::Triplet<double>> t;
    const double E = friction ? pair_friction_energy(F, 1e-6, free, xs, y, &g, &t) : contact_energy(P, free, x, y, &g, &t);
    std::vector<std::tuple<int, int, double>> tt;
    for (const auto& e : t) tt.emplace_back(e.row(), e.col(), e.value());
    return Result{E, g, tt};
  };
  const int saved = omp_get_max_threads();
  for (bool friction : {false, true}) {
    omp_set_num_threads(1);
    const Result one = run(friction);
    omp_set_num_threads(3);
    const Result three = run(friction);
    omp_set_num_threads(saved);
    EXPECT_GT(std::get<0>(one), 0.0);
    EXPECT_EQ(std::get<0>(one), std::get<0>(three)) << friction;
    EXPECT_EQ(std::get<1>(one), std::get<1>(three)) << friction;
    EXPECT_GT(std::get<2>(one).size(), 1000u);
    EXPECT_EQ(std::get<2>(one), std::get<2>(three)) << friction;
  }
}

// A rebuild with a pad of many blocks (200,000 of them, duplicates and blocks already in A among
// them, the (-1, -1) places a pair of held points leaves): the pad's blocks are sorted on the
// threads from 65,536 on (sim/contact_pattern.cpp); the pattern is the union of A's and the
// pad's full 3 x 3 blocks exactly, on 1 thread as on 3.
TEST(ContactCache, PaddedPatternOfAManyBlockPadIsTheUnionOnAnyThreadCount) {
  const int nv = 1200, n = 3 * nv;
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, 1.0);
  for (int v = 1; v < nv; ++v) t.emplace_back(3 * v, 3 * (v - 1), 0.5);
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> vert(0, nv - 1);
  std::vector<std::pair<int, int>> blocks;
  for (int k = 0; k < 200000; ++k) {
    const int a = vert(rng), b = std::max(0, a - 1 - vert(rng) % 40);
    blocks.emplace_back(k % 50 == 0 ? -1 : a, k % 50 == 0 ? -1 : b);
  }
  const PaddedPattern::Pad pad = [&] { return blocks; };
  // The expected pattern: A's entries, and for every pad block fa > fb its 3 x 3 entries.
  std::vector<std::vector<int>> rows(n);
  for (int j = 0; j < A.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it) rows[size_t(j)].push_back(int(it.row()));
  for (const auto& [fa, fb] : blocks)
    if (fa > fb && fb >= 0)
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) rows[size_t(3 * fb + c)].push_back(3 * fa + r);
  for (auto& r : rows) {
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
  }
  const int saved = omp_get_max_threads();
  std::vector<Eigen::SparseMatrix<double>> got;
  for (int threads : {1, 3}) {
    omp_set_num_threads(threads);
    PaddedPattern kept;
    got.push_back(kept.embed(A, pad));
    omp_set_num_threads(saved);
  }
  for (const auto& M : got) {
    ASSERT_EQ(M.outerSize(), n);
    for (int j = 0; j < n; ++j) {
      const std::vector<int> col(M.innerIndexPtr() + M.outerIndexPtr()[j], M.innerIndexPtr() + M.outerIndexPtr()[j + 1]);
      ASSERT_EQ(col, rows[size_t(j)]) << "column " << j;
    }
    EXPECT_EQ(Eigen::SparseMatrix<double>(M - A).norm(), 0.0);  // A's values, zeros elsewhere
  }
}
