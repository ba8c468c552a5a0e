#pragma once
// The closest distance between two straight segments, a = a0 -> a1 and b = b0 -> b1, with its
// exact gradient and Hessian in the 12 endpoint coordinates q = [a0, a1, b0, b1].
//
// The squared distance is D(q) = min_{s,t in [0,1]} |p_a(s) - p_b(t)|^2, p_a(s) = a0 + s e_a,
// p_b(t) = b0 + t e_b. Where the minimizer (s*, t*) lies decides the *type* (IPC's
// classification): both parameters at an end (point-point, 4 cases), one at an end and the
// other inside (point-edge, 4 cases), both inside (edge-edge). Inside each type's region D is
// one smooth function of q; across region boundaries D and its gradient are continuous (the
// minimizer is unique and moves continuously), the Hessian jumps. The one exception is a pair
// of exactly parallel segments whose projections overlap: the minimizer is a whole interval,
// and D has a kink there (a measure-zero set; see docs/rve.md section 3).
//
// Derivatives, written out once for every type (llm.c style, no autodiff): with
// r = p_a(s) - p_b(t) = C(s, t) q, C = [(1-s) I, s I, -(1-t) I, -t I] (3 x 12),
//   f(q, s, t) = r . r,       D(q) = f(q, s*(q), t*(q)).
// Gradient (Danskin: the free parameters are stationary, the clamped ones are constants):
//   dD/dq = 2 C^T r.
// Hessian (the implicit function theorem on the stationarity of the free parameters y, a
// subset of (s, t)):
//   d2D/dq2 = f_qq - f_qy f_yy^-1 f_yq,   f_qq = 2 C^T C,
//   f_qs = 2 C^T e_a + 2 [-r, r, 0, 0],   f_qt = -2 C^T e_b + 2 [0, 0, r, -r],
//   f_ss = 2 e_a.e_a,  f_tt = 2 e_b.e_b,  f_st = -2 e_a.e_b.
// Nearly parallel segments: f_yy is singular for edge-edge when e_a x e_b = 0. Below
// |e_a x e_b|^2 < kParallel |e_a|^2 |e_b|^2 (an angle below 1e-6 rad) the edge-edge type is
// not used; the closest pair is taken with one parameter at an end (the exact minimum of
// parallel segments, and within 1e-12 (L/d)^2 relative of it for nearly parallel ones).
#include <Eigen/Core>

namespace yarnhom::numerics {

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

enum class SegmentDistanceType : int {
  kA0B0, kA0B1, kA1B0, kA1B1,  // point-point
  kA0B, kA1B,                  // endpoint of a to the interior of b
  kAB0, kAB1,                  // endpoint of b to the interior of a
  kAB                          // interior to interior (edge-edge)
};
const char* to_string(SegmentDistanceType t);

// Relative threshold on |e_a x e_b|^2 / (|e_a|^2 |e_b|^2) below which segments count as parallel.
inline constexpr double kParallel = 1e-12;

// Parameters of a closest pair: p_a(s), p_b(t); and the type they imply.
struct ClosestPair {
  double s = 0, t = 0;
  SegmentDistanceType type = SegmentDistanceType::kA0B0;
};
// A closest pair of points, robust to degenerate (zero-length) and parallel segments.
ClosestPair closest_pair(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& b0,
                         const Eigen::Vector3d& b1);

// The squared distance of a given type (the type's smooth formula, valid inside its region
// and extended smoothly beyond), with its exact gradient and Hessian when asked.
double segment_distance_squared(const Vec12& q, SegmentDistanceType type, Vec12* g = nullptr, Mat12* H = nullptr);

// The squared closest distance (type from closest_pair), with derivatives when asked.
double segment_distance_squared(const Vec12& q, Vec12* g = nullptr, Mat12* H = nullptr,
                                SegmentDistanceType* type = nullptr);

// The closest distance itself (no derivatives), for collision detection.
double segment_distance(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& b0,
                        const Eigen::Vector3d& b1);

}  // namespace yarnhom::numerics
