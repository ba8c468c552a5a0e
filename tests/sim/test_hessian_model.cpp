// The Split model of the element Hessians (sim/hessian_model.hpp): positive semi-definite on a
// compressed, bent, shearing sheet where the exact Hessian is indefinite; equal to the exact
// Hessian (itself checked against finite differences in test_energy.cpp) where the material's
// d2Psi/ds2 and the in-plane curvature term are PSD and no bending moment acts: a flat sheet
// under uniform biaxial tension, rotated rigidly in space. And the in-plane term alone: its
// (f1, f2) projection leaves a PSD term unchanged and makes a compressed one PSD.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <random>

#include "sim/dof_map.hpp"
#include "sim/hessian_pattern.hpp"
#include "sim/inplane_strain.hpp"
#include "sim/rectangle.hpp"
#include "sim/shell_energy.hpp"
#include "tests/common/poly_material.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

const MaterialFn& material() {
  static const MaterialFn m = test::poly_material_fn(test::simple_cloth_terms());
  return m;
}

MatrixXd dense_hessian(const Mesh& m, const VectorXd& x, HessianModel model) {
  const auto rest = make_element_rests(m);
  const DofMap D = make_dof_map(m.num_vertices(), {});
  const HessianPattern pat = make_hessian_pattern(m, D);
  Eigen::SparseMatrix<double> H = pat.matrix;
  VectorXd g = VectorXd::Zero(x.size());
  shell_energy_derivatives(m, rest, material(), x, g, &pat, H.valuePtr(), nullptr, model);
  const Eigen::SparseMatrix<double> full = H.selfadjointView<Eigen::Lower>();
  return MatrixXd(full);
}

Eigen::Vector2d eig_range(const MatrixXd& H) {
  Eigen::SelfAdjointEigenSolver<MatrixXd> es(H);
  return {es.eigenvalues().minCoeff(), es.eigenvalues().maxCoeff()};
}

}  // namespace

TEST(HessianModel, SplitIsPsdWhereTheExactHessianIsIndefinite) {
  const Mesh m = make_rectangle(0.04, 0.03, 4, 3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  // Compressed along x (s_x ~ -0.1: the |f1| term's curvature turns negative), sheared and
  // bent both ways (bending moments act, the dihedral angles' Hessians enter).
  VectorXd x(3 * m.num_vertices());
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double u = m.rest(v, 0), w = m.rest(v, 1);
    x.segment<3>(3 * v) << 0.9 * u + 0.15 * w, 1.02 * w, 8 * u * u - 5 * w * w + 3 * u * w;
    x.segment<3>(3 * v) += 1e-3 * Eigen::Vector3d(U(rng), U(rng), U(rng));
  }
  const Eigen::Vector2d exact = eig_range(dense_hessian(m, x, HessianModel::Exact));
  ASSERT_LT(exact[0], -1e-6 * exact[1]) << "the scene must make the exact Hessian indefinite";
  const MatrixXd S = dense_hessian(m, x, HessianModel::Split);
  const Eigen::Vector2d split = eig_range(S);
  EXPECT_GT(split[0], -1e-12 * split[1]);
  EXPECT_GT(split[1], 0.1 * exact[1]);  // not a vanishing matrix: same stiffness scale
  EXPECT_LT((S - S.transpose()).cwiseAbs().maxCoeff(), 1e-12 * split[1]);
}

TEST(HessianModel, SplitEqualsTheExactHessianWhereItIsPsdAndNoMomentActs) {
  const Mesh m = make_rectangle(0.05, 0.04, 5, 4);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  VectorXd x(3 * m.num_vertices());
  for (int v = 0; v < m.num_vertices(); ++v)
    x.segment<3>(3 * v) = R * Eigen::Vector3d(1.1 * m.rest(v, 0), 1.05 * m.rest(v, 1), 0) + Eigen::Vector3d(0.1, -0.2, 0.3);
  const MatrixXd E = dense_hessian(m, x, HessianModel::Exact);
  const Eigen::Vector2d exact = eig_range(E);
  ASSERT_GT(exact[0], -1e-12 * exact[1]) << "uniform tension: the exact Hessian must be PSD";
  const MatrixXd S = dense_hessian(m, x, HessianModel::Split);
  EXPECT_LT((S - E).cwiseAbs().maxCoeff(), 1e-12 * E.cwiseAbs().maxCoeff());
  // The projected-element model agrees there too (nothing to project).
  const MatrixXd P = dense_hessian(m, x, HessianModel::ProjectedElement);
  EXPECT_LT((P - E).cwiseAbs().maxCoeff(), 1e-12 * E.cwiseAbs().maxCoeff());
}

TEST(HessianModel, InPlaneTermProjectedInF1F2) {
  const Eigen::Vector3d x0(0, 0, 0), x1(0.011, 0.001, 0.002), x2(0.003, 0.009, -0.001);
  const Eigen::Matrix2d Binv = (Eigen::Matrix2d() << 100, 0, 0, 100).finished();  // 1 cm legs at rest
  auto term = [&](const Eigen::Vector3d& lambda, bool psd) {
    Mat9 H;
    inplane_strain(x0, x1, x2, Binv, nullptr, &lambda, &H, psd);
    return H;
  };
  auto min_eig = [](const Mat9& H) { return Eigen::SelfAdjointEigenSolver<Mat9>(H).eigenvalues().minCoeff(); };
  // Tension in both directions, no shear stress: PSD already, the projection changes nothing.
  const Eigen::Vector3d tension(2.0, 0.0, 1.5);
  const Mat9 T = term(tension, false);
  ASSERT_GT(min_eig(T), -1e-12 * T.norm());
  EXPECT_LT((term(tension, true) - T).cwiseAbs().maxCoeff(), 1e-12 * T.norm());
  // Compression and shear stress: indefinite exactly, PSD projected.
  const Eigen::Vector3d compression(-2.0, 0.8, 1.0);
  const Mat9 C = term(compression, false);
  ASSERT_LT(min_eig(C), -1e-3 * C.norm());
  const Mat9 Cp = term(compression, true);
  EXPECT_GT(min_eig(Cp), -1e-12 * Cp.norm());
  // The projection keeps C's positive part: C - Cp is negative semi-definite.
  EXPECT_LT(Eigen::SelfAdjointEigenSolver<Mat9>(C - Cp).eigenvalues().maxCoeff(), 1e-12 * C.norm());
}

// The in-plane term's projection is the 6 x 6 one in (f1, f2) (done as a 4 x 4 tangent block and
// a 2 x 2 normal block): recovering the exact 6 x 6 matrix from the unprojected 9 x 9 term
// (H9 = C^T Hf C with C the 6 x 9 map x -> f of full rank), projecting it whole and mapping it
// back gives the projected term, for both eigenvalue filters, over random shapes and stresses.
TEST(HessianModel, InPlaneProjectionIsTheWhole6x6Projection) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  const Eigen::Matrix2d Binv = (Eigen::Matrix2d() << 100, 20, -10, 90).finished();
  Eigen::Matrix<double, 6, 9> C = Eigen::Matrix<double, 6, 9>::Zero();  // f_a = sum_v c_av x_v
  for (int a = 0; a < 2; ++a) {
    const double c[3] = {-(Binv(0, a) + Binv(1, a)), Binv(0, a), Binv(1, a)};
    for (int v = 0; v < 3; ++v) C.block<3, 3>(3 * a, 3 * v) = c[v] * Eigen::Matrix3d::Identity();
  }
  const Eigen::Matrix<double, 6, 6> CCi = (C * C.transpose()).inverse();
  int projected = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d x0(0, 0, 0);
    const Eigen::Vector3d x1 = Eigen::Vector3d(0.01, 0, 0) + 0.004 * Eigen::Vector3d(U(rng), U(rng), U(rng));
    const Eigen::Vector3d x2 = Eigen::Vector3d(0.002, 0.011, 0) + 0.004 * Eigen::Vector3d(U(rng), U(rng), U(rng));
    const Eigen::Vector3d lambda(3 * U(rng), 2 * U(rng), 3 * U(rng));
    for (numerics::EigenFilter filter : {numerics::EigenFilter::Clamp, numerics::EigenFilter::Abs}) {
      Mat9 H, Hp;
      inplane_strain(x0, x1, x2, Binv, nullptr, &lambda, &H, false);
      inplane_strain(x0, x1, x2, Binv, nullptr, &lambda, &Hp, true, filter);
      Eigen::Matrix<double, 6, 6> Hf = CCi * C * H * C.transpose() * CCi;
      Hf = (0.5 * (Hf + Hf.transpose())).eval();
      projected += numerics::project_psd<6>(Hf, filter);
      const Mat9 ref = C.transpose() * Hf * C;
      EXPECT_LT((Hp - ref).cwiseAbs().maxCoeff(), 1e-9 * ref.cwiseAbs().maxCoeff()) << trial;
    }
  }
  EXPECT_GT(projected, 100);  // most random stresses are indefinite there: the projection is tested
}
