// Block-Jacobi preconditioned CG (numerics/block_jacobi_pcg.hpp), the CPU twin: the whole matrix
// and the block inverses built from one triangle, convergence to the tolerance and to the
// Cholesky solution, descent at a loose tolerance, refusal of a block that is not positive
// definite, breakdown on an indefinite matrix, and the solver kind SparseCholesky runs it as.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <omp.h>

#include <random>
#include <vector>

#include "numerics/block_jacobi_pcg.hpp"
#include "numerics/sparse_cholesky.hpp"
#include "tests/common/pcg_test_system.hpp"

using namespace yarnhom::numerics;
using yarnhom::test::pcg_test_system;

TEST(BlockJacobiPcg, BuildsTheWholeMatrixAndItsBlockInversesFromOneTriangle) {
  const Eigen::SparseMatrix<double> L = pcg_test_system(6, 0.01, 1.0);
  const Eigen::MatrixXd Ad = Eigen::MatrixXd(Eigen::SparseMatrix<double>(L.selfadjointView<Eigen::Lower>()));
  BlockJacobiBuilder builder;
  BlockCsr A;
  ASSERT_TRUE(builder.build(L, A));
  ASSERT_EQ(A.n, L.rows());
  Eigen::MatrixXd Bd = Eigen::MatrixXd::Zero(A.n, A.n);
  for (int r = 0; r < A.n; ++r)
    for (int k = A.row_ptr[r]; k < A.row_ptr[r + 1]; ++k) Bd(r, A.col[k]) += A.val[k];
  EXPECT_LT((Bd - Ad).norm(), 1e-14 * Ad.norm());
  for (int b = 0; b < A.n / 3; ++b) {
    const Eigen::Matrix3d Bi = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&A.block_inv[9 * b]);
    EXPECT_LT((Bi * Ad.block<3, 3>(3 * b, 3 * b) - Eigen::Matrix3d::Identity()).norm(), 1e-12) << "block " << b;
  }
  // The same pattern with new values: the kept map puts them in place.
  const Eigen::SparseMatrix<double> L2 = 2.5 * L;
  BlockCsr A2 = A;
  ASSERT_TRUE(builder.build(L2, A2));
  EXPECT_EQ(A2.col, A.col);
  for (size_t k = 0; k < A.val.size(); ++k) EXPECT_DOUBLE_EQ(A2.val[k], 2.5 * A.val[k]);
}

TEST(BlockJacobiPcg, SolvesToTheToleranceAndAgreesWithCholesky) {
  const Eigen::SparseMatrix<double> L = pcg_test_system(12, 0.01, 1.0);
  const Eigen::SparseMatrix<double> Afull = L.selfadjointView<Eigen::Lower>();
  std::mt19937 rng(3);
  std::normal_distribution<double> nd;
  Eigen::VectorXd b(L.rows());
  for (int i = 0; i < b.size(); ++i) b[i] = nd(rng);
  SparseCholesky chol(SolverKind::Ldlt);
  ASSERT_TRUE(chol.factorize(L));
  const Eigen::VectorXd xs = chol.solve(b);
  BlockJacobiBuilder builder;
  BlockCsr A;
  ASSERT_TRUE(builder.build(L, A));
  Eigen::VectorXd x(b.size());
  const BlockPcgResult tight = block_jacobi_pcg(A, b.data(), x.data(), 1e-11, 5000);
  EXPECT_TRUE(tight.converged);
  EXPECT_FALSE(tight.breakdown);
  EXPECT_GT(tight.iterations, 5);  // not a trivial system
  EXPECT_LE((b - Afull * x).norm() / b.norm(), 1e-11 * 1.0001);
  EXPECT_NEAR(tight.relative_residual, (b - Afull * x).norm() / b.norm(), 1e-12);
  EXPECT_LT((x - xs).norm() / xs.norm(), 1e-8);
  // Loose: stops early, within its tolerance, and is a descent direction of the quadratic model
  // q(x) = 1/2 x.A x - b.x that takes most of the exact step's decrease.
  const BlockPcgResult loose = block_jacobi_pcg(A, b.data(), x.data(), 1e-2, 5000);
  EXPECT_TRUE(loose.converged);
  EXPECT_LT(loose.iterations, tight.iterations);
  EXPECT_LE((b - Afull * x).norm() / b.norm(), 1e-2);
  const double q = 0.5 * x.dot(Afull * x) - b.dot(x), qs = -0.5 * b.dot(xs);
  EXPECT_LT(q, 0.0);
  EXPECT_GT(q / qs, 0.99);
  // The iteration cap is respected.
  const BlockPcgResult capped = block_jacobi_pcg(A, b.data(), x.data(), 1e-11, 3);
  EXPECT_EQ(capped.iterations, 3);
  EXPECT_FALSE(capped.converged);
}

TEST(BlockJacobiPcg, RefusesABlockThatIsNotPositiveDefiniteAndStopsOnAnIndefiniteMatrix) {
  Eigen::SparseMatrix<double> L = pcg_test_system(4, 0.01, 1.0);
  BlockJacobiBuilder builder;
  BlockCsr A;
  L.coeffRef(4, 4) = -1.0;  // vertex 1's block
  EXPECT_FALSE(builder.build(L, A));
  SparseCholesky pcg(SolverKind::Pcg);
  EXPECT_FALSE(pcg.factorize(L));
  // Positive definite blocks, strong negative couplings: indefinite; CG stops where p.A p <= 0.
  Eigen::SparseMatrix<double> M = pcg_test_system(4, 0.01, 1.0);
  for (int k = 0; k < M.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(M, k); it; ++it)
      if (it.row() / 3 != it.col() / 3) it.valueRef() *= 8.0;
  ASSERT_TRUE(builder.build(M, A));
  Eigen::VectorXd b = Eigen::VectorXd::Ones(M.rows()), x(M.rows());
  const BlockPcgResult r = block_jacobi_pcg(A, b.data(), x.data(), 1e-12, 1000);
  EXPECT_TRUE(r.breakdown);
  EXPECT_FALSE(r.converged);
}

TEST(BlockJacobiPcg, SparseCholeskyRunsItAsTheIterativeKind) {
  const Eigen::SparseMatrix<double> L = pcg_test_system(8, 0.01, 1.0);
  const Eigen::SparseMatrix<double> Afull = L.selfadjointView<Eigen::Lower>();
  EXPECT_EQ(parse_solver_kind("pcg"), SolverKind::Pcg);
  // solver_kind_name is parse_solver_kind's inverse; Auto is named by what it runs.
  for (SolverKind k : {SolverKind::Ldlt, SolverKind::Pcg}) EXPECT_EQ(parse_solver_kind(solver_kind_name(k)), k);
  EXPECT_STREQ(solver_kind_name(SolverKind::PcgCuda), "pcg-cuda");
  EXPECT_STREQ(solver_kind_name(SolverKind::Auto), cholmod_available() ? "cholmod" : "ldlt");
  if (!pcg_device_factory()) {
    try {
      parse_solver_kind("pcg-cuda");
      ADD_FAILURE() << "pcg-cuda accepted without a GPU twin";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("CUDA"), std::string::npos) << e.what();
    }
  }
  SparseCholesky s(SolverKind::Pcg);
  s.set_iterative(1e-9, 1000);
  ASSERT_TRUE(s.factorize(L));
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(L.rows(), -1.0, 2.0);
  const Eigen::VectorXd x = s.solve(b);
  EXPECT_LE((b - Afull * x).norm() / b.norm(), 1e-9);
  const Eigen::VectorXd x2 = s.solve(2 * b);
  EXPECT_LT((x2 - 2 * x).norm(), 1e-6 * x.norm());
  EXPECT_EQ(s.solves(), 2);
  EXPECT_GT(s.iterations(), 2 * 5);
  EXPECT_EQ(s.factor_nonzeros(), 0.0);
  EXPECT_STREQ(s.name(), "pcg (block Jacobi, CPU)");
}

// Above 200,000 entries the builder scatters them on the threads: the same whole matrix and block
// inverses on 1 and 3 threads, bit for bit.
TEST(BlockJacobiPcg, BuildsTheSameSystemOnAnyThreadCount) {
  const Eigen::SparseMatrix<double> L = pcg_test_system(80, 0.01, 1.0);
  ASSERT_GT(L.nonZeros(), 200000);
  const int saved = omp_get_max_threads();
  std::vector<BlockCsr> built;
  std::vector<TriangleMap> maps;
  for (int threads : {1, 3, 4}) {
    omp_set_num_threads(threads);
    BlockJacobiBuilder builder;
    BlockCsr A;
    EXPECT_TRUE(builder.build(L, A));
    built.push_back(A);
    maps.push_back(builder.map());
  }
  omp_set_num_threads(saved);
  for (size_t t = 1; t < built.size(); ++t) {
    EXPECT_EQ(built[0].row_ptr, built[t].row_ptr);
    EXPECT_EQ(built[0].col, built[t].col);
    EXPECT_EQ(maps[0].pos, maps[t].pos);
    EXPECT_EQ(maps[0].mirror, maps[t].mirror);
    EXPECT_EQ(maps[0].diag, maps[t].diag);
  }
  // The pattern is the whole matrix's, each row's columns ascending (the row-major matrix's).
  const Eigen::SparseMatrix<double, Eigen::RowMajor> full(L.selfadjointView<Eigen::Lower>());
  ASSERT_EQ(built[0].row_ptr.size(), size_t(full.rows()) + 1);
  for (Eigen::Index r = 0; r <= full.rows(); ++r) ASSERT_EQ(built[0].row_ptr[size_t(r)], full.outerIndexPtr()[r]);
  for (Eigen::Index k = 0; k < full.nonZeros(); ++k) ASSERT_EQ(built[0].col[size_t(k)], full.innerIndexPtr()[k]);
  EXPECT_EQ(built[0].col, built[1].col);
  EXPECT_EQ(built[0].val, built[1].val);
  EXPECT_EQ(built[0].block_inv, built[1].block_inv);
  // and the one-thread build is the matrix: each row's entries sum to A's row sums
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(L.rows());
  const Eigen::VectorXd rows = L.selfadjointView<Eigen::Lower>() * ones;
  double err = 0;
  for (int r = 0; r < built[0].n; ++r) {
    double s = 0;
    for (int k = built[0].row_ptr[r]; k < built[0].row_ptr[r + 1]; ++k) s += built[0].val[k];
    err = std::max(err, std::abs(s - rows[r]));
  }
  EXPECT_LT(err, 1e-12 * rows.cwiseAbs().maxCoeff());
}

// The pattern's identity: kept while the pattern stays (values rebuilt, with or without the
// caller's word that it stays), a new one when it changes or when the system given is not the
// one the builder wrote last, never 0 once built; build_pattern writes the same pattern and a
// map that puts every entry where build puts it.
TEST(BlockJacobiPcg, KeepsThePatternIdWhileThePatternStays) {
  const Eigen::SparseMatrix<double> L = pcg_test_system(6, 0.01, 1.0);
  BlockJacobiBuilder builder;
  BlockCsr A;
  ASSERT_TRUE(builder.build(L, A));
  const uint64_t id = A.pattern_id;
  EXPECT_NE(id, 0u);
  ASSERT_TRUE(builder.build(Eigen::SparseMatrix<double>(3.0 * L), A, true));
  EXPECT_EQ(A.pattern_id, id);
  ASSERT_TRUE(builder.build(Eigen::SparseMatrix<double>(2.0 * L), A));
  EXPECT_EQ(A.pattern_id, id);
  BlockCsr fresh;
  ASSERT_TRUE(builder.build(L, fresh, true));  // an empty system is built whatever the caller says
  EXPECT_NE(fresh.pattern_id, 0u);
  EXPECT_NE(fresh.pattern_id, id);
  for (size_t k = 0; k < A.val.size(); ++k) EXPECT_EQ(A.val[k], 2.0 * fresh.val[k]);
  const Eigen::SparseMatrix<double> other = pcg_test_system(7, 0.01, 1.0);
  ASSERT_TRUE(builder.build(other, fresh));
  EXPECT_NE(fresh.pattern_id, id);
  // The pattern alone, and the map: entry k at pos[k] (and mirror[k]) of build's val.
  BlockJacobiBuilder pb;
  BlockCsr P;
  pb.build_pattern(L, P);
  EXPECT_NE(P.pattern_id, 0u);
  EXPECT_EQ(P.row_ptr, A.row_ptr);
  EXPECT_EQ(P.col, A.col);
  EXPECT_TRUE(P.val.empty());
  const TriangleMap& m = pb.map();
  ASSERT_EQ(m.pos.size(), size_t(L.nonZeros()));
  int diag = 0;
  for (int k = 0; k < int(L.nonZeros()); ++k) {
    EXPECT_EQ(2.0 * L.valuePtr()[k], A.val[size_t(m.pos[size_t(k)])]);
    if (m.mirror[size_t(k)] >= 0) {
      EXPECT_EQ(2.0 * L.valuePtr()[k], A.val[size_t(m.mirror[size_t(k)])]);
    }
    diag += m.diag[size_t(k)] >= 0;
  }
  EXPECT_EQ(diag, 6 * A.n / 3);  // each 3 x 3 diagonal block's lower triangle
}
