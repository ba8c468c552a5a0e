#pragma once
// Random network parameters for tests: uniform in +-1.5/sqrt(fan_in), large enough that every
// sigmoid works in its curved range, so that higher derivatives are far from zero.
#include <cmath>
#include <random>
#include <vector>

#include "core/network.hpp"

namespace yarnhom::test {

template <class T = double>
std::vector<T> random_params(const NetworkDesc& desc, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<T> p(desc.num_params());
  for (int k = 0; k < desc.num_layers(); ++k) {
    const double a = 1.5 / std::sqrt(double(desc.layer_in(k))) + (k == 0 ? 1.0 : 0.0);
    std::uniform_real_distribution<double> u(-a, a);
    const int n = desc.layer_out(k) * (desc.layer_in(k) + 1);
    for (int i = 0; i < n; ++i) p[desc.weight_offset(k) + i] = T(u(rng));
  }
  return p;
}

}  // namespace yarnhom::test
