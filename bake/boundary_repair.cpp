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

void repair_1d(BakedTable& t, BoundaryRepair& rep) {
  const double lo = t.lower[0], hi = t.upper[0];
  const int n = t.knots[0];
  const double h = (hi - lo) / (n - 1), w = layer_width(lo, hi, n);
  for (int e = 0; e < 2; ++e) {
    const bool upper = e == 1;
    const double sigma = upper ? 1.0 : -1.0;
    SideRepair side;
    side.knots = 1;
    double s, c;
    end_jet_1d(t.f, t.f_x, h, upper, s, c);
    if (s >= 0 && c >= 0) {
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
    const double s_target = std::max(s, 0.0), c_target = std::max(c, 0.0);
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
    side.max_slope_raise = alpha;
    rep.sides.push_back(side);
  }
}

// One edge of a 2D table: axis a (0: x edge, the boundary x = const), upper or lower side.
void repair_edge(BakedTable& t, int a, bool upper, BoundaryRepair& rep) {
  const int b = 1 - a;
  const int na = t.knots[a], nb = t.knots[b], n1 = t.knots[1];
  const double sigma = upper ? 1.0 : -1.0;
  const double hb = (t.upper[b] - t.lower[b]) / (nb - 1);
  const int ib = upper ? na - 1 : 0;
  auto idx = [&](int ia, int jb) { return a == 0 ? size_t(ia) * n1 + jb : size_t(jb) * n1 + ia; };
  std::vector<double>& slope = a == 0 ? t.f_x : t.f_y;  // derivative across the edge
  // Outward slope v along the edge and its along-edge derivative times hb (Hermite scaling).
  std::vector<double> v(nb), m(nb);
  for (int j = 0; j < nb; ++j) {
    v[j] = sigma * slope[idx(ib, j)];
    m[j] = sigma * t.f_xy[idx(ib, j)] * hb;
  }
  std::vector<double> v2 = v, m2 = m;
  std::vector<char> adjusted(nb, 0);
  auto adjust = [&](int j) {
    if (adjusted[j]) return;
    adjusted[j] = 1;
    if (j == 0) {
      v2[j] = std::max({v[j], 0.0, -m[j] / 3});
    } else if (j == nb - 1) {
      v2[j] = std::max({v[j], 0.0, m[j] / 3});
    } else {
      v2[j] = std::max(v[j], 0.0);
      m2[j] = std::clamp(m[j], -3 * v2[j], 3 * v2[j]);
    }
  };
  for (bool again = true; again;) {
    again = false;
    for (int j = 0; j + 1 < nb; ++j) {
      if (adjusted[j] && adjusted[j + 1]) continue;
      if (hermite_piece_min(v2[j], m2[j], v2[j + 1], m2[j + 1]) < 0) {
        adjust(j);
        adjust(j + 1);
        again = true;
      }
    }
  }
  SideRepair side;
  side.knots = nb;
  std::vector<double> delta(nb), ddelta(nb);
  for (int j = 0; j < nb; ++j) {
    delta[j] = v2[j] - v[j];
    ddelta[j] = (m2[j] - m[j]) / hb;
    if (delta[j] > 1e-9 * std::abs(v[j]) + 1e-12 * std::abs(m[j]) + 1e-300) {
      ++side.repaired;
      side.max_slope_raise = std::max(side.max_slope_raise, delta[j]);
    }
  }
  rep.sides.push_back(side);
  if (side.repaired == 0 && std::all_of(ddelta.begin(), ddelta.end(), [](double d) { return d == 0; })) return;
  const double w = layer_width(t.lower[a], t.upper[a], na);
  std::vector<double>& across = a == 0 ? t.f_x : t.f_y;  // d/d(axis a)
  std::vector<double>& along = a == 0 ? t.f_y : t.f_x;   // d/d(axis b)
  for (int i = 0; i < na; ++i) {
    const double xi = layer_xi(t.lower[a], t.upper[a], na, i, upper, w);
    if (xi <= 0) continue;
    const double r = w * rho1(xi), dr = sigma * drho1(xi);
    for (int j = 0; j < nb; ++j) {
      if (delta[j] == 0 && ddelta[j] == 0) continue;
      const size_t q = idx(i, j);
      const double df = delta[j] * r;
      t.f[q] += df;
      across[q] += delta[j] * dr;
      along[q] += ddelta[j] * r;
      t.f_xy[q] += ddelta[j] * dr;
      rep.max_change = std::max(rep.max_change, std::abs(df));
    }
  }
}

}  // namespace

double hermite_piece_min(double v0, double m0, double v1, double m1) {
  const double a0 = v0, a1 = m0, a2 = -3 * v0 - 2 * m0 + 3 * v1 - m1, a3 = 2 * v0 + m0 - 2 * v1 + m1;
  auto p = [&](double u) { return a0 + u * (a1 + u * (a2 + u * a3)); };
  double lo = std::min(v0, v1);
  // Critical points: a1 + 2 a2 u + 3 a3 u^2 = 0 in (0, 1).
  const double A = 3 * a3, B = 2 * a2, C = a1;
  if (A == 0) {
    if (B != 0) {
      const double u = -C / B;
      if (u > 0 && u < 1) lo = std::min(lo, p(u));
    }
  } else {
    const double disc = B * B - 4 * A * C;
    if (disc >= 0) {
      const double sq = std::sqrt(disc);
      for (double u : {(-B + sq) / (2 * A), (-B - sq) / (2 * A)})
        if (u > 0 && u < 1) lo = std::min(lo, p(u));
    }
  }
  return lo;
}

BoundaryRepair repair_boundary(BakedTable& t) {
  BoundaryRepair rep;
  rep.layer_fraction = kLayerFraction;
  if (t.f.empty()) return rep;
  const auto [mn, mx] = std::minmax_element(t.f.begin(), t.f.end());
  rep.range = *mx - *mn;
  if (t.dim() == 1) {
    repair_1d(t, rep);
    return rep;
  }
  repair_edge(t, 0, false, rep);
  repair_edge(t, 0, true, rep);
  repair_edge(t, 1, false, rep);
  repair_edge(t, 1, true, rep);
  return rep;
}

}  // namespace yarnhom
