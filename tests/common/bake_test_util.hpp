#pragma once
// Shared helpers of the bake tests: a ModelNetwork with random weights over a given box (no
// trained model is needed), and analytic term functions with known derivatives.
#include <cmath>
#include <vector>

#include "bake/term_function.hpp"
#include "core/jet_layout.hpp"
#include "core/model.hpp"
#include "tests/common/random_net.hpp"

namespace yarnhom::test {

inline ModelNetwork random_model_network(const std::string& name, std::vector<double> lo,
                                         std::vector<double> hi, unsigned seed,
                                         std::vector<int> hidden = {16, 32, 16}) {
  ModelNetwork n;
  n.term = term_by_name(name);
  n.lower = lo;
  n.upper = hi;
  n.desc.input_dim = n.term.dim();
  n.desc.hidden = hidden;
  n.params = random_params<float>(n.desc, seed);
  for (size_t k = 0; k < lo.size(); ++k) {
    n.norm.center.push_back(0.5 * (lo[k] + hi[k]));
    n.norm.halfwidth.push_back(0.5 * (hi[k] - lo[k]));
  }
  n.norm.out_mean = 0.3;
  n.norm.out_std = 2.0;
  return n;
}

// A polynomial of degree <= 3 in d = 1 or 2 variables, sum c[i][j] x^i y^j (i + j <= 3), with
// its exact jet: Taylor expansions of it are known by hand.
struct Poly {
  double c[4][4] = {};
  double operator()(double x, double y, int dx, int dy) const {
    auto dpow = [](double t, int k, int m) {  // d^m/dt^m t^k
      if (m > k) return 0.0;
      double f = 1;
      for (int q = 0; q < m; ++q) f *= (k - q);
      return f * std::pow(t, k - m);
    };
    double s = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        if (c[i][j] != 0) s += c[i][j] * dpow(x, i, dx) * dpow(y, j, dy);
    return s;
  }
};

inline TermFunction poly_function(const Poly& p, int d) {
  return [p, d](const double* s, int n, int order) {
    const int C = jet_channels(d, order);
    std::vector<double> out(size_t(C) * n);
    for (int q = 0; q < n; ++q) {
      const double x = s[q * d], y = d == 2 ? s[q * d + 1] : 0.0;
      double jet[kMaxJetChannels];
      if (d == 1) {
        for (int m = 0; m <= order; ++m) jet[m] = p(x, 0, m, 0);
      } else {
        jet[0] = p(x, y, 0, 0);
        if (order >= 1) { jet[1] = p(x, y, 1, 0); jet[2] = p(x, y, 0, 1); }
        for (int k = 0; order >= 2 && k < 3; ++k) {
          JetPair e = jet_pair(2, k);
          jet[3 + k] = p(x, y, 2 - e.i - e.j, e.i + e.j);
        }
        for (int k = 0; order >= 3 && k < 4; ++k) {
          JetTriple e = jet_triple(2, k);
          const int ny = e.i + e.j + e.k;
          jet[6 + k] = p(x, y, 3 - ny, ny);
        }
      }
      for (int c = 0; c < C; ++c) out[size_t(c) * n + q] = jet[c];
    }
    return out;
  };
}

}  // namespace yarnhom::test
