#include "bake/bake_table.hpp"

#include <stdexcept>

#include "core/jet_layout.hpp"

namespace yarnhom {

BakedTable bake_function(const Term& term, const std::vector<double>& lower,
                         const std::vector<double>& upper, const std::vector<int>& knots,
                         const TermFunction& f) {
  const int d = term.dim();
  if (lower.size() != size_t(d) || upper.size() != size_t(d) || knots.size() != size_t(d))
    throw std::invalid_argument("bake '" + term.name + "': box or knot counts of the wrong size");
  for (int k = 0; k < d; ++k) {
    if (knots[k] < 2) throw std::invalid_argument("bake '" + term.name + "': need at least 2 knots per axis");
    if (!(lower[k] < upper[k])) throw std::invalid_argument("bake '" + term.name + "': empty box");
  }
  BakedTable t;
  t.term = term;
  t.lower = lower;
  t.upper = upper;
  t.knots = knots;
  const int n = static_cast<int>(t.num_knots());
  std::vector<double> s(size_t(n) * d);
  if (d == 1) {
    for (int i = 0; i < n; ++i) s[i] = knot_position(lower[0], upper[0], n, i);
    // Order 1 is all the cubic Hermite table stores.
    auto jet = f(s.data(), n, 1);
    t.f.assign(jet.begin(), jet.begin() + n);
    t.f_x.assign(jet.begin() + n, jet.begin() + 2 * n);
  } else {
    const int n0 = knots[0], n1 = knots[1];
    for (int i = 0; i < n0; ++i)
      for (int j = 0; j < n1; ++j) {
        s[2 * (size_t(i) * n1 + j)] = knot_position(lower[0], upper[0], n0, i);
        s[2 * (size_t(i) * n1 + j) + 1] = knot_position(lower[1], upper[1], n1, j);
      }
    // Order 2 for the mixed derivative f_xy, channel jet_ch2(2, 0, 1).
    auto jet = f(s.data(), n, 2);
    auto channel = [&](int c) { return std::vector<double>(jet.begin() + size_t(c) * n, jet.begin() + size_t(c + 1) * n); };
    t.f = channel(0);
    t.f_x = channel(1);
    t.f_y = channel(2);
    t.f_xy = channel(jet_ch2(2, 0, 1));
  }
  compute_safeguard(t);
  return t;
}

BakedTable bake_network(const ModelNetwork& net, int res1d, int res2d) {
  const int d = net.term.dim();
  std::vector<int> knots(d, d == 1 ? res1d : res2d);
  BakedTable t = bake_function(net.term, net.lower, net.upper, knots, network_function(net));
  t.desc = net.desc;
  t.norm = net.norm;
  t.epochs = net.epochs;
  t.backend = net.backend;
  t.status = net.status;
  return t;
}

BakedModel bake_model(const Model& model, const std::string& model_path, int res1d, int res2d,
                      double psi0, bool psi0_known) {
  BakedModel b;
  b.model = model_path;
  b.dataset = model.dataset;
  b.psi0 = psi0;
  b.psi0_known = psi0_known;
  b.areal_density = model.areal_density;
  for (const ModelNetwork& net : model.networks) b.tables.push_back(bake_network(net, res1d, res2d));
  return b;
}

}  // namespace yarnhom
