#pragma once
// How well a term's function (network or baked table) fits its data, in physical meaning, and
// the thresholds a fit must meet (issue 12; docs/training.md, "Fit quality").
//
//   energy RMSE / range     sqrt(mean_p (Psi_hat(s_p) - Psi_p)^2) over the points measured,
//                           divided by max_p Psi_p - min_p Psi_p over ALL the term's points
//   gradient error / mean   sqrt(mean_p |D (grad Psi_hat(s_p) - grad Psi_p)|^2) (Euclidean, RMS)
//                           over the points measured, divided by mean_p |D grad Psi_p| over all
//                           the term's points, with D = diag(half-widths of the term's box):
//                           the gradient with respect to the box coordinate x = (s - c) / h, in
//                           J/m^2 (the energy change across half the box). The strain
//                           components of a 2D bending term have different units (1 and 1/m);
//                           unscaled, the Euclidean norm all but ignored the bending direction
//                           (stockinette term 15: dPsi/ds_a ~ 1.8 J/m^2, dPsi/dII ~ 0.003 J/m).
//
// and, of the data alone, where the points form a grid (produce's and synth's do):
//
//   data inconsistency      sqrt(mean over neighbour pairs along each axis of
//                           |h_k ((Psi_q - Psi_p) / (s_q - s_p) - (g_p + g_q)_k / 2)|^2),
//                           divided by the same mean gradient: how far the data's gradients
//                           disagree with the slopes of their own energies (the trapezoid rule,
//                           exact to O(spacing^2) on smooth data: 0-10 % on the smooth terms of
//                           the paper-preset datasets). Where it is large the data are not a
//                           smooth function (a solve that switched branches between neighbours,
//                           buckling), and no smooth fit can match both energies and gradients:
//                           the verdict then says so.
//
// and, for the 1D terms, where the range-relative limits cannot look:
//
//   small-stress error      sqrt(mean_p ((dPsi_hat(s_p) - dPsi_p) / dPsi_p)^2) over the points
//                           measured whose |dPsi_p| is 1-20 % of the term's largest |dPsi|: the
//                           stress relative to itself where it is small but not nothing, the
//                           strains a stretch test starts at. A network can pass the limits
//                           above and miss these by a quarter (basket s_x before the relative
//                           fit: 21 % RMS, 28 % at s_x = 0.048; docs/training.md, "Relative fit").
//                           Limit 10 %; -1 for 2D terms and where no point measured is in the band.
//
// All are measured on the held-out validation points (the model file records which) and, for
// comparison, on all points. A term passes when its validation energy RMSE is below 3 % of
// its range and its gradient error below 10 % of its mean gradient (the "limit" rule): tighter
// than the fit between neighbouring samples of a 31 x 31 grid that a Hermite table already
// achieves, and loose enough that a term which passes is indistinguishable from its data in a
// simulation (a 3 % energy error is below the pattern-to-pattern differences of supplement
// Fig. 5). Where the data disagree with themselves by more than the gradient limit (data G >=
// 10 %), no smooth fit can meet it, and the gradient limit is relative to the data instead: the
// gradient error must be below 1.25 x data G (the "data" rule, issue 36's decision). The energy
// limit and the small-stress limit stay as they are. The verdict names the rule a term passed by;
// data G comes down with better data (a 2 x 2 patch, more branch rounds), never the limit with
// worse fits.
#include <string>
#include <vector>

#include "core/dataset.hpp"

namespace yarnhom {

inline constexpr double kFitEnergyThreshold = 0.03;  // energy RMSE / data range
inline constexpr double kFitGradThreshold = 0.10;    // gradient RMS error / mean |gradient|
inline constexpr double kFitDataRuleFactor = 1.25;  // rough data (data G >= the gradient limit): gradient error < 1.25 data G
inline constexpr double kFitSmallStressThreshold = 0.10;  // 1D: RMS relative gradient error, small stresses
inline constexpr double kSmallStressBand[2] = {0.01, 0.20};  // of the term's largest |gradient|

struct FitQuality {
  int n = 0;                    // points measured
  double energy_rmse = 0;       // J/m^2
  double energy_range = 0;      // max - min of all the term's energies
  double energy_rel = 0;        // energy_rmse / energy_range (0 when the range is 0)
  double grad_rms = 0;          // RMS Euclidean error of the box-scaled gradient (J/m^2)
  double grad_mean = 0;         // mean |box-scaled gradient| over all the term's points
  double grad_rel = 0;          // grad_rms / grad_mean (0 when the mean is 0)
  double data_inconsistency = -1;  // of the data alone, / grad_mean; < 0: not a grid
  double small_stress_rel = -1;    // 1D: the small-stress error above; < 0: not measured
  int small_stress_n = 0;          // points measured in its band
  bool energy_ok() const { return energy_rel < kFitEnergyThreshold; }
  bool rough_data() const { return data_inconsistency >= kFitGradThreshold; }
  bool grad_within_limit() const { return grad_rel < kFitGradThreshold; }
  bool grad_within_data() const { return rough_data() && grad_rel < kFitDataRuleFactor * data_inconsistency; }
  bool grad_ok() const { return grad_within_limit() || grad_within_data(); }
  bool small_stress_ok() const { return small_stress_rel < kFitSmallStressThreshold; }  // true when not measured
  bool ok() const { return energy_ok() && grad_ok() && small_stress_ok(); }
};

// jet: the function at every one of the term's N points, [C, N] channel-major with channels
// value, d/ds_0 (, d/ds_1) first (core/jet_layout.hpp, order >= 1). points: the indices to
// measure (empty: all).
FitQuality fit_quality(const TermData& data, const std::vector<double>& jet, const std::vector<int>& points = {});

// The rule a term passes by: "limit" (the gradient within 10 % of the mean gradient), "data"
// (rough data, the gradient within 1.25 x data G), or "-" (it fails).
std::string fit_rule(const FitQuality& q);

// "ok", "ok by the data rule: gradient error 47% of the mean gradient, within 1.25 x data G (83%)",
// or the failed thresholds in words, e.g.
// "FAILS: energy RMSE 7.2% of the data range (limit 3%); gradient error 31% of the mean gradient (limit 10%);
// small stresses off by 21% (limit 10%)",
// followed, when the data's own inconsistency exceeds the gradient limit, by
// "; the data's own gradients and energies disagree by 43% of the mean gradient: not smooth data" (and the
// gradient's limit then reads "limit 10%, or 1.25 x data G = 54%").
std::string fit_verdict(const FitQuality& q);

// Why a baked table can miss the data where its network fits them (docs/bake.md): for a 1D term
// the end repair, for a 2D term the edge slope and corner twist repairs (where the total falls
// outward), and for both the interpolation.
inline const char* baked_table_cause(int dim) {
  return dim == 1 ? "1D end repair or interpolation"
                  : "edge slope or corner twist repair where the total falls outward, or interpolation";
}

// The data inconsistency above, relative to grad_mean (-1 when the points do not form a grid).
double data_inconsistency(const TermData& data, double grad_mean);

}  // namespace yarnhom
