// The shell energy sum_T A_T Psi(s_T) with a baked material: gradient and (unprojected)
// Hessian against central differences; rigid motions of the rest shape give zero energy and
// zero force; a uniform in-plane strain gives zero force at interior vertices (patch test);
// the PSD projection leaves PSD matrices alone and removes negative eigenvalues; the coupling of
// a prescribed move (the one-solve step's) is the Hessian applied to it.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <random>

#include "sim/dof_map.hpp"
#include "sim/hessian_pattern.hpp"
#include "sim/problem.hpp"
#include "numerics/psd_projection.hpp"
#include "sim/rectangle.hpp"
#include "sim/shell_energy.hpp"
#include "sim/simulation.hpp"
#include "tests/common/fd_util.hpp"
#include "tests/common/poly_material.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;
using Eigen::VectorXd;

namespace {

const MaterialFn& material() {
  static const MaterialFn m = test::poly_material_fn(test::simple_cloth_terms());
  return m;
}

// A small bent, stretched sheet.
VectorXd deformed(const Mesh& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  VectorXd x(3 * m.num_vertices());
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double u = m.rest(v, 0), w = m.rest(v, 1);
    x.segment<3>(3 * v) << 1.1 * u + 0.05 * w, 0.95 * w, 0.3 * u * u + 0.2 * u * w;
    x.segment<3>(3 * v) += 2e-3 * Eigen::Vector3d(U(rng), U(rng), U(rng));
  }
  return x;
}

Eigen::MatrixXd dense_hessian(const Mesh& m, const std::vector<ElementRest>& rest, const VectorXd& x, bool project) {
  const DofMap D = make_dof_map(m.num_vertices(), {});
  const HessianPattern pat = make_hessian_pattern(m, D);
  Eigen::SparseMatrix<double> H = pat.matrix;
  VectorXd g = VectorXd::Zero(x.size());
  shell_energy_derivatives(m, rest, material(), x, g, &pat, H.valuePtr(), nullptr,
                           project ? HessianModel::ProjectedElement : HessianModel::Exact);
  const Eigen::SparseMatrix<double> full = H.selfadjointView<Eigen::Lower>();
  return Eigen::MatrixXd(full);
}

}  // namespace

TEST(ShellEnergy, GradientAndHessianMatchFiniteDifferences) {
  const Mesh m = make_rectangle(0.04, 0.03, 4, 3);
  const auto rest = make_element_rests(m);
  const VectorXd x = deformed(m, 3);
  VectorXd g = VectorXd::Zero(x.size());
  const double E = shell_energy_derivatives(m, rest, material(), x, g, nullptr, nullptr);
  EXPECT_NEAR(E, shell_energy(m, rest, material(), x), 1e-15 * std::abs(E));
  auto energy = [&](const VectorXd& y) { return shell_energy(m, rest, material(), y); };
  EXPECT_LT(test::rel_err(g, test::fd_gradient(energy, x, 1e-7)), 1e-6);
  auto gradient = [&](const VectorXd& y) {
    VectorXd g = VectorXd::Zero(y.size());
    shell_energy_derivatives(m, rest, material(), y, g, nullptr, nullptr);
    return g;
  };
  const Eigen::MatrixXd H = dense_hessian(m, rest, x, false);
  EXPECT_LT(test::rel_err(H, test::fd_jacobian(gradient, x, 1e-7)), 1e-6);
  // The projected Hessian is positive semi-definite and differs from the exact one.
  const Eigen::MatrixXd Hp = dense_hessian(m, rest, x, true);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Hp);
  EXPECT_GT(es.eigenvalues().minCoeff(), -1e-9 * es.eigenvalues().maxCoeff());
}

TEST(ShellEnergy, RigidMotionsOfTheRestShapeGiveZeroEnergyAndForce) {
  const Mesh m = make_rectangle(0.1, 0.05, 6, 3);
  const auto rest = make_element_rests(m);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.2, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  VectorXd x(3 * m.num_vertices());
  for (int v = 0; v < m.num_vertices(); ++v)
    x.segment<3>(3 * v) = R * Eigen::Vector3d(m.rest(v, 0), m.rest(v, 1), 0) + Eigen::Vector3d(0.3, 2, -1);
  VectorXd g = VectorXd::Zero(x.size());
  const double E = shell_energy_derivatives(m, rest, material(), x, g, nullptr, nullptr);
  EXPECT_NEAR(E, 0.0, 1e-15);
  // Force scale for comparison: a 1 % stretch of the same sheet.
  VectorXd y = x, gy = VectorXd::Zero(x.size());
  for (int v = 0; v < m.num_vertices(); ++v) y.segment<3>(3 * v) = R * Eigen::Vector3d(1.01 * m.rest(v, 0), m.rest(v, 1), 0);
  shell_energy_derivatives(m, rest, material(), y, gy, nullptr, nullptr);
  EXPECT_LT(g.cwiseAbs().maxCoeff(), 1e-10 * gy.cwiseAbs().maxCoeff());
}

TEST(ShellEnergy, PatchTestUniformStrainHasNoInteriorForce) {
  const Mesh m = make_rectangle(0.1, 0.08, 10, 8);
  const auto rest = make_element_rests(m);
  Eigen::Matrix<double, 3, 2> F;
  F << 1.2, 0.1, 0.05, 0.9, 0.0, 0.0;
  VectorXd x(3 * m.num_vertices());
  for (int v = 0; v < m.num_vertices(); ++v) x.segment<3>(3 * v) = F * m.rest.row(v).transpose();
  VectorXd g = VectorXd::Zero(x.size());
  shell_energy_derivatives(m, rest, material(), x, g, nullptr, nullptr);
  double interior = 0, boundary = 0;
  for (int j = 0; j <= 8; ++j)
    for (int i = 0; i <= 10; ++i) {
      const double f = g.segment<3>(3 * rectangle_vertex(10, i, j)).norm();
      if (i == 0 || j == 0 || i == 10 || j == 8)
        boundary = std::max(boundary, f);
      else
        interior = std::max(interior, f);
    }
  EXPECT_GT(boundary, 1e-4);
  EXPECT_LT(interior, 1e-12 * boundary);
  // The boundary forces are the tractions: their sum vanishes (no net force).
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (int v = 0; v < m.num_vertices(); ++v) total += g.segment<3>(3 * v);
  EXPECT_LT(total.norm(), 1e-12 * boundary);
}

TEST(PsdProjection, KeepsPsdMatricesAndClampsNegativeEigenvalues) {
  std::mt19937 rng(5);
  std::normal_distribution<double> N(0, 1);
  Eigen::Matrix<double, 18, 18> A;
  for (int i = 0; i < 18; ++i)
    for (int j = 0; j < 18; ++j) A(i, j) = N(rng);
  // PSD of rank 12 (zero modes like an element's rigid motions): unchanged.
  Eigen::Matrix<double, 18, 12> B = A.leftCols<12>();
  Eigen::Matrix<double, 18, 18> P = B * B.transpose(), P0 = P;
  EXPECT_FALSE(numerics::project_psd(P));
  EXPECT_EQ(P, P0);
  // Indefinite: projected onto the PSD cone, same eigenvectors, negative eigenvalues -> 0.
  Eigen::Matrix<double, 18, 18> S = A + A.transpose(), S0 = S;
  EXPECT_TRUE(numerics::project_psd(S));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 18, 18>> e0(S0), e1(S);
  for (int i = 0; i < 18; ++i) EXPECT_NEAR(e1.eigenvalues()[i], std::max(0.0, e0.eigenvalues()[i]), 1e-10);
}

// The one-solve step's coupling (sim/shell_energy.hpp: H_e applied to the prescribed vertices'
// move): with the exact Hessian it is the directional derivative of the gradient along the move
// (central differences), at every vertex; with the projected one, the assembled projected
// Hessian (every vertex free) times the move.
TEST(ShellEnergy, CouplingIsTheHessianAppliedToThePrescribedMove) {
  const Mesh m = make_rectangle(0.04, 0.03, 4, 3);
  const auto rest = make_element_rests(m);
  const VectorXd x = deformed(m, 5);
  std::vector<int> left;
  for (int j = 0; j <= 3; ++j) left.push_back(rectangle_vertex(4, 0, j));
  const DofMap D = make_dof_map(m.num_vertices(), left);
  const HessianPattern pat = make_hessian_pattern(m, D);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  VectorXd d = VectorXd::Zero(x.size());
  for (int v : left) d.segment<3>(3 * v) = 1e-3 * Eigen::Vector3d(U(rng), U(rng), U(rng));
  auto coupling = [&](HessianModel model) {
    Eigen::SparseMatrix<double> H = pat.matrix;
    VectorXd g = VectorXd::Zero(x.size()), c = VectorXd::Zero(x.size());
    shell_energy_derivatives(m, rest, material(), x, g, &pat, H.valuePtr(), nullptr, model, nullptr,
                             numerics::EigenFilter::Clamp, &d, &c);
    return c;
  };
  auto gradient = [&](const VectorXd& y) {
    VectorXd g = VectorXd::Zero(y.size());
    shell_energy_derivatives(m, rest, material(), y, g, nullptr, nullptr);
    return g;
  };
  const double eps = 1e-4;  // along d (1 mm): steps of 0.1 um
  const VectorXd fd = (gradient(x + eps * d) - gradient(x - eps * d)) / (2 * eps);
  const VectorXd exact = coupling(HessianModel::Exact);
  EXPECT_GT(exact.norm(), 0);
  EXPECT_LT(test::rel_err(exact, fd), 1e-6);
  EXPECT_LT(test::rel_err(coupling(HessianModel::ProjectedElement), VectorXd(dense_hessian(m, rest, x, true) * d)), 1e-12);
}

// The element loop runs in fixed chunks of triangles, each summed in its own place and the
// chunks added in order (sim/shell_energy.cpp): on any thread count the energy, the gradient
// and every matrix entry are the one thread's bit for bit, and the chunked sums lose nothing
// (the exact Hessian times a direction against central differences of the gradient).
TEST(ShellEnergy, AssemblyOnAnyThreadCountIsTheOneThreadsBitForBit) {
  const Mesh m = make_rectangle(0.3, 0.25, 40, 30);  // 2,400 triangles: several chunks, threaded
  ASSERT_GE(m.num_triangles(), 2048);
  const auto rest = make_element_rests(m);
  const VectorXd x = deformed(m, 9);
  std::vector<int> held;
  for (int j = 0; j <= 30; ++j) held.push_back(rectangle_vertex(40, 0, j));
  const DofMap D = make_dof_map(m.num_vertices(), held);
  const HessianPattern pat = make_hessian_pattern(m, D);
  const int saved = omp_get_max_threads();
  auto assemble = [&](int threads, VectorXd& g, double& E, HessianModel model) {
    omp_set_num_threads(threads);
    Eigen::SparseMatrix<double> H = pat.matrix;
    g = VectorXd::Zero(x.size());
    E = shell_energy_derivatives(m, rest, material(), x, g, &pat, H.valuePtr(), nullptr, model);
    omp_set_num_threads(saved);
    return H;
  };
  VectorXd g1;
  double E1 = 0;
  const Eigen::SparseMatrix<double> H1 = assemble(1, g1, E1, HessianModel::ProjectedElement);
  ASSERT_GT(H1.coeffs().cwiseAbs().maxCoeff(), 0);
  for (int threads : {2, 3, 7}) {
    VectorXd g;
    double E = 0;
    const Eigen::SparseMatrix<double> H = assemble(threads, g, E, HessianModel::ProjectedElement);
    EXPECT_EQ(E, E1) << threads;
    EXPECT_EQ((g - g1).cwiseAbs().maxCoeff(), 0.0) << threads;
    EXPECT_EQ((H.coeffs() - H1.coeffs()).cwiseAbs().maxCoeff(), 0.0) << threads;
  }
  // The exact Hessian over the free vertices against the gradient's central differences.
  VectorXd g;
  double E = 0;
  const Eigen::SparseMatrix<double> Hx = assemble(3, g, E, HessianModel::Exact);
  const Eigen::SparseMatrix<double> Hfull = Hx.selfadjointView<Eigen::Lower>();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 3; ++trial) {
    VectorXd d = VectorXd::Zero(x.size()), df(3 * D.num_free());
    for (int f = 0; f < D.num_free(); ++f)
      for (int k = 0; k < 3; ++k) d[3 * D.free_vertices[size_t(f)] + k] = df[3 * f + k] = u(rng);
    const double eps = 1e-7;  // (truncation error ~ eps^2: 4e-4 at 1e-5)
    VectorXd gp = VectorXd::Zero(x.size()), gm = VectorXd::Zero(x.size());
    shell_energy_derivatives(m, rest, material(), x + eps * d, gp, nullptr, nullptr);
    shell_energy_derivatives(m, rest, material(), x - eps * d, gm, nullptr, nullptr);
    VectorXd fd(3 * D.num_free());
    for (int f = 0; f < D.num_free(); ++f)
      fd.segment<3>(3 * f) = (gp - gm).segment<3>(3 * D.free_vertices[size_t(f)]) / (2 * eps);
    EXPECT_LT(test::rel_err(VectorXd(Hfull * df), fd), 1e-6) << trial;
  }
}

// The step's strain check (sim/simulation.hpp, unphysical_strain) scans the triangles on the
// threads from 4,096 on: with two vertices dragged far off a 4,500-triangle sheet it names the
// first triangle beyond the limits (as a scan in order finds it), on 1 thread as on 3; the flat
// sheet passes.
TEST(ShellEnergy, StrainCheckNamesTheFirstTriangleBeyondTheLimitsOnAnyThreadCount) {
  const Mesh m = make_rectangle(0.3, 0.25, 50, 45);
  ASSERT_GE(m.num_triangles(), 4096);
  const Problem P = make_problem(m, material(), 0.2);
  VectorXd x(3 * m.num_vertices());
  for (int v = 0; v < m.num_vertices(); ++v) x.segment<3>(3 * v) = Eigen::Vector3d(m.rest(v, 0), m.rest(v, 1), 0);
  EXPECT_FALSE(unphysical_strain(P, x, nullptr).has_value());
  for (int v : {rectangle_vertex(50, 40, 30), rectangle_vertex(50, 7, 9)}) x[3 * v] += 0.5;  // 6 cm triangles stretched 8x
  const std::vector<Strain6> s = triangle_strains(m, P.rest, x);
  int first = -1;
  for (int t = 0; t < m.num_triangles() && first < 0; ++t)
    if (std::abs(s[size_t(t)][0]) > 5 || std::abs(s[size_t(t)][2]) > 5) first = t;
  ASSERT_GE(first, 0);
  const int saved = omp_get_max_threads();
  for (int threads : {1, 3}) {
    omp_set_num_threads(threads);
    const auto why = unphysical_strain(P, x, nullptr);
    omp_set_num_threads(saved);
    ASSERT_TRUE(why.has_value()) << threads;
    EXPECT_NE(why->find("triangle " + std::to_string(first) + " reached"), std::string::npos) << *why;
  }
}
