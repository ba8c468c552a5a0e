#include "cpu/network_eval.hpp"

#include "core/jet_layout.hpp"
#include "cpu/mlp_jet.hpp"

namespace yarnhom::cpu {

std::vector<double> eval_network_physical(const ModelNetwork& net, const double* s, int n,
                                          int order) {
  const int d = net.desc.input_dim, C = jet_channels(d, order);
  std::vector<double> params(net.params.begin(), net.params.end());
  std::vector<double> x(size_t(n) * d);
  for (int p = 0; p < n; ++p)
    for (int i = 0; i < d; ++i)
      x[p * d + i] = (s[p * d + i] - net.norm.center[i]) / net.norm.halfwidth[i];
  std::vector<double> out(size_t(C) * n);
  JetWorkspace<double> ws;
  mlp_jet_forward<double>(net.desc, params.data(), x.data(), n, order, out.data(), ws);
  const double sigma = net.norm.out_std;
  const auto& h = net.norm.halfwidth;
  // Scale factor of every channel: sigma over the product of the half-widths of its indices.
  std::vector<double> scale(C, sigma);
  for (int i = 0; i < d && order >= 1; ++i) scale[1 + i] = sigma / h[i];
  for (int q = 0; q < jet_num_pairs(d) && order >= 2; ++q) {
    JetPair e = jet_pair(d, q);
    scale[jet_first(d, 2) + q] = sigma / (h[e.i] * h[e.j]);
  }
  for (int t = 0; t < jet_num_triples(d) && order >= 3; ++t) {
    JetTriple e = jet_triple(d, t);
    scale[jet_first(d, 3) + t] = sigma / (h[e.i] * h[e.j] * h[e.k]);
  }
  for (int c = 0; c < C; ++c)
    for (int p = 0; p < n; ++p) out[size_t(c) * n + p] *= scale[c];
  for (int p = 0; p < n; ++p) out[p] += net.norm.out_mean;
  return out;
}

}  // namespace yarnhom::cpu
