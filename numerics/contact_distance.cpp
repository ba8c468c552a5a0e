#include "numerics/contact_distance.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace yarnhom::numerics {

const char* to_string(PointTriangleType t) {
  switch (t) {
    case PointTriangleType::kT0: return "p-t0";
    case PointTriangleType::kT1: return "p-t1";
    case PointTriangleType::kT2: return "p-t2";
    case PointTriangleType::kE01: return "p-e01";
    case PointTriangleType::kE12: return "p-e12";
    case PointTriangleType::kE20: return "p-e20";
    case PointTriangleType::kInterior: return "p-t";
  }
  return "?";
}

namespace {
using V = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

M3 cross_matrix(const V& a) {
  M3 m;
  m << 0, -a[2], a[1], a[2], 0, -a[0], -a[1], a[0], 0;
  return m;
}

// Point-segment pair as a degenerate segment pair [p, p, e0, e1] of a fixed type (a0-b0,
// a0-b1 or a0-b); derivatives folded onto p (the a0 and a1 slots are the same point).
double point_edge(const V& p, const V& e0, const V& e1, SegmentDistanceType type, Eigen::Matrix<double, 9, 1>* g,
                  Eigen::Matrix<double, 9, 9>* H) {
  Vec12 q, gs;
  Mat12 Hs;
  q.segment<3>(0) = p;
  q.segment<3>(3) = p;
  q.segment<3>(6) = e0;
  q.segment<3>(9) = e1;
  const double D = segment_distance_squared(q, type, g ? &gs : nullptr, H ? &Hs : nullptr);
  // S (12 x 9) maps (p, e0, e1) to (a0, a1, b0, b1): fold rows/columns 0-2 and 3-5.
  if (g) {
    g->segment<3>(0) = gs.segment<3>(0) + gs.segment<3>(3);
    g->segment<6>(3) = gs.segment<6>(6);
  }
  if (H) {
    Eigen::Matrix<double, 12, 9> S = Eigen::Matrix<double, 12, 9>::Zero();
    S.block<3, 3>(0, 0).setIdentity();
    S.block<3, 3>(3, 0).setIdentity();
    S.block<6, 6>(6, 3).setIdentity();
    *H = S.transpose() * Hs * S;
  }
  return D;
}
}  // namespace

PointTriangleClosest point_triangle_closest(const V& p, const V& a, const V& b, const V& c) {
  // Ericson, Real-Time Collision Detection, 5.1.5: the Voronoi region of p.
  PointTriangleClosest r;
  const V ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {PointTriangleType::kT0, V(1, 0, 0)};
  const V bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {PointTriangleType::kT1, V(0, 1, 0)};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {PointTriangleType::kE01, V(1 - v, v, 0)};
  }
  const V cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {PointTriangleType::kT2, V(0, 0, 1)};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {PointTriangleType::kE20, V(1 - w, 0, w)};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {PointTriangleType::kE12, V(0, 1 - w, w)};
  }
  const double den = va + vb + vc;
  if (!(std::abs(den) > 0)) {  // a degenerate (zero-area) triangle: its nearest edge
    double best = INFINITY;
    for (int e = 0; e < 3; ++e) {
      const V& u = e == 0 ? a : (e == 1 ? b : c);
      const V& w = e == 0 ? b : (e == 1 ? c : a);
      const V d = w - u;
      const double t = d.squaredNorm() > 0 ? std::clamp((p - u).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
      const double dist = (p - u - t * d).squaredNorm();
      if (dist < best) {
        best = dist;
        r.type = e == 0 ? PointTriangleType::kE01 : (e == 1 ? PointTriangleType::kE12 : PointTriangleType::kE20);
        r.bary.setZero();
        r.bary[e] = 1 - t;
        r.bary[(e + 1) % 3] = t;
      }
    }
    return r;
  }
  const double v = vb / den, w = vc / den;
  return {PointTriangleType::kInterior, V(1 - v - w, v, w)};
}

double point_triangle_distance_squared(const Vec12& q, PointTriangleType type, Vec12* g, Mat12* H) {
  const V p = q.segment<3>(0), t[3] = {q.segment<3>(3), q.segment<3>(6), q.segment<3>(9)};
  if (g) g->setZero();
  if (H) H->setZero();
  switch (type) {
    case PointTriangleType::kT0:
    case PointTriangleType::kT1:
    case PointTriangleType::kT2: {
      const int i = int(type);
      const V r = p - t[i];
      if (g) {
        g->segment<3>(0) = 2 * r;
        g->segment<3>(3 + 3 * i) = -2 * r;
      }
      if (H) {
        H->block<3, 3>(0, 0).diagonal().setConstant(2);
        H->block<3, 3>(3 + 3 * i, 3 + 3 * i).diagonal().setConstant(2);
        H->block<3, 3>(0, 3 + 3 * i).diagonal().setConstant(-2);
        H->block<3, 3>(3 + 3 * i, 0).diagonal().setConstant(-2);
      }
      return r.squaredNorm();
    }
    case PointTriangleType::kE01:
    case PointTriangleType::kE12:
    case PointTriangleType::kE20: {
      const int i = int(type) - 3, j = (i + 1) % 3;
      const V e = t[j] - t[i];
      const double s = (p - t[i]).dot(e) / e.squaredNorm();
      // The type's formula is the interior of the edge (free parameter); the classification
      // picked it only where 0 < s < 1, but the smooth formula holds beyond.
      (void)s;
      Eigen::Matrix<double, 9, 1> gl;
      Eigen::Matrix<double, 9, 9> Hl;
      const double D = point_edge(p, t[i], t[j], SegmentDistanceType::kA0B, g ? &gl : nullptr, H ? &Hl : nullptr);
      const int slot[3] = {0, 1 + i, 1 + j};
      if (g)
        for (int a = 0; a < 3; ++a) g->segment<3>(3 * slot[a]) = gl.segment<3>(3 * a);
      if (H)
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) H->block<3, 3>(3 * slot[a], 3 * slot[b]) = Hl.block<3, 3>(3 * a, 3 * b);
      return D;
    }
    case PointTriangleType::kInterior: break;
  }
  const V w = p - t[0], e1 = t[1] - t[0], e2 = t[2] - t[0];
  const V N = e1.cross(e2);
  const double s = w.dot(N), Q = N.squaredNorm();
  const double D = s * s / Q;
  if (!g && !H) return D;
  using V9 = Eigen::Matrix<double, 9, 1>;
  using M9 = Eigen::Matrix<double, 9, 9>;
  V9 ds, dQ;
  ds.segment<3>(0) = N;
  ds.segment<3>(3) = e2.cross(w);
  ds.segment<3>(6) = w.cross(e1);
  dQ.segment<3>(0).setZero();
  dQ.segment<3>(3) = 2 * e2.cross(N);
  dQ.segment<3>(6) = 2 * N.cross(e1);
  const V9 gu = (2 * s / Q) * ds - (s * s / (Q * Q)) * dQ;
  // u = M q: w = p - t0, e1 = t1 - t0, e2 = t2 - t0.
  Eigen::Matrix<double, 9, 12> Mq = Eigen::Matrix<double, 9, 12>::Zero();
  for (int k = 0; k < 3; ++k) {
    Mq.block<3, 3>(3 * k, 3).diagonal().setConstant(-1);
    Mq.block<3, 3>(3 * k, 3 * (k == 0 ? 0 : k + 1)).diagonal().setConstant(1);
  }
  if (g) *g = Mq.transpose() * gu;
  if (H) {
    M9 Hs = M9::Zero(), HQ = M9::Zero();
    Hs.block<3, 3>(0, 3) = -cross_matrix(e2);
    Hs.block<3, 3>(0, 6) = cross_matrix(e1);
    Hs.block<3, 3>(3, 6) = -cross_matrix(w);
    Hs.block<3, 3>(3, 0) = Hs.block<3, 3>(0, 3).transpose();
    Hs.block<3, 3>(6, 0) = Hs.block<3, 3>(0, 6).transpose();
    Hs.block<3, 3>(6, 3) = Hs.block<3, 3>(3, 6).transpose();
    // d2Q = 2 J^T J + cross blocks of 4 N . (de1 x de2), J = [-[e2]x, [e1]x] (dN = J (de1, de2)).
    Eigen::Matrix<double, 3, 6> J;
    J << -cross_matrix(e2), cross_matrix(e1);
    HQ.block<6, 6>(3, 3) = 2 * J.transpose() * J;
    HQ.block<3, 3>(3, 6) += -2 * cross_matrix(N);
    HQ.block<3, 3>(6, 3) += 2 * cross_matrix(N);
    const M9 Hu = (2 * ds * ds.transpose() + 2 * s * Hs) / Q -
                  (2 * s / (Q * Q)) * (ds * dQ.transpose() + dQ * ds.transpose()) - (s * s / (Q * Q)) * HQ +
                  (2 * s * s / (Q * Q * Q)) * dQ * dQ.transpose();
    *H = Mq.transpose() * Hu * Mq;
  }
  return D;
}

double point_triangle_distance_squared(const Vec12& q, Vec12* g, Mat12* H, PointTriangleType* type) {
  const PointTriangleClosest c = point_triangle_closest(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
  if (type) *type = c.type;
  if (!g && !H)
    return (q.segment<3>(0) - c.bary[0] * q.segment<3>(3) - c.bary[1] * q.segment<3>(6) - c.bary[2] * q.segment<3>(9))
        .squaredNorm();
  return point_triangle_distance_squared(q, c.type, g, H);
}

double point_triangle_distance(const V& p, const V& t0, const V& t1, const V& t2) {
  const PointTriangleClosest c = point_triangle_closest(p, t0, t1, t2);
  return (p - c.bary[0] * t0 - c.bary[1] * t1 - c.bary[2] * t2).norm();
}

double contact_distance_squared(ContactKind kind, const Vec12& q, Vec12* g, Mat12* H) {
  return kind == ContactKind::PointTriangle ? point_triangle_distance_squared(q, g, H)
                                            : segment_distance_squared(q, g, H);
}

double contact_distance(ContactKind kind, const Vec12& q) {
  if (kind == ContactKind::PointTriangle)
    return point_triangle_distance(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
  return segment_distance(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
}

Eigen::Vector4d contact_weights(ContactKind kind, const Vec12& q) {
  if (kind == ContactKind::PointTriangle) {
    const PointTriangleClosest c = point_triangle_closest(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
    return {1.0, -c.bary[0], -c.bary[1], -c.bary[2]};
  }
  const ClosestPair cp = closest_pair(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q.segment<3>(9));
  return {1 - cp.s, cp.s, -(1 - cp.t), -cp.t};
}

namespace {

// 2D: does segment a0-a1 meet triangle t (closed)? Coordinates already projected.
double orient2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
}
bool segments_meet_2d(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, const Eigen::Vector2d& q0,
                      const Eigen::Vector2d& q1) {
  const double o1 = orient2d(p0, p1, q0), o2 = orient2d(p0, p1, q1), o3 = orient2d(q0, q1, p0),
               o4 = orient2d(q0, q1, p1);
  auto on = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= c.y() &&
           c.y() <= std::max(a.y(), b.y());
  };
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return true;
  return (o1 == 0 && on(p0, p1, q0)) || (o2 == 0 && on(p0, p1, q1)) || (o3 == 0 && on(q0, q1, p0)) ||
         (o4 == 0 && on(q0, q1, p1));
}
bool point_in_triangle_2d(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                          const Eigen::Vector2d& c) {
  const double o1 = orient2d(a, b, p), o2 = orient2d(b, c, p), o3 = orient2d(c, a, p);
  return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}
}  // namespace

bool segment_triangle_intersect(const V& a0, const V& a1, const V& t0, const V& t1, const V& t2) {
  // Signed distances of the ends from the triangle's plane; within 1e-12 of the sizes involved
  // they count as on it (rounding decides nothing there: a nearly coplanar pair is tested in 2D).
  const V N = (t1 - t0).cross(t2 - t0);
  const double nn = N.norm();
  if (!(nn > 0)) return false;  // a degenerate triangle has no interior to cross
  const double L = std::max({(t1 - t0).norm(), (t2 - t1).norm(), (t0 - t2).norm(), (a1 - a0).norm()});
  const double tol = 1e-12 * L;
  const double d0 = N.dot(a0 - t0) / nn, d1 = N.dot(a1 - t0) / nn;
  if ((d0 > tol && d1 > tol) || (d0 < -tol && d1 < -tol)) return false;
  Eigen::Index k;
  N.cwiseAbs().maxCoeff(&k);
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  auto P = [&](const V& v) { return Eigen::Vector2d(v[i], v[j]); };
  const bool on0 = std::abs(d0) <= tol, on1 = std::abs(d1) <= tol;
  if (on0 && on1) {
    // Coplanar: drop the normal's largest coordinate and test in 2D.
    if (point_in_triangle_2d(P(a0), P(t0), P(t1), P(t2)) || point_in_triangle_2d(P(a1), P(t0), P(t1), P(t2)))
      return true;
    return segments_meet_2d(P(a0), P(a1), P(t0), P(t1)) || segments_meet_2d(P(a0), P(a1), P(t1), P(t2)) ||
           segments_meet_2d(P(a0), P(a1), P(t2), P(t0));
  }
  // The segment crosses (or touches) the plane at one point: is it inside the triangle (closed)?
  const V p = on0 ? a0 : (on1 ? a1 : V(a0 + (d0 / (d0 - d1)) * (a1 - a0)));
  return point_in_triangle_2d(P(p), P(t0), P(t1), P(t2));
}

bool triangles_intersect(const V& a0, const V& a1, const V& a2, const V& b0, const V& b1, const V& b2) {
  const V a[3] = {a0, a1, a2}, b[3] = {b0, b1, b2};
  for (int i = 0; i < 3; ++i) {
    if (segment_triangle_intersect(a[i], a[(i + 1) % 3], b0, b1, b2)) return true;
    if (segment_triangle_intersect(b[i], b[(i + 1) % 3], a0, a1, a2)) return true;
  }
  return false;
}

}  // namespace yarnhom::numerics
