#include "accuracy/fit_error.hpp"

#include <algorithm>
#include <cmath>

namespace yarnhom {

FitError fit_error(const TermFunction& f, const TermData& data) {
  const int n = data.n, d = data.dim();
  auto jet = f(data.strain.data(), n, 1);
  FitError e;
  e.n = n;
  double mean = 0, gnorm = 0;
  for (int p = 0; p < n; ++p) mean += data.energy[p] / n;
  double var = 0;
  for (int p = 0; p < n; ++p) {
    const double r = jet[p] - data.energy[p];
    e.energy_mae += std::abs(r) / n;
    e.energy_rmse += r * r / n;
    e.energy_max = std::max(e.energy_max, std::abs(r));
    var += (data.energy[p] - mean) * (data.energy[p] - mean) / n;
    double dg = 0, g = 0;
    for (int i = 0; i < d; ++i) {
      const double gi = data.gradient[size_t(p) * d + i];
      const double di = jet[size_t(1 + i) * n + p] - gi;
      dg += di * di;
      g += gi * gi;
    }
    e.grad_mae += std::sqrt(dg) / n;
    gnorm += std::sqrt(g) / n;
  }
  e.energy_rmse = std::sqrt(e.energy_rmse);
  e.energy_rel = var > 0 ? e.energy_rmse / std::sqrt(var) : 0.0;
  e.grad_rel = gnorm > 0 ? e.grad_mae / gnorm : 0.0;
  return e;
}

}  // namespace yarnhom
