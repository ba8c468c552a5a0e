#include "produce/synthetic.hpp"

#include <cmath>
#include <stdexcept>

namespace yarnhom {

const char* const kSyntheticDefinition =
    "Psi(s) = 0.5 g(sx) + 0.8 g(sy) + 0.3 sa^2 + 0.2 sa^4 + 0.1 sx sy + 0.15 sa^2 (sx + sy) "
    "+ 0.05 sa sx^2 + 0.02 kx^2 + 0.03 ky^2 + 0.004 ka^2 + 0.002 kx^4 + 0.01 kx^2 sx "
    "+ 0.008 ky^2 sy + 0.006 kx^2 sy + 0.005 ky^2 sx + 0.004 sa^2 (kx^2 + ky^2) "
    "+ 0.003 kx ky^2 sx; g(t) = (exp(2t) - 1 - 2t)/4, (kx, ka, ky) = (II_x, II_a, II_y) / 200 "
    "[J/m^2]";

double synthetic_psi(const double s[6], double grad[6]) {
  const double sx = s[0], sa = s[1], sy = s[2];
  const double kx = s[3] / 200.0, ka = s[4] / 200.0, ky = s[5] / 200.0;
  auto g = [](double t) { return (std::exp(2 * t) - 1 - 2 * t) / 4; };
  auto dg = [](double t) { return (std::exp(2 * t) - 1) / 2; };
  const double kx2 = kx * kx, ky2 = ky * ky, sa2 = sa * sa;
  const double psi = 0.5 * g(sx) + 0.8 * g(sy) + 0.3 * sa2 + 0.2 * sa2 * sa2 + 0.1 * sx * sy +
                     0.15 * sa2 * (sx + sy) + 0.05 * sa * sx * sx + 0.02 * kx2 + 0.03 * ky2 +
                     0.004 * ka * ka + 0.002 * kx2 * kx2 + 0.01 * kx2 * sx + 0.008 * ky2 * sy +
                     0.006 * kx2 * sy + 0.005 * ky2 * sx + 0.004 * sa2 * (kx2 + ky2) +
                     0.003 * kx * ky2 * sx;
  if (grad) {
    grad[0] = 0.5 * dg(sx) + 0.1 * sy + 0.15 * sa2 + 0.1 * sa * sx + 0.01 * kx2 + 0.005 * ky2 +
              0.003 * kx * ky2;
    grad[1] = 0.6 * sa + 0.8 * sa2 * sa + 0.3 * sa * (sx + sy) + 0.05 * sx * sx +
              0.008 * sa * (kx2 + ky2);
    grad[2] = 0.8 * dg(sy) + 0.1 * sx + 0.15 * sa2 + 0.008 * ky2 + 0.006 * kx2;
    const double dkx = 0.04 * kx + 0.008 * kx2 * kx + 0.02 * kx * sx + 0.012 * kx * sy +
                       0.008 * sa2 * kx + 0.003 * ky2 * sx;
    const double dky = 0.06 * ky + 0.016 * ky * sy + 0.01 * ky * sx + 0.008 * sa2 * ky +
                       0.006 * kx * ky * sx;
    grad[3] = dkx / 200.0;
    grad[4] = 0.008 * ka / 200.0;
    grad[5] = dky / 200.0;
  }
  return psi;
}

namespace {

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) {
    v[i] = a + (b - a) * i / (n - 1);
    if (std::abs(v[i]) < 1e-12 * (b - a)) v[i] = 0.0;  // the rest state exactly, not 1e-17
  }
  return v;
}

}  // namespace

Dataset make_synthetic_dataset(const std::string& preset) {
  int n1, n2;
  if (preset == "paper") {
    n1 = 100;
    n2 = 31;
  } else if (preset == "quick") {
    n1 = 21;
    n2 = 9;
  } else {
    throw std::invalid_argument("unknown preset '" + preset + "' (quick or paper)");
  }
  Dataset ds;
  ds.pattern = "synthetic";
  ds.source = "synthetic";
  ds.note = kSyntheticDefinition;
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  ds.psi0 = synthetic_psi(zero);
  // Psi along one axis minus Psi0, and its gradient component there.
  auto along = [&](int i, double t, double* dpsi) {
    double s[6] = {0, 0, 0, 0, 0, 0}, g[6];
    s[i] = t;
    const double v = synthetic_psi(s, g) - ds.psi0;
    if (dpsi) *dpsi = g[i];
    return v;
  };
  for (const Term& term : all_terms()) {
    TermData t;
    t.term = term;
    for (int i : term.indices) {
      Range r = default_range(i);
      t.lower.push_back(r.lower);
      t.upper.push_back(r.upper);
    }
    if (term.dim() == 1) {
      const int i = term.indices[0];
      for (double a : linspace(t.lower[0], t.upper[0], n1)) {
        double d;
        const double v = along(i, a, &d);
        t.strain.push_back(a);
        t.energy.push_back(v);
        t.raw.push_back(v);
        t.gradient.push_back(d);
      }
      t.n = n1;
    } else {
      const int i = term.indices[0], j = term.indices[1];
      auto A = linspace(t.lower[0], t.upper[0], n2), Bv = linspace(t.lower[1], t.upper[1], n2);
      for (double a : A)
        for (double b : Bv) {
          double s[6] = {0, 0, 0, 0, 0, 0}, g[6];
          s[i] = a;
          s[j] = b;
          const double raw = synthetic_psi(s, g) - ds.psi0;
          double da, db;
          const double pa = along(i, a, &da), pb = along(j, b, &db);
          t.strain.push_back(a);
          t.strain.push_back(b);
          t.raw.push_back(raw);
          t.energy.push_back(raw - pa - pb);
          t.gradient.push_back(g[i] - da);
          t.gradient.push_back(g[j] - db);
        }
      t.n = n2 * n2;
    }
    ds.terms.push_back(std::move(t));
  }
  return ds;
}

}  // namespace yarnhom
