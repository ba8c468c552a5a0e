#include "core/fit_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace yarnhom {

FitQuality fit_quality(const TermData& data, const std::vector<double>& jet, const std::vector<int>& points) {
  const int N = data.n, d = data.dim();
  if (jet.size() < size_t(1 + d) * N)
    throw std::invalid_argument("fit_quality: the jet of term " + data.term.name + " has too few channels");
  FitQuality q;
  double lo = data.energy[0], hi = data.energy[0], gsum = 0;
  for (int p = 0; p < N; ++p) {
    lo = std::min(lo, data.energy[p]);
    hi = std::max(hi, data.energy[p]);
    double g2 = 0;
    for (int i = 0; i < d; ++i) g2 += data.gradient[size_t(p) * d + i] * data.gradient[size_t(p) * d + i];
    gsum += std::sqrt(g2);
  }
  q.energy_range = hi - lo;
  q.grad_mean = gsum / N;
  double e2 = 0, dg2 = 0;
  auto add = [&](int p) {
    if (p < 0 || p >= N) throw std::invalid_argument("fit_quality: point index out of range for term " + data.term.name);
    const double r = jet[p] - data.energy[p];
    e2 += r * r;
    for (int i = 0; i < d; ++i) {
      const double di = jet[size_t(1 + i) * N + p] - data.gradient[size_t(p) * d + i];
      dg2 += di * di;
    }
    ++q.n;
  };
  if (points.empty())
    for (int p = 0; p < N; ++p) add(p);
  else
    for (int p : points) add(p);
  q.energy_rmse = std::sqrt(e2 / q.n);
  q.grad_rms = std::sqrt(dg2 / q.n);
  q.energy_rel = q.energy_range > 0 ? q.energy_rmse / q.energy_range : 0.0;
  q.grad_rel = q.grad_mean > 0 ? q.grad_rms / q.grad_mean : 0.0;
  return q;
}

std::string fit_verdict(const FitQuality& q) {
  if (q.ok()) return "ok";
  std::string out = "FAILS:";
  char buf[160];
  if (!q.energy_ok()) {
    std::snprintf(buf, sizeof buf, " energy RMSE %.3g%% of the data range (limit %g%%)", 100 * q.energy_rel,
                  100 * kFitEnergyThreshold);
    out += buf;
  }
  if (!q.grad_ok()) {
    std::snprintf(buf, sizeof buf, "%s gradient error %.3g%% of the mean gradient (limit %g%%)", q.energy_ok() ? "" : ";",
                  100 * q.grad_rel, 100 * kFitGradThreshold);
    out += buf;
  }
  return out;
}

}  // namespace yarnhom
