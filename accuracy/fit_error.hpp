#pragma once
// How well a term (network or baked table) fits its data: energy and gradient errors, absolute
// (J/m^2, J/m^2 per strain unit) and relative (to the spread of the data).
#include "bake/term_function.hpp"
#include "core/dataset.hpp"

namespace yarnhom {

struct FitError {
  int n = 0;
  double energy_mae = 0, energy_rmse = 0, energy_max = 0;
  double energy_rel = 0;  // energy_rmse / standard deviation of the data energies
  double grad_mae = 0;    // mean over points of |grad_hat - grad| (Euclidean)
  double grad_rel = 0;    // grad_mae / mean |grad| of the data
};

FitError fit_error(const TermFunction& f, const TermData& data);

}  // namespace yarnhom
