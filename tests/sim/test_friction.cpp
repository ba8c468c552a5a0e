// Lagged smooth friction (sim/friction.hpp): the potential's gradient and Hessian against
// central differences on both sides of the sticking threshold eps; a sheet on an inclined plane
// slides with g (sin theta - mu cos theta) when mu < tan theta and creeps at the velocity the
// mollifier predicts (below eps_v) when mu > tan theta, dynamically and in load steps; mu = 0 is
// the frictionless slide g sin theta exactly; an off-centre drape slides off the sphere without
// friction and stays on it with mu = 0.3; contacts carry the barrier's normal force, none with mu = 0.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "numerics/barrier.hpp"
#include "sim/friction.hpp"
#include "sim/rectangle.hpp"
#include "sim/simulation.hpp"
#include "tests/common/fd_util.hpp"
#include "tests/common/poly_material.hpp"

using namespace yarnhom;
using namespace yarnhom::sim;

namespace {

const MaterialFn& material() {
  static const MaterialFn m = test::poly_material_fn(test::simple_cloth_terms());
  return m;
}

FrictionContact some_contact() {
  FrictionContact c;
  c.vertex = 0;
  c.mu_lambda = 0.7;
  c.T = tangent_basis(Eigen::Vector3d(0.3, -0.5, 0.8).normalized());
  c.x_start = Eigen::Vector3d(0.1, 0.2, -0.3);
  return c;
}

}  // namespace

TEST(Friction, TangentBasisIsOrthonormalAndPerpendicularToTheNormal) {
  for (const Eigen::Vector3d& n0 : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.3, -0.5, 0.8)}) {
    const Eigen::Vector3d n = n0.normalized();
    const Eigen::Matrix<double, 3, 2> T = tangent_basis(n);
    EXPECT_LT((T.transpose() * T - Eigen::Matrix2d::Identity()).norm(), 1e-14);
    EXPECT_LT((T.transpose() * n).norm(), 1e-14);
  }
}

TEST(Friction, MollifierIsC1AndCoulombBeyondEps) {
  const double eps = 2e-5;
  // f0 and f1 = f0' continuous at eps (f1 = 1 there), f1 = 0 at rest, f0 = y beyond.
  const FrictionMollifier a = friction_mollifier(eps * (1 - 1e-12), eps), b = friction_mollifier(eps, eps);
  EXPECT_NEAR(a.f0, b.f0, 1e-15);
  EXPECT_NEAR(a.f1_over_y * eps, 1.0, 1e-10);
  EXPECT_NEAR(b.f1_over_y * eps, 1.0, 1e-14);
  EXPECT_DOUBLE_EQ(friction_mollifier(3 * eps, eps).f0, 3 * eps);
  EXPECT_DOUBLE_EQ(friction_mollifier(0, eps).f0, eps / 3);
  EXPECT_DOUBLE_EQ(friction_mollifier(0, eps).f1_over_y, 2 / eps);
}

TEST(Friction, GradientAndHessianMatchFiniteDifferencesOnBothSidesOfEps) {
  const double eps = 1e-3;
  const FrictionContact c = some_contact();
  // Tangential displacements of 0.3 eps, 0.8 eps (smoothed) and 1.5 eps, 4 eps (sliding), with
  // a normal component that friction must ignore.
  const Eigen::Vector3d n = c.T.col(0).cross(c.T.col(1));
  for (double r : {0.3, 0.8, 1.5, 4.0}) {
    const Eigen::Vector2d dir = Eigen::Vector2d(0.6, -0.8);
    const Eigen::Vector3d x = c.x_start + c.T * (r * eps * dir) + 0.37 * eps * n;
    Eigen::Vector3d g;
    Eigen::Matrix3d H;
    friction_energy(c, x, eps, &g, &H);
    const double h = 1e-4 * eps;  // far from the switch at |u| = eps on either side
    auto f = [&](const Eigen::VectorXd& y) { return friction_energy(c, y, eps); };
    auto grad = [&](const Eigen::VectorXd& y) {
      Eigen::Vector3d gy;
      friction_energy(c, y, eps, &gy);
      return Eigen::VectorXd(gy);
    };
    const Eigen::VectorXd gfd = test::fd_gradient(f, x, h);
    const Eigen::MatrixXd Hfd = test::fd_jacobian(grad, x, h);
    EXPECT_LT(test::rel_err(g, gfd), 1e-8) << "|u| = " << r << " eps: " << g.transpose() << " vs " << gfd.transpose();
    EXPECT_LT(test::rel_err(H, Hfd), 1e-6) << "|u| = " << r << " eps\n" << H << "\nvs\n" << Hfd;
    // Sliding: the force is mu lambda along the slip; smoothed: less.
    const double force = g.norm() / c.mu_lambda;
    if (r >= 1) EXPECT_NEAR(force, 1.0, 1e-12);
    else EXPECT_NEAR(force, 2 * r - r * r, 1e-12);
    EXPECT_NEAR(g.dot(n), 0.0, 1e-14);
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(H).eigenvalues().minCoeff(), -1e-12 * H.norm());
  }
  // At rest: no force, the sticking stiffness mu lambda 2/eps in the tangent plane.
  Eigen::Vector3d g;
  Eigen::Matrix3d H;
  friction_energy(c, c.x_start, eps, &g, &H);
  EXPECT_EQ(g.norm(), 0.0);
  EXPECT_LT((H - c.mu_lambda * 2 / eps * c.T * c.T.transpose()).norm(), 1e-12 * H.norm());
}

namespace {

// A 10 cm sheet lying at rest on the plane through the origin tilted by theta about y (downhill
// along -(cos theta, 0, sin theta)), at the distance where each vertex's barrier force carries
// the normal component of its weight.
struct Incline {
  double theta;
  Eigen::Vector3d n, down;
  Scene scene;
};

Incline incline(double theta, double mu, Integrator integ) {
  Incline I;
  I.theta = theta;
  I.n = Eigen::Vector3d(-std::sin(theta), 0, std::cos(theta));
  I.down = -Eigen::Vector3d(std::cos(theta), 0, std::sin(theta));
  Scene& s = I.scene;
  s.mesh = make_rectangle(0.1, 0.1, 3, 3);
  s.integrator = integ;
  // |b'(d)| kappa A = rho A g cos theta with kappa = 100 rho g (the default): |b'(d)| = cos/100.
  double lo = 1e-12, hi = s.dhat;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (std::abs(numerics::distance_barrier(mid, s.dhat).db) > std::cos(theta) / 100 ? lo : hi) = mid;
  }
  const double d = 0.5 * (lo + hi);
  const Eigen::Vector3d ex(std::cos(theta), 0, std::sin(theta));
  for (int v = 0; v < s.mesh.num_vertices(); ++v)
    s.mesh.x.row(v) = (s.mesh.rest(v, 0) * ex + s.mesh.rest(v, 1) * Eigen::Vector3d::UnitY() + d * I.n).transpose();
  Collider plane;
  plane.kind = Collider::Kind::Plane;
  plane.normal = I.n;
  plane.friction = mu;
  s.colliders = {plane};
  s.newton.tol_step = 1e-11;  // m; the creep moves about 1e-6 m a step
  return I;
}

double mean_along(const Eigen::VectorXd& v, const Eigen::Vector3d& dir) {
  double s = 0;
  for (int i = 0; i < v.size() / 3; ++i) s += v.segment<3>(3 * i).dot(dir);
  return s / (v.size() / 3);
}

}  // namespace

TEST(Friction, SheetOnAnInclineSlidesWithGSinMinusMuCos) {
  const double theta = 30 * M_PI / 180, g = 9.81, h = 0.01, rho = 0.3;
  for (double mu : {0.0, 0.2, 0.45}) {
    Incline I = incline(theta, mu, Integrator::Newton);
    I.scene.dt = h;
    std::vector<double> speed;
    SimResult r = run_simulation(I.scene, material(), rho, SimSettings{}, [&](int, const SimResult& res) {
      speed.push_back(mean_along(res.v, I.down));
    });
    ASSERT_TRUE(r.finite);
    ASSERT_TRUE(r.all_converged);
    ASSERT_EQ(speed.size(), 90u);
    // Implicit Euler under a constant net force: v_k = k h a from the first step on.
    const double a = (speed[89] - speed[9]) / (80 * h), expect = g * (std::sin(theta) - mu * std::cos(theta));
    if (mu == 0)
      EXPECT_NEAR(a, expect, 1e-6 * expect) << "frictionless: exactly g sin theta";
    else
      EXPECT_NEAR(a, expect, 1e-4 * expect) << "mu " << mu;  // the normal force is lagged exactly: m g cos theta
    // It stays on the plane, at the normal equilibrium.
    for (int v = 0; v < I.scene.mesh.num_vertices(); ++v) EXPECT_NEAR(r.v.segment<3>(3 * v).dot(I.n), 0.0, 1e-6);
  }
}

TEST(Friction, SheetOnAnInclineSticksWhenMuExceedsTanTheta) {
  // mu > tan theta: the smoothed friction balances the slope's pull mu lambda f1(v h) = m g sin
  // theta at the velocity v with f1 = tan(theta)/mu, i.e. v = (1 - sqrt(1 - tan(theta)/mu)) eps_v
  // (a creep below eps_v: IPC's static friction); so over a time t the sheet moves less than
  // eps_v t.
  const double theta = 30 * M_PI / 180, h = 0.01, rho = 0.3, mu = 0.8;
  Incline I = incline(theta, mu, Integrator::Newton);
  I.scene.dt = h;
  I.scene.frames = 100;
  const Eigen::VectorXd x0 = flatten(I.scene.mesh.x);
  const SimResult r = run_simulation(I.scene, material(), rho, SimSettings{});
  ASSERT_TRUE(r.finite);
  ASSERT_TRUE(r.all_converged);
  const double eps_v = r.friction_eps_v, t = 100 * h;
  EXPECT_NEAR(eps_v, 1e-3 * 0.1 * std::sqrt(2.0), 1e-15);  // the default, 1e-3 sheet diagonals per second
  const double creep = (1 - std::sqrt(1 - std::tan(theta) / mu)) * eps_v;
  const double moved = mean_along(r.x - x0, I.down);
  EXPECT_GT(moved, 0);
  EXPECT_LT(moved, eps_v * t);
  EXPECT_NEAR(mean_along(r.v, I.down), creep, 1e-3 * creep);
  EXPECT_NEAR(moved, creep * t, 1e-2 * creep * t);
}

TEST(Friction, StaticLoadStepsCreepByTheMollifiersDisplacement) {
  // In load steps eps is a displacement (eps_v x 1 s): each step's equilibrium has
  // mu lambda f1(|u|) = m g sin theta, |u| = (1 - sqrt(1 - tan(theta)/mu)) eps.
  const double theta = 20 * M_PI / 180, rho = 0.3, mu = 0.6;
  Incline I = incline(theta, mu, Integrator::Static);
  I.scene.frames = 4;
  I.scene.newton.tol_step = 1e-12;
  const Eigen::VectorXd x0 = flatten(I.scene.mesh.x);
  std::vector<double> moved;
  const SimResult r = run_simulation(I.scene, material(), rho, SimSettings{}, [&](int, const SimResult& res) {
    moved.push_back(mean_along(res.x - x0, I.down));
  });
  ASSERT_TRUE(r.finite);
  ASSERT_TRUE(r.all_converged);
  const double step = (1 - std::sqrt(1 - std::tan(theta) / mu)) * r.friction_eps_v;
  // The relaxation at load 0 (the load path starts in equilibrium) is the first of these
  // equilibria: after frame k the sheet has crept k + 1 steps.
  ASSERT_EQ(moved.size(), 4u);
  for (size_t k = 0; k < moved.size(); ++k) EXPECT_NEAR(moved[k], (k + 2) * step, 1e-3 * step) << "load step " << k + 1;
}

TEST(Friction, OffCentreDrapeStaysOnTheSphereOnlyWithFriction) {
  // The drape scene with the sheet shifted 6 cm sideways: its overhang pulls it off a
  // frictionless sphere; with mu = 0.3 it comes to rest draped over it. By frame 60 its corners
  // still sway at a few cm/s, in a phase the rounding of the 60 steps sets (a relative change of
  // 1e-15 in one element term moved the last frame's largest speed from 0.005 to 0.055 m/s), so
  // the speed is judged over the last 10 frames.
  for (double mu : {0.0, 0.3}) {
    Scene s = builtin_scene("drape", 10);
    for (int v = 0; v < s.mesh.num_vertices(); ++v) s.mesh.x(v, 0) += 0.06;
    for (Collider& c : s.colliders) c.friction = mu;
    s.frames = 60;
    double vmax = 0;  // the mean over frames 51-60 of the largest vertex speed
    const SimResult r = run_simulation(s, material(), 0.3, SimSettings{}, [&](int frame, const SimResult& res) {
      if (frame <= 50) return;
      double vm = 0;
      for (int v = 0; v < s.mesh.num_vertices(); ++v) vm = std::max(vm, res.v.segment<3>(3 * v).norm());
      vmax += vm / 10;
    });
    ASSERT_TRUE(r.finite);
    Eigen::Vector3d com = Eigen::Vector3d::Zero();
    for (int v = 0; v < s.mesh.num_vertices(); ++v) com += r.x.segment<3>(3 * v) / s.mesh.num_vertices();
    // Sphere: radius 0.15 m at the origin; floor at z = -0.15.
    if (mu == 0) {
      EXPECT_LT(com.z(), -0.1) << "frictionless: slid off onto the floor, " << com.transpose();
      EXPECT_GT(std::hypot(com.x(), com.y()), 0.15) << com.transpose();
    } else {
      EXPECT_GT(com.z(), 0.0) << "centre of mass above the sphere's centre: " << com.transpose();
      EXPECT_LT(std::hypot(com.x(), com.y()), 0.05) << com.transpose();
      EXPECT_LT(vmax, 0.04) << "largest speed over the last 10 frames, mean, m/s";
    }
  }
}

TEST(Friction, ContactsCarryTheBarriersNormalForceAndNoneWithZeroMu) {
  Mesh mesh = make_rectangle(0.1, 0.1, 1, 1);
  for (int v = 0; v < 4; ++v) mesh.x(v, 2) = v == 0 ? 4e-4 : 0.05;  // only vertex 0 within dhat = 1 mm
  Problem P = make_problem(mesh, material(), 0.3);
  P.kappa = 30;
  Collider floor;
  floor.kind = Collider::Kind::Plane;
  P.colliders = {floor};
  const Eigen::VectorXd x = flatten(P.mesh.x);
  EXPECT_TRUE(friction_contacts(P, {}, x, x).empty()) << "mu = 0: frictionless, no contact";
  EXPECT_FALSE(has_friction(P));
  P.colliders[0].friction = 0.5;
  const std::vector<FrictionContact> c = friction_contacts(P, {}, x, x);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].vertex, 0);
  // mu lambda = mu kappa A |b'(d)|: the barrier's force on the vertex.
  EXPECT_NEAR(c[0].mu_lambda, 0.5 * 30 * P.vertex_area[0] * std::abs(numerics::distance_barrier(4e-4, P.dhat).db), 1e-15);
  EXPECT_LT((c[0].T.transpose() * Eigen::Vector3d::UnitZ()).norm(), 1e-15);
  // A prescribed vertex gets none.
  EXPECT_TRUE(friction_contacts(P, {-1, 0, 1, 2}, x, x).empty());
}
