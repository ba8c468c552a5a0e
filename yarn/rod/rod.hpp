#pragma once
// Discrete elastic rods (Bergou et al. 2008; 2010 for the time-parallel reference frame):
// the elastic energy of one closed yarn is a sum of
//   stretch, per edge:   1/2 EA L (|e|/L - 1)^2                         (L: rest length)
//   bend, per joint:     EI/(2 l) ((k1 - K1)^2 + (k2 - K2)^2)             (l: Voronoi rest length)
//   twist, per joint:    GJ/(2 l) (m - M)^2,  m = theta_out - theta_in + reference twist
// with material curvatures k1 = (m2_in + m2_out)/2 . kb, k2 = -(m1_in + m1_out)/2 . kb,
// kb = 2 t_in x t_out / (1 + t_in . t_out), and material frames m1 = cos(theta) d1 + sin(theta)
// d2, m2 = -sin(theta) d1 + cos(theta) d2 built on reference directors d1 (d2 = t x d1).
//
// The reference director of an edge is its director at the last frame update, parallel
// transported from the tangent it had then to the current tangent. That makes every energy
// an explicit smooth function of (positions, twist angles) given the stored frames, so its
// derivatives are exact and finite differences check them; the frames are re-based after
// each accepted Newton step (update), which leaves the energy unchanged.
#include <Eigen/Core>

namespace yarnhom::yarn {

struct EdgeFrame {
  Eigen::Vector3d t;   // unit tangent when the frame was last updated
  Eigen::Vector3d d1;  // reference director then, perpendicular to t
};

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec11 = Eigen::Matrix<double, 11, 1>;
using Mat11 = Eigen::Matrix<double, 11, 11>;

// Stretch of one edge x0 -> x1; g, H over [x0, x1] when non-null.
double stretch_energy(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, double rest_length,
                      double EA, Vec6* g, Mat6* H);

// The joint between an incoming and an outgoing edge. q = [x_prev, x, x_next, theta_in,
// theta_out]. `twist_hint` picks the 2 pi branch of the reference twist (its last value).
struct JointRest {
  Eigen::Vector2d kappa = Eigen::Vector2d::Zero();  // rest material curvatures K1, K2
  double twist = 0;                                 // rest twist M
  double voronoi = 1;                               // l = (L_in + L_out) / 2
};
struct JointFrames {
  EdgeFrame in, out;
  double twist_hint = 0;
};
enum JointTerms { kBend = 1, kTwist = 2, kBendTwist = 3 };
double joint_energy(const Vec11& q, const JointFrames& f, const JointRest& rest, double EI,
                    double GJ, int terms, Vec11* g, Mat11* H);

// Reference director of an edge now (the stored frame transported to the current tangent).
Eigen::Vector3d transported_director(const EdgeFrame& f, const Eigen::Vector3d& t_now);
// Reference twist at a joint for given current tangents and directors, on the branch nearest
// the hint.
double reference_twist(const Eigen::Vector3d& t_in, const Eigen::Vector3d& d1_in,
                       const Eigen::Vector3d& t_out, const Eigen::Vector3d& d1_out, double hint);
// Material curvatures and twist of a joint now (for reports and tests).
struct JointStrain {
  double k1, k2, twist;
};
JointStrain joint_strain(const Vec11& q, const JointFrames& f);

}  // namespace yarnhom::yarn
