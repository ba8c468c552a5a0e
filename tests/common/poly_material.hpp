#pragma once
// A homogeneous test material with known derivatives: each term a polynomial of degree <= 3
// per variable, baked into Hermite tables (which reproduce such polynomials exactly inside
// their boxes), so tests can compare the simulator against the formula.
#include <map>
#include <memory>

#include "bake/bake_table.hpp"
#include "material/material.hpp"
#include "core/jet_layout.hpp"
#include "core/terms.hpp"
#include "material/material_fn.hpp"

namespace yarnhom::test {

// sum c[i][j] x^i y^j, i, j <= 3.
struct Poly2 {
  double c[4][4] = {};
  double d(double x, double y, int dx, int dy) const {
    auto dp = [](double t, int k, int m) {
      if (m > k) return 0.0;
      double f = 1;
      for (int q = 0; q < m; ++q) f *= (k - q);
      double p = 1;
      for (int q = 0; q < k - m; ++q) p *= t;
      return f * p;
    };
    double s = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        if (c[i][j] != 0) s += c[i][j] * dp(x, i, dx) * dp(y, j, dy);
    return s;
  }
};

inline TermFunction poly_term_function(const Poly2& p, int d) {
  return [p, d](const double* s, int n, int order) {
    const int C = jet_channels(d, order);
    std::vector<double> out(size_t(C) * n);
    for (int q = 0; q < n; ++q) {
      const double x = s[q * d], y = d == 2 ? s[q * d + 1] : 0.0;
      double jet[kMaxJetChannels] = {};
      if (d == 1) {
        for (int m = 0; m <= order; ++m) jet[m] = p.d(x, 0, m, 0);
      } else {
        jet[0] = p.d(x, y, 0, 0);
        if (order >= 1) {
          jet[1] = p.d(x, y, 1, 0);
          jet[2] = p.d(x, y, 0, 1);
        }
        for (int k = 0; order >= 2 && k < 3; ++k) {
          JetPair e = jet_pair(2, k);
          jet[3 + k] = p.d(x, y, 2 - e.i - e.j, e.i + e.j);
        }
        for (int k = 0; order >= 3 && k < 4; ++k) {
          JetTriple e = jet_triple(2, k);
          const int ny = e.i + e.j + e.k;
          jet[6 + k] = p.d(x, y, 3 - ny, ny);
        }
      }
      for (int c = 0; c < C; ++c) out[size_t(c) * n + q] = jet[c];
    }
    return out;
  };
}

// Terms by name; boxes are HYLC's defaults (curvatures +-200 /m) unless in_plane_lower moves
// the lower end of s_x and s_y. 1D: c[i][0]. Bake repairs a 1D term whose end slope points
// inward or curves down in a layer 5 % of the box wide (docs/bake.md): there that table is not
// the polynomial. 2D tables are the polynomial everywhere in the box.
inline BakedModel poly_baked_model(const std::map<std::string, Poly2>& terms, double psi0 = 0.0, int knots1 = 41,
                                   int knots2 = 21, double in_plane_lower = -0.2) {
  BakedModel m;
  m.psi0 = psi0;
  m.psi0_known = true;
  for (const Term& t : all_terms()) {
    auto it = terms.find(t.name);
    if (it == terms.end()) continue;
    std::vector<double> lo, hi;
    for (int i : t.indices) {
      const Range r = default_range(i, 200, 200);
      lo.push_back(i == 0 || i == 2 ? in_plane_lower : r.lower);
      hi.push_back(r.upper);
    }
    std::vector<int> knots(t.dim(), t.dim() == 1 ? knots1 : knots2);
    m.tables.push_back(bake_function(t, lo, hi, knots, poly_term_function(it->second, t.dim())));
  }
  return m;
}

// A simple cloth-like material: quadratic in-plane stiffness with a Poisson coupling and a
// cubic stiffening along x, quadratic bending. J/m^2.
inline std::map<std::string, Poly2> simple_cloth_terms() {
  std::map<std::string, Poly2> t;
  t["0"].c[2][0] = 10.0;  // 10 sx^2 + 4 sx^3
  t["0"].c[3][0] = 4.0;
  t["1"].c[2][0] = 2.0;   // shear
  t["2"].c[2][0] = 6.0;
  t["02"].c[1][1] = 3.0;  // 3 sx sy
  t["3"].c[2][0] = 2e-6;  // bending, J/m^2 per (1/m)^2
  t["5"].c[2][0] = 3e-6;
  return t;
}

inline MaterialFn poly_material_fn(const std::map<std::string, Poly2>& terms, double in_plane_lower = -0.2) {
  auto mat = std::make_shared<BakedMaterial>(make_baked_material(poly_baked_model(terms, 0.0, 41, 21, in_plane_lower)));
  return baked_material_fn(mat);
}

// simple_cloth_terms with a box that reaches s = -0.5, built once: the sim tests' scenes (a
// stretched strip's lateral contraction reaches s = -0.2 at 170 %, a drape's folds more) stay
// inside it.
inline const MaterialFn& simple_cloth_material() {
  static const MaterialFn m = poly_material_fn(simple_cloth_terms(), -0.5);
  return m;
}

}  // namespace yarnhom::test
