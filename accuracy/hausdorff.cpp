#include "accuracy/hausdorff.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "accuracy/point_triangle.hpp"

namespace yarnhom {

namespace {

// A uniform grid of cubic cells over a box, each cell listing the items whose bounding boxes
// overlap it; nearest-item queries visit rings of cells of growing Chebyshev radius and stop
// once the nearest item found is closer than any cell of the next ring can be.
struct Grid {
  Eigen::Vector3d lo;
  double h = 1;
  int n[3] = {1, 1, 1};
  std::vector<std::vector<int>> cells;

  Grid(const Eigen::Vector3d& lo_, const Eigen::Vector3d& hi_, size_t items) : lo(lo_) {
    const Eigen::Vector3d e = (hi_ - lo_).cwiseMax(0.0);
    const double emax = std::max(e.maxCoeff(), 1e-12);
    // The cell size that gives about one cell per item (at most 2 million cells).
    const double target = std::clamp(double(items), 1.0, 2e6);
    double a = emax / std::cbrt(target) * 1e-3, b = emax;
    for (int it = 0; it < 60; ++it) {
      const double m = std::sqrt(a * b);
      double c = 1;
      for (int k = 0; k < 3; ++k) c *= std::max(1.0, std::ceil(e[k] / m));
      (c > target ? a : b) = m;
    }
    h = b;
    for (int k = 0; k < 3; ++k) n[k] = std::max(1, int(std::ceil(e[k] / h)));
    cells.resize(size_t(n[0]) * n[1] * n[2]);
  }
  int coord(double x, int k) const { return std::clamp(int(std::floor((x - lo[k]) / h)), 0, n[k] - 1); }
  size_t index(int i, int j, int k) const { return (size_t(i) * n[1] + j) * n[2] + k; }
  void insert(int item, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    for (int i = coord(a[0], 0); i <= coord(b[0], 0); ++i)
      for (int j = coord(a[1], 1); j <= coord(b[1], 1); ++j)
        for (int k = coord(a[2], 2); k <= coord(b[2], 2); ++k) cells[index(i, j, k)].push_back(item);
  }
  // Smallest dist(item) over the items; dist returns a distance.
  template <class Dist>
  double nearest(const Eigen::Vector3d& p, Dist dist) const {
    const int c[3] = {coord(p[0], 0), coord(p[1], 1), coord(p[2], 2)};
    const int rmax = std::max({n[0], n[1], n[2]});
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r <= rmax; ++r) {
      for (int i = c[0] - r; i <= c[0] + r; ++i) {
        if (i < 0 || i >= n[0]) continue;
        for (int j = c[1] - r; j <= c[1] + r; ++j) {
          if (j < 0 || j >= n[1]) continue;
          for (int k = c[2] - r; k <= c[2] + r; ++k) {
            if (k < 0 || k >= n[2]) continue;
            if (std::max({std::abs(i - c[0]), std::abs(j - c[1]), std::abs(k - c[2])}) != r) continue;
            for (int item : cells[index(i, j, k)]) best = std::min(best, dist(item));
          }
        }
      }
      // Every cell of ring r + 1 is at least r h away from p (p lies inside its own cell).
      if (best <= r * h) break;
    }
    return best;
  }
};

void bounds(const Eigen::Matrix3Xd& A, Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  if (A.cols() == 0) return;
  lo = lo.cwiseMin(A.rowwise().minCoeff());
  hi = hi.cwiseMax(A.rowwise().maxCoeff());
}

}  // namespace

Eigen::VectorXd point_mesh_distances(const Eigen::Matrix3Xd& P, const Eigen::Matrix3Xd& V, const Eigen::Matrix3Xi& F) {
  if (F.cols() == 0) throw std::invalid_argument("point_mesh_distances: the mesh has no triangles");
  if (F.minCoeff() < 0 || F.maxCoeff() >= V.cols()) throw std::invalid_argument("point_mesh_distances: face index out of range");
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  bounds(P, lo, hi);
  bounds(V, lo, hi);
  Grid g(lo, hi, size_t(F.cols()));
  for (Eigen::Index t = 0; t < F.cols(); ++t) {
    Eigen::Vector3d a = V.col(F(0, t)), b = a;
    for (int k = 1; k < 3; ++k) {
      a = a.cwiseMin(V.col(F(k, t)));
      b = b.cwiseMax(V.col(F(k, t)));
    }
    g.insert(int(t), a, b);
  }
  Eigen::VectorXd d(P.cols());
#pragma omp parallel for schedule(dynamic, 64)
  for (Eigen::Index i = 0; i < P.cols(); ++i) {
    const Eigen::Vector3d p = P.col(i);
    d[i] = g.nearest(p, [&](int t) {
      return point_triangle_distance(p, V.col(F(0, t)), V.col(F(1, t)), V.col(F(2, t)));
    });
  }
  return d;
}

Eigen::VectorXd nearest_point_distances(const Eigen::Matrix3Xd& Q, const Eigen::Matrix3Xd& P) {
  if (P.cols() == 0) throw std::invalid_argument("nearest_point_distances: no points");
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  bounds(P, lo, hi);
  bounds(Q, lo, hi);
  Grid g(lo, hi, size_t(P.cols()));
  for (Eigen::Index i = 0; i < P.cols(); ++i) g.insert(int(i), P.col(i), P.col(i));
  Eigen::VectorXd d(Q.cols());
#pragma omp parallel for schedule(dynamic, 64)
  for (Eigen::Index i = 0; i < Q.cols(); ++i) {
    const Eigen::Vector3d q = Q.col(i);
    d[i] = g.nearest(q, [&](int j) { return (q - P.col(j)).norm(); });
  }
  return d;
}

Eigen::Matrix3Xd sample_surface(const Eigen::Matrix3Xd& V, const Eigen::Matrix3Xi& F, double spacing) {
  if (!(spacing > 0)) throw std::invalid_argument("sample_surface: spacing must be positive");
  std::vector<Eigen::Vector3d> s;
  for (Eigen::Index v = 0; v < V.cols(); ++v) s.push_back(V.col(v));
  for (Eigen::Index t = 0; t < F.cols(); ++t) {
    const Eigen::Vector3d a = V.col(F(0, t)), b = V.col(F(1, t)), c = V.col(F(2, t));
    const double lmax = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int k = std::max(1, int(std::ceil(lmax / spacing)));
    // Barycentric (i, j, k - i - j)/k, without the three corners (they are vertices). Points on
    // a shared edge are sampled by both triangles: harmless for a maximum.
    for (int i = 0; i <= k; ++i)
      for (int j = 0; i + j <= k; ++j) {
        if ((i == k) || (j == k) || (i + j == 0)) continue;
        s.push_back((double(i) * b + double(j) * c + double(k - i - j) * a) / k);
      }
  }
  Eigen::Matrix3Xd out(3, s.size());
  for (size_t i = 0; i < s.size(); ++i) out.col(Eigen::Index(i)) = s[i];
  return out;
}

HausdorffDistance hausdorff(const Eigen::Matrix3Xd& P, const Eigen::Matrix3Xd& V, const Eigen::Matrix3Xi& F,
                            double spacing) {
  HausdorffDistance h;
  const Eigen::VectorXd dp = point_mesh_distances(P, V, F);
  h.points_to_surface = dp.size() ? dp.maxCoeff(&h.worst_point) : 0.0;
  h.mean_points_to_surface = dp.size() ? dp.mean() : 0.0;
  const Eigen::Matrix3Xd S = sample_surface(V, F, spacing);
  const Eigen::VectorXd ds = nearest_point_distances(S, P);
  Eigen::Index worst = 0;
  h.surface_to_points = ds.size() ? ds.maxCoeff(&worst) : 0.0;
  if (ds.size()) h.worst_surface_sample = S.col(worst);
  h.symmetric = std::max(h.points_to_surface, h.surface_to_points);
  return h;
}

}  // namespace yarnhom
