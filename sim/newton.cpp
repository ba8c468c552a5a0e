#include "sim/newton.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <stdexcept>

#include "core/scope_profile.hpp"
#include "numerics/newton.hpp"
#include "numerics/pcg.hpp"
#include "numerics/triplet_matrix.hpp"
#include "sim/contact_pattern.hpp"
#include "sim/hinge_angles.hpp"

namespace yarnhom::sim {

namespace {
using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// The step's size in the chosen norm (sim/newton.hpp); pf over the free unknowns.
double step_size(const Problem& P, const DofMap& D, const Eigen::VectorXd& pf, StepNorm norm) {
  if (norm != StepNorm::MassRms || P.mass.size() == 0) return pf.cwiseAbs().maxCoeff();
  double mass = 0, sum = 0;
  for (int i = 0; i < D.num_free(); ++i) {
    const double m = P.mass[D.free_vertices[i]];
    mass += m;
    sum += m * pf.segment<3>(3 * i).squaredNorm();
  }
  if (!(mass > 0)) return pf.cwiseAbs().maxCoeff();
  return std::sqrt(sum / mass);
}
}  // namespace

StepNorm parse_step_norm(const std::string& name) {
  if (name == "auto") return StepNorm::Auto;
  if (name == "max") return StepNorm::Max;
  if (name == "rms") return StepNorm::MassRms;
  throw std::invalid_argument("tolerance norm '" + name + "': expected auto, max or rms");
}

const char* step_norm_name(StepNorm n) {
  switch (n) {
    case StepNorm::Auto: return "auto";
    case StepNorm::Max: return "max";
    case StepNorm::MassRms: return "rms";
  }
  return "?";
}

NewtonStats newton_minimize(const Problem& P, const DofMap& D, const HessianPattern& pat, LinearSolver& solver,
                            StepState& S, Eigen::VectorXd& x, const NewtonSettings& opt, bool profile,
                            const Eigen::VectorXd* target) {
  NewtonStats st;
  // H: the pattern's matrix, its values set to zero at each iteration; the copy and the zeroing
  // on the threads (a garment's matrix is millions of entries: serial, a few ms a step).
  Eigen::SparseMatrix<double> H;
  copy_pattern(pat.matrix, H);
  Eigen::VectorXd grad(x.size());
  std::vector<Eigen::Triplet<double>> contact;
  const int F = D.num_free();
  if (F == 0) {
    st.converged = true;
    st.energy = potential_value(P, D, S, x, &st.shell_energy);
    return st;
  }
  // The prescribed vertices' move within the first iteration (sim/newton.hpp).
  Eigen::VectorXd move, coupling;
  if (target) {
    move = Eigen::VectorXd::Zero(x.size());
    for (size_t v = 0; v < D.free_index.size(); ++v)
      if (D.free_index[v] < 0) move.segment<3>(3 * v) = target->segment<3>(3 * v) - x.segment<3>(3 * v);
    if (!(move.cwiseAbs().maxCoeff() > 0)) move.resize(0);
    else coupling = Eigen::VectorXd::Zero(x.size());
  }
  bool factored = false;  // the solver holds a factorization of this solve's (factor reuse)
  bool refactor = false;  // the last reused step failed its line search: factor this iteration's matrix
  int budget = opt.max_iterations;
  for (int it = 0; it < budget; ++it) {
    auto t0 = Clock::now();
    fill_values(H, 0.0);
    contact.clear();
    const bool lift = it == 0 && move.size() > 0;
    double E;
    {
      prof::Scope ps("assembly: potential derivatives");
      E = potential_derivatives(P, D, pat, S, x, grad, H.valuePtr(), profile ? &st.shell : nullptr, &st.shell_energy,
                                &contact, lift ? &move : nullptr, lift ? &coupling : nullptr);
    }
    st.energy = E;
    Eigen::VectorXd g = gather_free(D, grad);
    // Contact pairs couple vertices the mesh does not: their triplets are added to the pattern's
    // matrix, whose pattern then grows (the solver analyses a changed pattern again). Every
    // column of the lower-triangular sum starts with its diagonal entry.
    Eigen::SparseMatrix<double>* A = &H;
    Eigen::SparseMatrix<double> Hc, Hsum;
    std::vector<int> diag;
    if (!contact.empty()) {
      {
        prof::Scope ps("assembly: contact and seam triplets to a matrix");
        numerics::triplets_to_matrix(contact, H.rows(), H.cols(), Hc);
      }
      // With a kept pattern, the same values on it (sim/contact_pattern.hpp), the sum written
      // straight into it: the solver's analysis is reused while the contacts stay within it.
      // Its pad: the couplings of the pairs within 2 dhat at x.
      if (!pat.contact) {
        Hsum = H + Hc;
        Hsum.makeCompressed();
        A = &Hsum;
      } else {
        prof::Scope ps_embed("assembly: H + contact on the kept pattern");
        A = &pat.contact->embed_sum(H, Hc, [&] {
          // Six places per pair (one per two of its four points; (-1, -1) where a point is an
          // obstacle's or held, which the pattern skips), filled on the threads.
          const Eigen::VectorXd y = solve_obstacles(P, S);
          const std::vector<ContactPair> near = contact_candidates_within(P, x, y, 2 * P.dhat);
          const int64_t nc = int64_t(near.size());
          std::vector<std::pair<int, int>> blocks(6 * size_t(nc), {-1, -1});
#pragma omp parallel for schedule(static) if (nc >= 8192)
          for (int64_t i = 0; i < nc; ++i) {
            const ContactPair& c = near[size_t(i)];
            int f[4];
            for (int k = 0; k < 4; ++k) f[k] = c.slot[k] >= 0 ? D.free_index[c.slot[k]] : -1;
            int q = 0;
            for (int k = 0; k < 4; ++k)
              for (int l = k + 1; l < 4; ++l, ++q)
                if (std::min(f[k], f[l]) >= 0 && f[k] != f[l])
                  blocks[6 * size_t(i) + size_t(q)] = {std::max(f[k], f[l]), std::min(f[k], f[l])};
          }
          return blocks;
        });
      }
      diag.assign(A->outerIndexPtr(), A->outerIndexPtr() + 3 * F);
    } else {
      diag = pat.diag_slots;
    }
    auto t1 = Clock::now();
    st.t_assemble += seconds(t0, t1);
    // Factor reuse (sim/newton.hpp): after the solve's first factorization, CG on this
    // iteration's matrix preconditioned by the last factor; a factorization of its own only when
    // CG does not reach the tolerance within opt.reuse_cg iterations.
    Eigen::VectorXd pf;
    bool reused = false;
    int cg_its = 0;
    double shift_mu = 0;
    if (opt.reuse_cg > 0 && factored && !lift && !refactor) {
      const double floor = 0.1 * opt.tol_step;  // an error a tenth of the convergence tolerance is none
      const numerics::PcgResult cg = numerics::pcg(
          [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return A->selfadjointView<Eigen::Lower>() * v; },
          [&](const Eigen::VectorXd& r) { return solver.solve(r); }, -g, opt.reuse_cg,
          [&](const Eigen::VectorXd& y, const Eigen::VectorXd& z) {
            const double err = step_size(P, D, z, opt.norm);
            return err <= floor || err <= opt.reuse_tol * step_size(P, D, y, opt.norm);
          });
      st.cg_iterations += cg.iterations;
      cg_its = cg.iterations;
      if (cg.converged) {
        pf = cg.x;
        reused = true;
        ++st.reused;
      }
    }
    refactor = false;
    if (!reused) {
      // Factorize; on failure shift the diagonal by a growing multiple of its mean magnitude
      // (numerics/newton.hpp's schedule: 1e-8, then x10, 12 shifts at most).
      double mean_diag = 0;
      for (int k = 0; k < 3 * F; ++k) mean_diag += A->valuePtr()[diag[k]];
      mean_diag = std::max(std::abs(mean_diag) / (3 * F), 1e-300);
      double applied = 0;  // the shift already on H's diagonal
      const numerics::ShiftResult shift = numerics::shifted_factorization(
          0.0,
          [&](double mu) {
            if (mu > applied) {
              for (int k = 0; k < 3 * F; ++k) A->valuePtr()[diag[k]] += (mu - applied) * mean_diag;
              applied = mu;
            }
            ++st.factorizations;
            return solver.factorize(*A);
          },
          {1e-8, 10, 13, 0.0});
      if (shift.mu > 0) ++st.shifted;
      shift_mu = shift.mu;
      factored = shift.ok;
      if (!shift.ok) {
        if (lift) st.prescribed_reached = false;
        break;
      }
      if (lift) {
        // The prescribed move with the free vertices' first-order response, as far as CCD and a
        // finite potential allow; then the gradient where it ends.
        Eigen::VectorXd m = move;
        scatter_free(D, -solver.solve(gather_free(D, coupling)), m);
        double beta = m.allFinite() ? max_feasible_step(P, x, m, &S) : 0.0;
        Eigen::VectorXd xl;
        bool moved = false;
        for (int k = 0; k < 40 && beta > 0; ++k, beta *= 0.5) {
          xl = x + beta * m;
          if (std::isfinite(potential_value(P, D, S, xl))) {
            moved = true;
            break;
          }
        }
        st.prescribed_reached = moved && beta == 1.0;
        if (moved) {
          x = xl;
          if (st.prescribed_reached)  // exactly on the targets, not to rounding
            for (size_t v = 0; v < D.free_index.size(); ++v)
              if (D.free_index[v] < 0) x.segment<3>(3 * v) = target->segment<3>(3 * v);
          if (!S.theta_ref.empty()) S.theta_ref = hinge_angles(P.mesh, x, &S.theta_ref);
          E = potential_derivatives(P, D, pat, S, x, grad, nullptr, nullptr, &st.shell_energy);
          st.energy = E;
          g = gather_free(D, grad);
        }
      }
      pf = -solver.solve(g);
    }
    auto t2 = Clock::now();
    st.t_solve += seconds(t1, t2);
    ++st.iterations;
    st.step_norm = step_size(P, D, pf, opt.norm);
    if (!std::isfinite(st.step_norm)) break;
    // A step below the tolerance converges the solve, and is still taken (line search included,
    // one energy evaluation): the last correction is not dropped, so a slow creep below the
    // tolerance's speed is not frozen into a rest that is not one.
    const bool last = st.step_norm < opt.tol_step;
    Eigen::VectorXd p = Eigen::VectorXd::Zero(x.size());
    scatter_free(D, pf, p);
    const double slope = g.dot(pf);  // < 0 for a positive-definite solve
    // Armijo backtracking from the collider-limited step (CCD as a step filter).
    Eigen::VectorXd xn, xt;
    double shell_n = NAN, shell_t = NAN;  // E_shell at xn and xt (the accepted trial is the last evaluated)
    double feasible;
    {
      prof::Scope ps("line search: CCD of the step");
      feasible = max_feasible_step(P, x, p, &S);
    }
    std::optional<prof::Scope> ps_trials;  // ends with the line search's timing below
    ps_trials.emplace("line search: trials and extension");
    const numerics::LineSearchResult ls = numerics::armijo_backtracking(
        E, slope, feasible,
        [&](double alpha) {
          xn = x + alpha * p;
          return potential_value(P, D, S, xn, &shell_n);
        },
        {opt.armijo, 40, 0.0});
    st.evaluations += ls.trials;
    st.backtracks += ls.trials - (ls.accepted ? 1 : 0);
    const double alpha = ls.alpha;
    double En = ls.energy;
    // A full step that decreased the energy more than its quadratic model predicts (En - E <
    // slope/2 for a Newton step) crossed a region of negative curvature, which the projected
    // Hessian flattened to zero: the step is too short there. Extend it while the energy keeps
    // falling (up to 16 steps, within the collider bound), instead of creeping.
    if (!last && ls.accepted && alpha == 1.0 && En - E < 0.5 * slope) {
      // Multiples of p allowed from x: by the colliders over the longest extension (cheap), by
      // the contact pairs over each trial's own move, when it is tried (a CCD over 16 p at
      // once, the extensions' reach, built a region of millions of pairs for a 16k sheet, and
      // most extensions stop at 2 or 4).
      const double amax = std::min(16.0, 16 * max_feasible_step(P, x, 16 * p));
      double contact_ok = 1.0;  // the contact pairs' CCD allows x -> x + a p for a up to this
      const numerics::Extension ext = numerics::extend_step(
          1.0, En, slope, 4, 0.0,
          [&](double a) {
            if (a > amax) return std::numeric_limits<double>::infinity();
            if (a > contact_ok && has_contact(P)) {
              if (!(max_feasible_step(P, x, a * p, &S) >= 1)) return std::numeric_limits<double>::infinity();
              contact_ok = a;
            }
            xt = x + a * p;
            return potential_value(P, D, S, xt, &shell_t);
          },
          [&](double) {
            xn = xt;
            shell_n = shell_t;
          });
      En = ext.energy;
      st.extensions += ext.doublings;
      st.evaluations += ext.doublings + 1;
    }
    st.t_line_search += seconds(t2, Clock::now());
    ps_trials.reset();
    if (!ls.accepted && reused) {
      // The inexact step found no decrease: the same point again with a factorization of its own.
      refactor = true;
      continue;
    }
    if (!ls.accepted) {
      // No decrease at rounding level: the step is below what the energy resolves.
      st.converged = alpha * st.step_norm < opt.tol_step || std::abs(slope) < 1e-14 * (1 + std::abs(E));
      break;
    }
    if (std::getenv("YARNHOM_SIM_DEBUG"))
      std::fprintf(stderr, "  newton %d: E %.12g -> %.12g, |p| %.3g, alpha %.3g, slope %.3g, shift %g, ccd %.3g, %s\n", it, E, En,
                   st.step_norm, alpha, slope, shift_mu, max_feasible_step(P, x, p, &S),
                   reused ? ("CG " + std::to_string(cg_its)).c_str() : cg_its ? "factored after CG" : "factored");
    x = xn;
    if (alpha < 1 && budget < opt.max_iterations + opt.extra_when_cut) ++budget;
    st.energy = En;
    st.shell_energy = shell_n;
    // The hinges' branches follow the iterate: a step that turns a hinge by more than pi in all
    // (a soft knit's edge curling within one time step) is then still continuous, as long as no
    // single Newton update turns it by pi (sim/hinge_angles.hpp).
    if (!S.theta_ref.empty()) S.theta_ref = hinge_angles(P.mesh, x, &S.theta_ref);
    if (last) {
      st.converged = true;
      break;
    }
  }
  return st;
}

}  // namespace yarnhom::sim
