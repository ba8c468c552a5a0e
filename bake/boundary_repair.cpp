#include "bake/boundary_repair.hpp"

#include <algorithm>
#include <cmath>

namespace yarnhom {

namespace {

constexpr double kLayerFraction = 0.05;

// rho1(xi) = xi^3 (xi - 1): zero with rho1', rho1'' at 0; rho1(1) = 0, rho1'(1) = 1.
inline double rho1(double t) { return t * t * t * (t - 1); }
inline double drho1(double t) { return 4 * t * t * t - 3 * t * t; }
// rho2(xi) = xi^3 (1 - xi)^2 / 2: zero with rho2', rho2'' at 0; rho2(1) = rho2'(1) = 0, rho2''(1) = 1.
inline double rho2(double t) { return 0.5 * t * t * t * (1 - t) * (1 - t); }
inline double drho2(double t) { return 0.5 * (3 * t * t * (1 - t) * (1 - t) - 2 * t * t * t * (1 - t)); }

double layer_width(double lo, double hi, int n) {
  const double W = hi - lo, h = W / (n - 1);
  return std::min(0.5 * W, std::max(kLayerFraction * W, 2 * h));
}

// Position across the layer of knot k (1 on the boundary at the end `upper`, <= 0 outside it).
double layer_xi(double lo, double hi, int n, int k, bool upper, double w) {
  const double x = k == n - 1 ? hi : lo + (hi - lo) * k / (n - 1);
  const double dist = upper ? hi - x : x - lo;
  return 1.0 - dist / w;
}

// Outward slope and curvature of a 1D table at one end, from its end cell's cubic Hermite.
void end_jet_1d(const std::vector<double>& f, const std::vector<double>& fx, double h, bool upper, double& slope,
                double& curv) {
  const int n = int(f.size());
  if (upper) {
    const double f0 = f[n - 2], f1 = f[n - 1], d0 = fx[n - 2], d1 = fx[n - 1];
    slope = d1;
    curv = (6 * (f0 - f1) + 2 * h * d0 + 4 * h * d1) / (h * h);
  } else {
    const double f0 = f[0], f1 = f[1], d0 = fx[0], d1 = fx[1];
    slope = -d0;
    curv = (6 * (f1 - f0) - 4 * h * d0 - 2 * h * d1) / (h * h);
  }
}

void repair_1d(BakedTable& t, BoundaryRepair& rep, const double* floor) {
  const double lo = t.lower[0], hi = t.upper[0];
  const int n = t.knots[0];
  const double h = (hi - lo) / (n - 1), w = layer_width(lo, hi, n);
  for (int e = 0; e < 2; ++e) {
    const bool upper = e == 1;
    const double sigma = upper ? 1.0 : -1.0;
    SideRepair side;
    side.knots = 1;
    side.curvature_floor = floor ? std::max(floor[e], 0.0) : 0.0;
    double s, c;
    end_jet_1d(t.f, t.f_x, h, upper, s, c);
    if (s >= 0 && c >= side.curvature_floor) {
      rep.sides.push_back(side);
      continue;
    }
    // The table's end slope and curvature of each basis function, sampled at the knots.
    std::vector<double> b1(n, 0.0), db1(n, 0.0), b2(n, 0.0), db2(n, 0.0);
    for (int k = 0; k < n; ++k) {
      const double xi = layer_xi(lo, hi, n, k, upper, w);
      if (xi <= 0) continue;
      b1[k] = w * rho1(xi);
      db1[k] = sigma * drho1(xi);
      b2[k] = w * w * rho2(xi);
      db2[k] = sigma * w * drho2(xi);
    }
    double s1, c1, s2, c2;
    end_jet_1d(b1, db1, h, upper, s1, c1);
    end_jet_1d(b2, db2, h, upper, s2, c2);
    const double s_target = std::max(s, 0.0), c_target = std::max(c, side.curvature_floor);
    const double alpha = (s_target - s) / s1;
    const double beta = (c_target - c - alpha * c1) / c2;
    for (int k = 0; k < n; ++k) {
      const double df = alpha * b1[k] + beta * b2[k];
      t.f[k] += df;
      t.f_x[k] += alpha * db1[k] + beta * db2[k];
      rep.max_change = std::max(rep.max_change, std::abs(df));
    }
    // Reported only when more than rounding noise (1e-9 of the table's largest slope).
    double gmax = 0;
    for (double g : t.f_x) gmax = std::max(gmax, std::abs(g));
    side.repaired = s < -1e-9 * gmax;
    side.curvature_raised = c < -1e-9 * gmax / h;
    side.floor_raised = side.curvature_floor > 0 && c < side.curvature_floor;
    side.max_slope_raise = alpha;
    rep.sides.push_back(side);
  }
}

}  // namespace

BoundaryRepair repair_boundary(BakedTable& t, const double* min_curvature) {
  BoundaryRepair rep;
  rep.layer_fraction = kLayerFraction;
  if (t.f.empty()) return rep;
  const auto [mn, mx] = std::minmax_element(t.f.begin(), t.f.end());
  rep.range = *mx - *mn;
  // A 2D table is a residual and is never changed (see the header).
  if (t.dim() == 1) repair_1d(t, rep, min_curvature);
  return rep;
}

}  // namespace yarnhom
