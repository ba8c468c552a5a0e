#include "bake/term_function.hpp"

#include "core/jet_layout.hpp"
#include "cpu/network_eval.hpp"

namespace yarnhom {

TermFunction network_function(const ModelNetwork& net) {
  return [net](const double* s, int n, int order) {
    return cpu::eval_network_physical(net, s, n, order);
  };
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
