#pragma once
// The quadratic expansion error of supplement Eq. 4-5 (spec section 9). For a term and a point
// s_i, D(s_i) is the mean over a neighbourhood Omega(s_i) of |Psi(s) - T2(s)|, T2 the
// second-order Taylor expansion of Psi at s_i: the integral of Eq. 5 divided by the measure of
// Omega (our reading). Omega is the interval (1D) or square (2D) centred at s_i with width, per
// axis, 1/100 of the data range. The supplement "uniformly distributes 1024 samples" in Omega;
// we take the 1024 midpoints of a regular subdivision (1024 cells in 1D, 32 x 32 in 2D): a
// deterministic midpoint rule, so that the metric is reproducible.
//   E_I = mean over the data points of D(s_i);
//   E = mean of E_I over the 1D terms + mean of E_I over the 2D terms          (Eq. 4)
#include <map>
#include <string>
#include <vector>

#include "bake/term_function.hpp"

namespace yarnhom {

// D at each of the n points (row-major [n, d]); width[d] is the side of Omega per axis.
// `samples` must be a square in 2D.
std::vector<double> expansion_error_per_point(const TermFunction& f, int d, const std::vector<double>& points,
                                              const std::vector<double>& width, int samples = 1024);

// E_I: the mean of expansion_error_per_point.
double quadratic_expansion_error(const TermFunction& f, int d, const std::vector<double>& points,
                                 const std::vector<double>& width, int samples = 1024);

// Eq. 4 from E_I per term name: mean over the 1D terms present plus mean over the 2D terms
// present (a group with no term contributes 0).
double combine_expansion_errors(const std::map<std::string, double>& per_term);

}  // namespace yarnhom
