#include "numerics/segment_distance.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace yarnhom::numerics {

const char* to_string(SegmentDistanceType t) {
  switch (t) {
    case SegmentDistanceType::kA0B0: return "a0-b0";
    case SegmentDistanceType::kA0B1: return "a0-b1";
    case SegmentDistanceType::kA1B0: return "a1-b0";
    case SegmentDistanceType::kA1B1: return "a1-b1";
    case SegmentDistanceType::kA0B: return "a0-b";
    case SegmentDistanceType::kA1B: return "a1-b";
    case SegmentDistanceType::kAB0: return "a-b0";
    case SegmentDistanceType::kAB1: return "a-b1";
    case SegmentDistanceType::kAB: return "a-b";
  }
  return "?";
}

namespace {

double clamp01(double x) { return x < 0 ? 0.0 : (x > 1 ? 1.0 : x); }

// Which parameters a type leaves free, and the fixed values of the others.
struct TypeInfo {
  bool s_free, t_free;
  double s, t;  // the fixed values (ignored where free)
};

TypeInfo info(SegmentDistanceType type) {
  switch (type) {
    case SegmentDistanceType::kA0B0: return {false, false, 0, 0};
    case SegmentDistanceType::kA0B1: return {false, false, 0, 1};
    case SegmentDistanceType::kA1B0: return {false, false, 1, 0};
    case SegmentDistanceType::kA1B1: return {false, false, 1, 1};
    case SegmentDistanceType::kA0B: return {false, true, 0, 0};
    case SegmentDistanceType::kA1B: return {false, true, 1, 0};
    case SegmentDistanceType::kAB0: return {true, false, 0, 0};
    case SegmentDistanceType::kAB1: return {true, false, 0, 1};
    case SegmentDistanceType::kAB: return {true, true, 0, 0};
  }
  return {false, false, 0, 0};
}

SegmentDistanceType type_of(double s, double t) {
  const int is = s == 0 ? 0 : (s == 1 ? 1 : 2), it = t == 0 ? 0 : (t == 1 ? 1 : 2);
  static const SegmentDistanceType table[3][3] = {
      {SegmentDistanceType::kA0B0, SegmentDistanceType::kA0B1, SegmentDistanceType::kA0B},
      {SegmentDistanceType::kA1B0, SegmentDistanceType::kA1B1, SegmentDistanceType::kA1B},
      {SegmentDistanceType::kAB0, SegmentDistanceType::kAB1, SegmentDistanceType::kAB}};
  return table[is][it];
}

}  // namespace

ClosestPair closest_pair(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& b0,
                         const Eigen::Vector3d& b1) {
  // Minimizes |a0 + s ea - b0 - t eb|^2 over the unit square (a convex quadratic): the
  // unconstrained optimum of s, then the best t for it, re-optimizing s whenever t had to be
  // clamped (Ericson, Real-Time Collision Detection, 5.1.9), with explicit degenerate cases.
  const Eigen::Vector3d ea = a1 - a0, eb = b1 - b0, r = a0 - b0;
  const double a = ea.squaredNorm(), e = eb.squaredNorm(), f = eb.dot(r);
  const double tiny = 1e-30 * (a + e + r.squaredNorm()) + 1e-300;
  double s, t;
  if (a <= tiny && e <= tiny) {
    s = t = 0;
  } else if (a <= tiny) {
    s = 0;
    t = clamp01(f / e);
  } else {
    const double c = ea.dot(r);
    if (e <= tiny) {
      t = 0;
      s = clamp01(-c / a);
    } else {
      const double b = ea.dot(eb), denom = a * e - b * b;
      // Parallel (or nearly): any s of the overlap is a minimizer; take an end (s = 0).
      s = denom > kParallel * a * e ? clamp01((b * f - c * e) / denom) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = clamp01(-c / a);
      } else if (t > 1) {
        t = 1;
        s = clamp01((b - c) / a);
      }
    }
  }
  ClosestPair cp;
  cp.s = s;
  cp.t = t;
  cp.type = type_of(s, t);
  return cp;
}

double segment_distance_squared(const Vec12& q, SegmentDistanceType type, Vec12* g, Mat12* H) {
  const Eigen::Vector3d a0 = q.segment<3>(0), a1 = q.segment<3>(3), b0 = q.segment<3>(6), b1 = q.segment<3>(9);
  const Eigen::Vector3d ea = a1 - a0, eb = b1 - b0;
  const TypeInfo ti = info(type);
  double s = ti.s, t = ti.t;
  // The free parameters at the type's stationary point (unclamped: the type's own smooth
  // formula, which equals the true distance inside the type's region).
  if (ti.s_free && ti.t_free) {
    const Eigen::Vector3d w = a0 - b0;
    const double A = ea.squaredNorm(), B = ea.dot(eb), E = eb.squaredNorm();
    const double det = A * E - B * B, c = ea.dot(w), f = eb.dot(w);
    s = (B * f - c * E) / det;
    t = (A * f - B * c) / det;
  } else if (ti.s_free) {
    s = ((b0 + t * eb) - a0).dot(ea) / ea.squaredNorm();
  } else if (ti.t_free) {
    t = ((a0 + s * ea) - b0).dot(eb) / eb.squaredNorm();
  }
  const Eigen::Vector3d r = a0 + s * ea - (b0 + t * eb);
  const double D = r.squaredNorm();
  const double c[4] = {1 - s, s, -(1 - t), -t};  // r = sum_k c_k q_k
  if (g)
    for (int k = 0; k < 4; ++k) g->segment<3>(3 * k) = 2.0 * c[k] * r;
  if (H) {
    // f_qq = 2 C^T C: block (k, l) = 2 c_k c_l I.
    H->setZero();
    for (int k = 0; k < 4; ++k)
      for (int l = 0; l < 4; ++l) H->block<3, 3>(3 * k, 3 * l).diagonal().setConstant(2.0 * c[k] * c[l]);
    // Minus f_qy f_yy^-1 f_yq over the free parameters y.
    Eigen::Matrix<double, 12, 2> fqy;
    Eigen::Matrix2d fyy;
    int m = 0;
    int idx[2];
    if (ti.s_free) {
      Vec12 fqs;
      for (int k = 0; k < 4; ++k) fqs.segment<3>(3 * k) = 2.0 * c[k] * ea;
      fqs.segment<3>(0) -= 2.0 * r;
      fqs.segment<3>(3) += 2.0 * r;
      fqy.col(m) = fqs;
      idx[m++] = 0;
    }
    if (ti.t_free) {
      Vec12 fqt;
      for (int k = 0; k < 4; ++k) fqt.segment<3>(3 * k) = -2.0 * c[k] * eb;
      fqt.segment<3>(6) += 2.0 * r;
      fqt.segment<3>(9) -= 2.0 * r;
      fqy.col(m) = fqt;
      idx[m++] = 1;
    }
    if (m > 0) {
      const double full[2][2] = {{2.0 * ea.squaredNorm(), -2.0 * ea.dot(eb)}, {-2.0 * ea.dot(eb), 2.0 * eb.squaredNorm()}};
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) fyy(i, j) = full[idx[i]][idx[j]];
      if (m == 1) {
        *H -= fqy.col(0) * fqy.col(0).transpose() / fyy(0, 0);
      } else {
        const Eigen::Matrix<double, 12, 2> X = fqy * fyy.inverse();
        *H -= X * fqy.transpose();
      }
    }
  }
  return D;
}

double segment_distance_squared(const Vec12& q, Vec12* g, Mat12* H, SegmentDistanceType* type) {
  const ClosestPair cp = closest_pair(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
  if (type) *type = cp.type;
  if (!g && !H) {
    const Eigen::Vector3d r = q.segment<3>(0) + cp.s * (q.segment<3>(3) - q.segment<3>(0)) -
                              q.segment<3>(6) - cp.t * (q.segment<3>(9) - q.segment<3>(6));
    return r.squaredNorm();
  }
  return segment_distance_squared(q, cp.type, g, H);
}

double segment_distance(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& b0,
                        const Eigen::Vector3d& b1) {
  const ClosestPair cp = closest_pair(a0, a1, b0, b1);
  return (a0 + cp.s * (a1 - a0) - b0 - cp.t * (b1 - b0)).norm();
}

}  // namespace yarnhom::numerics
