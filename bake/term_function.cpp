#include "bake/term_function.hpp"

#include "core/jet_layout.hpp"
#include "cpu/network_eval.hpp"

namespace yarnhom {

TermFunction network_function(const ModelNetwork& net) {
  return [net](const double* s, int n, int order) {
    return cpu::eval_network_physical(net, s, n, order);
  };
}

TermFunction axis_projection(const TermFunction& f, int dim) {
  if (dim != 2) return f;
  return [f](const double* s, int n, int order) {
    std::vector<double> out = f(s, n, order);
    // The same points on the x axis (y = 0), on the y axis (x = 0), and the origin.
    std::vector<double> sx(size_t(2) * n), sy(size_t(2) * n);
    for (int p = 0; p < n; ++p) {
      sx[2 * p] = s[2 * p];
      sx[2 * p + 1] = 0;
      sy[2 * p] = 0;
      sy[2 * p + 1] = s[2 * p + 1];
    }
    const double origin[2] = {0, 0};
    const std::vector<double> ax = f(sx.data(), n, order), ay = f(sy.data(), n, order), o = f(origin, 1, 0);
    const int C = jet_channels(2, order);
    for (int c = 0; c < C; ++c) {
      // Channel c's derivative orders (core/jet_layout.hpp): total order and b = number of y's.
      const int total = c == 0 ? 0 : c <= 2 ? 1 : c <= 5 ? 2 : 3;
      const int b = c == 0 ? 0 : c <= 2 ? c - 1 : c <= 5 ? c - 3 : c - 6, a = total - b;
      for (int p = 0; p < n; ++p) {
        double& v = out[size_t(c) * n + p];
        if (b == 0) v -= ax[size_t(c) * n + p];
        if (a == 0) v -= ay[size_t(c) * n + p];
        if (c == 0) v += o[0];
      }
    }
    return out;
  };
}

TermFunction material_function(const ModelNetwork& net) {
  const bool contains_origin = net.term.dim() == 2 && net.lower.size() == 2 && net.upper.size() == 2 &&
                               net.lower[0] <= 0 && net.upper[0] >= 0 && net.lower[1] <= 0 && net.upper[1] >= 0;
  return contains_origin ? axis_projection(network_function(net), 2) : network_function(net);
}

TermFunction baked_function(const BakedTerm& term) {
  return [term](const double* s, int n, int order) {
    const int d = term.dim, C = jet_channels(d, order);
    std::vector<double> out(size_t(C) * n);
    double jet[kMaxJetChannels];
    for (int p = 0; p < n; ++p) {
      eval_baked_jet(term, s + size_t(p) * d, order, jet);
      for (int c = 0; c < C; ++c) out[size_t(c) * n + p] = jet[c];
    }
    return out;
  };
}

}  // namespace yarnhom
