#pragma once
// 1D terms whose energy is a known function, sampled like produce's nodes, for the tests of the
// fit (train, core). The stiffening one is basket's s_x term within 10 %: curvature 24 at rest
// rising to 84 past |s| = 0.2, dPsi/ds 0.29 at 0.012, 2.5 at 0.06 and 84 at 1.
#include <cmath>
#include <functional>
#include <string>

#include "core/dataset.hpp"

namespace yarnhom::test {

inline double stiffening_psi(double s) { return 42 * s * s + 0.3 * (std::exp(-s * s / 0.01) - 1); }
inline double stiffening_dpsi(double s) { return 84 * s - 60 * s * std::exp(-s * s / 0.01); }

// Term `name` (1D) on n evenly spaced nodes of [lo, hi]: energies psi, gradients dpsi.
inline TermData analytic_term(const std::string& name, double lo, double hi, int n,
                              const std::function<double(double)>& psi,
                              const std::function<double(double)>& dpsi) {
  TermData t;
  t.term = term_by_name(name);
  t.lower = {lo};
  t.upper = {hi};
  t.n = n;
  for (int i = 0; i < n; ++i) {
    const double s = lo + (hi - lo) * i / (n - 1);
    t.strain.push_back(s);
    t.energy.push_back(psi(s));
    t.gradient.push_back(dpsi(s));
    t.raw.push_back(t.energy.back());
  }
  return t;
}

// A dataset of that one term.
inline Dataset analytic_dataset(const TermData& t) {
  Dataset ds;
  ds.pattern = "analytic";
  ds.source = "synthetic";
  ds.terms.push_back(t);
  return ds;
}

}  // namespace yarnhom::test
