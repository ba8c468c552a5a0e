#include "yarn/rod/rod.hpp"

#include <cmath>

#include "yarn/rod/frames.hpp"
#include "numerics/jet.hpp"

namespace yarnhom::yarn {

using numerics::Jet;
using numerics::V3;
using numerics::value;

double stretch_energy(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, double L, double EA,
                      Vec6* g, Mat6* H) {
  const Eigen::Vector3d e = x1 - x0;
  const double len = e.norm(), strain = len / L - 1.0;
  if (g || H) {
    const Eigen::Vector3d t = e / len;
    const Eigen::Vector3d ge = EA * strain * t;
    if (g) *g << -ge, ge;
    if (H) {
      const Eigen::Matrix3d tt = t * t.transpose();
      const Eigen::Matrix3d He = EA / L * tt + EA * strain / len * (Eigen::Matrix3d::Identity() - tt);
      H->topLeftCorner<3, 3>() = He;
      H->bottomRightCorner<3, 3>() = He;
      H->topRightCorner<3, 3>() = -He;
      H->bottomLeftCorner<3, 3>() = -He;
    }
  }
  return 0.5 * EA * L * strain * strain;
}

namespace {

template <class T>
struct JointGeom {
  T k1, k2, twist;
};

// Everything the joint energy needs, for any scalar: the single definition that the double
// energy, its Jet derivatives and the reports share.
// Everything the joint energy needs, for any scalar, from the two edge vectors and the two
// twist angles (the energy depends on the three points only through e_in = x - x_prev and
// e_out = x_next - x: 8 inputs instead of 11, which roughly halves the cost of the exact
// Hessian): the single definition that the double energy, its Jet derivatives and the
// reports share.
template <class T>
JointGeom<T> joint_geometry(const V3<T>& ein, const V3<T>& eout, const T& th_in, const T& th_out,
                            const JointFrames& f) {
  using std::cos;
  using std::sin;
  const V3<T> tin = (1.0 / norm(ein)) * ein;
  const V3<T> tout = (1.0 / norm(eout)) * eout;
  const V3<T> d1in = transport(V3<double>(f.in.t), tin, V3<double>(f.in.d1));
  const V3<T> d1out = transport(V3<double>(f.out.t), tout, V3<double>(f.out.d1));
  const V3<T> d2in = cross(tin, d1in), d2out = cross(tout, d1out);
  const T ci = cos(th_in), si = sin(th_in), co = cos(th_out), so = sin(th_out);
  const V3<T> m1in = ci * d1in + si * d2in, m2in = ci * d2in - si * d1in;
  const V3<T> m1out = co * d1out + so * d2out, m2out = co * d2out - so * d1out;
  const V3<T> kb = (2.0 / (1.0 + dot(tin, tout))) * cross(tin, tout);
  JointGeom<T> r;
  r.k1 = 0.5 * dot(m2in + m2out, kb);
  r.k2 = -0.5 * dot(m1in + m1out, kb);
  const V3<T> moved = transport_same(tin, tout, d1in);
  const T psi = signed_angle(moved, d1out, tout);
  const double shift = unwrap_near(value(psi), f.twist_hint) - value(psi);
  r.twist = th_out - th_in + (psi + shift);
  return r;
}

// q8 = [e_in, e_out, theta_in, theta_out].
template <class T>
T joint_energy_t(const T* q, const JointFrames& f, const JointRest& rest, double EI, double GJ,
                 int terms) {
  const V3<T> ein(q[0], q[1], q[2]), eout(q[3], q[4], q[5]);
  const JointGeom<T> g = joint_geometry(ein, eout, q[6], q[7], f);
  T e(0.0);
  if (terms & kBend) {
    const T d1 = g.k1 - rest.kappa[0], d2 = g.k2 - rest.kappa[1];
    e = e + (0.5 * EI / rest.voronoi) * (d1 * d1 + d2 * d2);
  }
  if (terms & kTwist) {
    const T dm = g.twist - rest.twist;
    e = e + (0.5 * GJ / rest.voronoi) * (dm * dm);
  }
  return e;
}

// d q8 / d q11: e_in = x - x_prev, e_out = x_next - x, angles unchanged.
Eigen::Matrix<double, 8, 11> edge_map() {
  Eigen::Matrix<double, 8, 11> D = Eigen::Matrix<double, 8, 11>::Zero();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  D.block<3, 3>(0, 0) = -I;
  D.block<3, 3>(0, 3) = I;
  D.block<3, 3>(3, 3) = -I;
  D.block<3, 3>(3, 6) = I;
  D(6, 9) = D(7, 10) = 1;
  return D;
}

Eigen::Matrix<double, 8, 1> to_edges(const Vec11& q) {
  Eigen::Matrix<double, 8, 1> e;
  e << q.segment<3>(3) - q.segment<3>(0), q.segment<3>(6) - q.segment<3>(3), q[9], q[10];
  return e;
}

}  // namespace

double joint_energy(const Vec11& q, const JointFrames& f, const JointRest& rest, double EI,
                    double GJ, int terms, Vec11* g, Mat11* H) {
  const Eigen::Matrix<double, 8, 1> q8 = to_edges(q);
  if (!g && !H) return joint_energy_t<double>(q8.data(), f, rest, EI, GJ, terms);
  Jet<8> qj[8];
  for (int i = 0; i < 8; ++i) qj[i] = Jet<8>::variable(i, q8[i]);
  const Jet<8> e = joint_energy_t<Jet<8>>(qj, f, rest, EI, GJ, terms);
  static const Eigen::Matrix<double, 8, 11> D = edge_map();
  if (g) *g = D.transpose() * e.g;
  if (H) *H = D.transpose() * e.h * D;
  return e.v;
}

Eigen::Vector3d transported_director(const EdgeFrame& f, const Eigen::Vector3d& t_now) {
  const V3<double> d = transport_same(V3<double>(f.t), V3<double>(t_now), V3<double>(f.d1));
  // Re-orthonormalize against round-off drift over many updates.
  Eigen::Vector3d r(d.x, d.y, d.z);
  r -= r.dot(t_now) * t_now;
  return r.normalized();
}

double reference_twist(const Eigen::Vector3d& t_in, const Eigen::Vector3d& d1_in,
                       const Eigen::Vector3d& t_out, const Eigen::Vector3d& d1_out, double hint) {
  const V3<double> moved = transport_same(V3<double>(t_in), V3<double>(t_out), V3<double>(d1_in));
  return unwrap_near(signed_angle(moved, V3<double>(d1_out), V3<double>(t_out)), hint);
}

JointStrain joint_strain(const Vec11& q, const JointFrames& f) {
  const Eigen::Matrix<double, 8, 1> q8 = to_edges(q);
  const JointGeom<double> g =
      joint_geometry(V3<double>(q8[0], q8[1], q8[2]), V3<double>(q8[3], q8[4], q8[5]), q8[6], q8[7], f);
  return {g.k1, g.k2, g.twist};
}

}  // namespace yarnhom::yarn
