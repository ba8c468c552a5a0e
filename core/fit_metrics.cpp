#include "core/fit_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <stdexcept>

namespace yarnhom {

namespace {

// The half-widths of the term's box: the scale D of the box coordinate.
std::vector<double> half_widths(const TermData& data) {
  std::vector<double> h(data.dim(), 1.0);
  for (int i = 0; i < data.dim(); ++i)
    if (size_t(i) < data.lower.size() && size_t(i) < data.upper.size() && data.upper[i] > data.lower[i])
      h[i] = 0.5 * (data.upper[i] - data.lower[i]);
  return h;
}

}  // namespace

double data_inconsistency(const TermData& data, double grad_mean) {
  const int N = data.n, d = data.dim();
  if (N < 2 || !(grad_mean > 0)) return -1;
  const std::vector<double> h = half_widths(data);
  // The grid: the distinct coordinates per axis and the point at each (i, j) present.
  std::vector<std::vector<double>> axis(d);
  for (int k = 0; k < d; ++k) {
    for (int p = 0; p < N; ++p) axis[k].push_back(data.strain[size_t(p) * d + k]);
    std::sort(axis[k].begin(), axis[k].end());
    axis[k].erase(std::unique(axis[k].begin(), axis[k].end()), axis[k].end());
  }
  size_t cells = 1;
  for (int k = 0; k < d; ++k) cells *= axis[k].size();
  if (cells > 2 * size_t(N) || (d == 2 && (axis[0].size() < 2 || axis[1].size() < 2))) return -1;  // scattered
  std::map<std::pair<int, int>, int> at;
  for (int p = 0; p < N; ++p) {
    int ij[2] = {0, 0};
    for (int k = 0; k < d; ++k)
      ij[k] = int(std::lower_bound(axis[k].begin(), axis[k].end(), data.strain[size_t(p) * d + k]) - axis[k].begin());
    at[{ij[0], ij[1]}] = p;
  }
  // Trapezoid rule between neighbours along each axis, in box coordinates.
  double sum = 0;
  long pairs = 0;
  for (const auto& [ij, p] : at)
    for (int k = 0; k < d; ++k) {
      const std::pair<int, int> next = k == 0 ? std::make_pair(ij.first + 1, ij.second) : std::make_pair(ij.first, ij.second + 1);
      const auto it = at.find(next);
      if (it == at.end()) continue;
      const int q = it->second;
      const double ds = data.strain[size_t(q) * d + k] - data.strain[size_t(p) * d + k];
      const double slope = (data.energy[q] - data.energy[p]) / ds;
      const double mean_g = 0.5 * (data.gradient[size_t(p) * d + k] + data.gradient[size_t(q) * d + k]);
      const double c = h[k] * (slope - mean_g);
      sum += c * c;
      ++pairs;
    }
  if (pairs == 0) return -1;
  return std::sqrt(sum / pairs) / grad_mean;
}

FitQuality fit_quality(const TermData& data, const std::vector<double>& jet, const std::vector<int>& points) {
  const int N = data.n, d = data.dim();
  if (jet.size() < size_t(1 + d) * N)
    throw std::invalid_argument("fit_quality: the jet of term " + data.term.name + " has too few channels");
  const std::vector<double> h = half_widths(data);
  FitQuality q;
  double lo = data.energy[0], hi = data.energy[0], gsum = 0;
  for (int p = 0; p < N; ++p) {
    lo = std::min(lo, data.energy[p]);
    hi = std::max(hi, data.energy[p]);
    double g2 = 0;
    for (int i = 0; i < d; ++i) g2 += std::pow(h[i] * data.gradient[size_t(p) * d + i], 2);
    gsum += std::sqrt(g2);
  }
  q.energy_range = hi - lo;
  q.grad_mean = gsum / N;
  double gmax = 0;  // largest |dPsi| of a 1D term, for the small-stress band
  if (d == 1)
    for (int p = 0; p < N; ++p) gmax = std::max(gmax, std::abs(data.gradient[p]));
  double e2 = 0, dg2 = 0, ss2 = 0;
  auto add = [&](int p) {
    if (p < 0 || p >= N) throw std::invalid_argument("fit_quality: point index out of range for term " + data.term.name);
    const double r = jet[p] - data.energy[p];
    e2 += r * r;
    for (int i = 0; i < d; ++i) {
      const double di = h[i] * (jet[size_t(1 + i) * N + p] - data.gradient[size_t(p) * d + i]);
      dg2 += di * di;
    }
    if (d == 1) {
      const double g = data.gradient[p], a = std::abs(g);
      if (a >= kSmallStressBand[0] * gmax && a <= kSmallStressBand[1] * gmax && a > 0) {
        const double r = (jet[size_t(N) + p] - g) / a;
        ss2 += r * r;
        ++q.small_stress_n;
      }
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
  q.small_stress_rel = q.small_stress_n > 0 ? std::sqrt(ss2 / q.small_stress_n) : -1.0;
  q.data_inconsistency = data_inconsistency(data, q.grad_mean);
  return q;
}

std::string fit_rule(const FitQuality& q) {
  if (!q.ok()) return "-";
  return q.grad_within_limit() ? "limit" : "data";
}

std::string fit_verdict(const FitQuality& q) {
  char buf[200];
  if (q.ok()) {
    if (q.grad_within_limit()) return "ok";
    std::snprintf(buf, sizeof buf, "ok by the data rule: gradient error %.3g%% of the mean gradient, within %g x data G (%.3g%%)",
                  100 * q.grad_rel, kFitDataRuleFactor, 100 * q.data_inconsistency);
    return buf;
  }
  std::string out = "FAILS:";
  if (!q.energy_ok()) {
    std::snprintf(buf, sizeof buf, " energy RMSE %.3g%% of the data range (limit %g%%)", 100 * q.energy_rel,
                  100 * kFitEnergyThreshold);
    out += buf;
  }
  if (!q.grad_ok()) {
    if (q.rough_data())
      std::snprintf(buf, sizeof buf, "%s gradient error %.3g%% of the mean gradient (limit %g%%, or %g x data G = %.3g%%)",
                    q.energy_ok() ? "" : ";", 100 * q.grad_rel, 100 * kFitGradThreshold, kFitDataRuleFactor,
                    100 * kFitDataRuleFactor * q.data_inconsistency);
    else
      std::snprintf(buf, sizeof buf, "%s gradient error %.3g%% of the mean gradient (limit %g%%)", q.energy_ok() ? "" : ";",
                    100 * q.grad_rel, 100 * kFitGradThreshold);
    out += buf;
  }
  if (!q.small_stress_ok()) {
    std::snprintf(buf, sizeof buf, "%s small stresses off by %.3g%% (RMS over %d points with |dPsi| at 1-20%% of its largest; limit %g%%)",
                  q.energy_ok() && q.grad_ok() ? "" : ";", 100 * q.small_stress_rel, q.small_stress_n,
                  100 * kFitSmallStressThreshold);
    out += buf;
  }
  if (q.data_inconsistency >= kFitGradThreshold) {
    std::snprintf(buf, sizeof buf, "; the data's own gradients and energies disagree by %.3g%% of the mean gradient: not smooth data",
                  100 * q.data_inconsistency);
    out += buf;
  }
  return out;
}

}  // namespace yarnhom
