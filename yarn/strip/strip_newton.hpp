#pragma once
// Internal to the strip solvers (strip_solve.cpp, strip_solve_trust.cpp): what both Newton
// methods keep and do at every iteration (the shared Newton pieces are numerics/newton.hpp's).
#include <algorithm>
#include <cmath>

#include "yarn/strip/strip_solve.hpp"

namespace yarnhom::yarn {

class StripNewton {
 protected:
  StripNewton(const StripProblem& P, StripState& st, const StripSolveOptions& opt)
      : P_(P), st_(st), opt_(opt), g_(P.num_dofs()), B_(P.make_hessian()) {}

  // Records iteration it's energy and residual (g_ its gradient); false when not finite.
  bool record(int it, double E) {
    rep_.energy = E;
    rep_.residual = strip_residual(P_, g_);
    rep_.iterations = it;
    return std::isfinite(E) && std::isfinite(rep_.residual);
  }
  // Converged: the assembly since ta counted, the closest distance into the certificate.
  void converged(numerics::SolveClock::time_point ta) {
    rep_.assembly_seconds += numerics::seconds_since(ta);
    st_.certificate.min_distance = std::min(st_.certificate.min_distance, P_.min_distance(st_) * 2 * P_.radius());
  }
  StripSolveReport finish(SolveStatus status, int analyses) {
    rep_.status = status;
    rep_.seconds = numerics::seconds_since(t0_);
    rep_.analyses = analyses;
    return rep_;
  }

  const StripProblem& P_;
  StripState& st_;
  const StripSolveOptions& opt_;
  const numerics::SolveClock::time_point t0_ = numerics::SolveClock::now();
  StripSolveReport rep_;
  Eigen::VectorXd g_;
  BlockHessian B_;  // the Hessian the model asks for
};

}  // namespace yarnhom::yarn
