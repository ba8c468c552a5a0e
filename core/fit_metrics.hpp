#pragma once
// How well a term's function (network or baked table) fits its data, in physical meaning, and
// the thresholds a fit must meet (issue 12; docs/training.md, "Fit quality").
//
//   energy RMSE / range     sqrt(mean_p (Psi_hat(s_p) - Psi_p)^2) over the points measured,
//                           divided by max_p Psi_p - min_p Psi_p over ALL the term's points
//   gradient error / mean   sqrt(mean_p |grad Psi_hat(s_p) - grad Psi_p|^2) (Euclidean, RMS)
//                           over the points measured, divided by mean_p |grad Psi_p| over all
//                           the term's points
//
// Both are measured on the held-out validation points (the model file records which) and, for
// comparison, on all points. A term passes when its validation energy RMSE is below 3 % of
// its range and its gradient error below 10 % of its mean gradient: tighter than the fit
// between neighbouring samples of a 31 x 31 grid that a Hermite table already achieves, and
// loose enough that a term which passes is indistinguishable from its data in a simulation
// (a 3 % energy error is below the pattern-to-pattern differences of supplement Fig. 5).
#include <string>
#include <vector>

#include "core/dataset.hpp"

namespace yarnhom {

inline constexpr double kFitEnergyThreshold = 0.03;  // energy RMSE / data range
inline constexpr double kFitGradThreshold = 0.10;    // gradient RMS error / mean |gradient|

struct FitQuality {
  int n = 0;                    // points measured
  double energy_rmse = 0;       // J/m^2
  double energy_range = 0;      // max - min of all the term's energies
  double energy_rel = 0;        // energy_rmse / energy_range (0 when the range is 0)
  double grad_rms = 0;          // RMS Euclidean gradient error
  double grad_mean = 0;         // mean |gradient| over all the term's points
  double grad_rel = 0;          // grad_rms / grad_mean (0 when the mean is 0)
  bool energy_ok() const { return energy_rel < kFitEnergyThreshold; }
  bool grad_ok() const { return grad_rel < kFitGradThreshold; }
  bool ok() const { return energy_ok() && grad_ok(); }
};

// jet: the function at every one of the term's N points, [C, N] channel-major with channels
// value, d/ds_0 (, d/ds_1) first (core/jet_layout.hpp, order >= 1). points: the indices to
// measure (empty: all).
FitQuality fit_quality(const TermData& data, const std::vector<double>& jet, const std::vector<int>& points = {});

// "ok", or the failed thresholds in words, e.g.
// "FAILS: energy RMSE 7.2% of the data range (limit 3%); gradient error 31% of the mean gradient (limit 10%)".
std::string fit_verdict(const FitQuality& q);

}  // namespace yarnhom
