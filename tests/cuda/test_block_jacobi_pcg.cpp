// The GPU twin of the block-Jacobi PCG (cuda/block_jacobi_pcg.cu) against the CPU twin
// (numerics/block_jacobi_pcg.hpp) on the same systems: the same iterations (to one), the same
// solution, bit-identical reruns, the same breakdown; and SparseCholesky's pcg-cuda kind through
// the registration sim/ does. Skips without a GPU.
#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <cstdlib>

#include "cuda/api.hpp"
#include "cuda/block_jacobi_pcg.hpp"
#include "numerics/block_jacobi_pcg.hpp"
#include "numerics/sparse_cholesky.hpp"
#include "tests/common/pcg_test_system.hpp"

using namespace yarnhom;

TEST(CudaBlockJacobiPcg, MatchesTheCpuTwin) {
  if (cuda::device_count() == 0) GTEST_SKIP() << "no CUDA GPU here (" << cuda::device_description() << ")";
  const Eigen::SparseMatrix<double> L = test::pcg_test_system(40, 0.01, 1.0);  // 4,800 unknowns
  numerics::BlockJacobiBuilder builder;
  numerics::BlockCsr A;
  ASSERT_TRUE(builder.build(L, A));
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.n, -1.0, 1.0).array().sin();
  auto dev = cuda::make_pcg_device();
  dev->upload(A);
  for (double tol : {1e-2, 1e-6, 1e-10}) {
    Eigen::VectorXd xc(A.n), xg(A.n), xg2(A.n);
    const numerics::BlockPcgResult rc = numerics::block_jacobi_pcg(A, b.data(), xc.data(), tol, 20000);
    const numerics::BlockPcgResult rg = dev->solve(b.data(), xg.data(), tol, 20000);
    const numerics::BlockPcgResult rg2 = dev->solve(b.data(), xg2.data(), tol, 20000);
    std::printf("tol %.0e: CPU %d iterations (residual %.3e), GPU %d (%.3e)\n", tol, rc.iterations,
                rc.relative_residual, rg.iterations, rg.relative_residual);
    EXPECT_TRUE(rc.converged && rg.converged);
    EXPECT_LE(std::abs(rc.iterations - rg.iterations), 1) << tol;
    EXPECT_LE(rg.relative_residual, tol);
    const Eigen::SparseMatrix<double> Af = L.selfadjointView<Eigen::Lower>();
    EXPECT_LE((b - Af * xg).norm() / b.norm(), tol * 1.001);
    if (rc.iterations == rg.iterations) EXPECT_LT((xc - xg).norm(), 1e-8 * xc.norm()) << tol;
    EXPECT_EQ(rg.iterations, rg2.iterations);
    EXPECT_EQ((xg - xg2).norm(), 0.0) << "reruns differ";
  }
  // New values on the same pattern.
  const Eigen::SparseMatrix<double> L2 = 3.0 * L;
  ASSERT_TRUE(builder.build(L2, A));
  dev->upload(A);
  Eigen::VectorXd xc(A.n), xg(A.n);
  numerics::block_jacobi_pcg(A, b.data(), xc.data(), 1e-10, 20000);
  dev->solve(b.data(), xg.data(), 1e-10, 20000);
  EXPECT_LT((xc - xg).norm(), 1e-8 * xc.norm());
}

TEST(CudaBlockJacobiPcg, StopsOnAnIndefiniteMatrixAsTheCpuTwinDoes) {
  if (cuda::device_count() == 0) GTEST_SKIP() << "no CUDA GPU here (" << cuda::device_description() << ")";
  Eigen::SparseMatrix<double> M = test::pcg_test_system(4, 0.01, 1.0);
  for (int k = 0; k < M.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(M, k); it; ++it)
      if (it.row() / 3 != it.col() / 3) it.valueRef() *= 8.0;
  numerics::BlockJacobiBuilder builder;
  numerics::BlockCsr A;
  ASSERT_TRUE(builder.build(M, A));
  Eigen::VectorXd b = Eigen::VectorXd::Ones(A.n), xc(A.n), xg(A.n);
  const numerics::BlockPcgResult rc = numerics::block_jacobi_pcg(A, b.data(), xc.data(), 1e-12, 1000);
  auto dev = cuda::make_pcg_device();
  dev->upload(A);
  const numerics::BlockPcgResult rg = dev->solve(b.data(), xg.data(), 1e-12, 1000);
  EXPECT_TRUE(rc.breakdown);
  EXPECT_TRUE(rg.breakdown);
  EXPECT_EQ(rc.iterations, rg.iterations);
}

TEST(CudaBlockJacobiPcg, SparseCholeskyRunsItAsPcgCuda) {
  if (cuda::device_count() == 0) GTEST_SKIP() << "no CUDA GPU here (" << cuda::device_description() << ")";
  numerics::register_pcg_device(&cuda::make_pcg_device);
  ASSERT_EQ(numerics::parse_solver_kind("pcg-cuda"), numerics::SolverKind::PcgCuda);
  const Eigen::SparseMatrix<double> L = test::pcg_test_system(10, 0.01, 1.0);
  numerics::SparseCholesky s(numerics::SolverKind::PcgCuda);
  s.set_iterative(1e-9, 5000);
  ASSERT_TRUE(s.factorize(L));
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(L.rows());
  const Eigen::VectorXd x = s.solve(b);
  const Eigen::SparseMatrix<double> Af = L.selfadjointView<Eigen::Lower>();
  EXPECT_LE((b - Af * x).norm() / b.norm(), 1e-9);
  EXPECT_EQ(s.solves(), 1);
  EXPECT_NE(std::string(s.name()).find("pcg-cuda"), std::string::npos);
}

// The system built on the device from the lower triangle (upload_triangle: the values scattered
// and the blocks inverted there, by the CPU builder's arithmetic) solves as the one built on
// the host and uploaded whole: the same iterations, the same solution to rounding; new values
// on the same pattern; a block that is not positive definite refused as the builder refuses it.
TEST(CudaBlockJacobiPcg, BuildsTheSystemFromTheTriangleAsTheHostDoes) {
  if (cuda::device_count() == 0) GTEST_SKIP() << "no CUDA GPU here (" << cuda::device_description() << ")";
  const Eigen::SparseMatrix<double> L = test::pcg_test_system(30, 0.01, 1.0);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(L.rows(), -1.0, 1.0).array().cos();
  numerics::BlockJacobiBuilder host_builder, pattern_builder;
  numerics::BlockCsr A, P;
  auto whole = cuda::make_pcg_device(), tri = cuda::make_pcg_device();
  for (double scale : {1.0, 2.5}) {
    const Eigen::SparseMatrix<double> Ls = scale * L;
    ASSERT_TRUE(host_builder.build(Ls, A));
    whole->upload(A);
    pattern_builder.build_pattern(Ls, P);
    ASSERT_TRUE(tri->upload_triangle(P, pattern_builder.map(), Ls.valuePtr(), int(Ls.nonZeros())));
    Eigen::VectorXd xw(A.n), xt(A.n);
    const numerics::BlockPcgResult rw = whole->solve(b.data(), xw.data(), 1e-8, 20000);
    const numerics::BlockPcgResult rt = tri->solve(b.data(), xt.data(), 1e-8, 20000);
    EXPECT_TRUE(rw.converged && rt.converged);
    EXPECT_LE(std::abs(rw.iterations - rt.iterations), 1) << scale;
    EXPECT_LT((xw - xt).norm(), 1e-6 * xw.norm()) << scale;
  }
  // A diagonal block that is not positive definite.
  Eigen::SparseMatrix<double> bad = L;
  bad.coeffRef(3, 3) = -1.0;
  numerics::BlockCsr Q;
  numerics::BlockJacobiBuilder qb;
  EXPECT_FALSE(qb.build(bad, Q));
  numerics::BlockJacobiBuilder qp;
  numerics::BlockCsr QP;
  qp.build_pattern(bad, QP);
  EXPECT_FALSE(tri->upload_triangle(QP, qp.map(), bad.valuePtr(), int(bad.nonZeros())));
}
