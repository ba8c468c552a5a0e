#include "yarn/rve/rest.hpp"

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <type_traits>

namespace yarnhom::yarn {

Eigen::Matrix2d in_plane_map(const Eigen::Vector3d& s) {
  Eigen::Matrix2d F;
  F << 1 + s[0], s[1] * (1 + s[2]), 0, (1 + s[2]) * std::sqrt(1 - s[1] * s[1]);
  return F;
}

Eigen::Vector3d in_plane_strain(const Eigen::Matrix2d& F) {
  // Columns of F are the deformed axes: |col 0| = 1 + s_x, |col 1| = 1 + s_y, and s_a the
  // cosine of the angle between them.
  const double a = F.col(0).norm(), c = F.col(1).norm();
  return {a - 1, F.col(0).dot(F.col(1)) / (a * c), c - 1};
}

namespace {

// The local frame of a flat strain (the same at every point).
Eigen::Matrix3d flat_frame(const Strain& s) {
  const ShellPoint<double> sp = shell_map(s.data(), 0.0, 0.0, 0.0);
  Eigen::Matrix3d R;
  for (int c = 0; c < 3; ++c) R.col(c) = Eigen::Vector3d(sp.R[c].x, sp.R[c].y, sp.R[c].z);
  return R;
}

// A configuration (flat strain s_p, u_p) of the old reference F0, in the new reference
// F(s) F0: the same positions F(s_p) F0 xi + R(s_p) u_p = F(s') F(s) F0 xi + R(s') u', so
// F(s') = F(s_p) F(s)^-1 (upper triangular again) and u' = R(s')^T R(s_p) u_p.
PathPoint carry_point(const PathPoint& p, const Strain& s) {
  if (!p.s.tail<3>().isZero(0.0))
    throw std::logic_error("carry_to_reference: a configuration under curvature cannot be carried to a new reference");
  PathPoint q;
  q.s.setZero();
  q.s.head<3>() = in_plane_strain(in_plane_map(p.s.head<3>()) * in_plane_map(s.head<3>()).inverse());
  const Eigen::Matrix3d R = flat_frame(q.s).transpose() * flat_frame(p.s);
  q.u.reserve(p.u.size());
  for (const auto& u : p.u) q.u.push_back(R * u);
  return q;
}

}  // namespace

RveState carry_to_reference(const RveState& st, const Strain& s) {
  const Eigen::Matrix3d R = flat_frame(s);
  RveState out = st;
  for (auto& u : out.u) u = R * u;
  for (auto& f : out.frames.edge) f = {R * f.t, R * f.d1};
  // The checked path (docs/rve.md section 5) is carried along: its last configuration and,
  // when recorded, all of them.
  out.anchor = carry_point(st.anchor, s);
  for (auto& p : out.path) p = carry_point(p, s);
  return out;
}

RveState tile_state(const RveState& st, int copies) {
  auto repeat = [copies](const auto& v) {
    std::decay_t<decltype(v)> out;
    out.reserve(v.size() * copies);
    for (int c = 0; c < copies; ++c) out.insert(out.end(), v.begin(), v.end());
    return out;
  };
  RveState out;
  out.u = repeat(st.u);
  out.theta = repeat(st.theta);
  out.frames.edge = repeat(st.frames.edge);
  out.frames.twist = repeat(st.frames.twist);
  // The checked path repeats too (the same configurations of every copy: by periodicity the
  // closest distances the certificate found are those of the larger tile).
  out.certificate = st.certificate;
  out.anchor = {st.anchor.s, repeat(st.anchor.u)};
  for (const PathPoint& p : st.path) out.path.push_back({p.s, repeat(p.u)});
  return out;
}

RestTile repeat_rest(const Pattern& pattern, const RestTile& one, int nx, int ny) {
  if (nx * ny == 1) return one;  // nothing to repeat (tile(p, 1, 1) would only rename the pattern)
  return RestTile{RveProblem(tile(pattern, nx, ny), one.rve.material(), one.rve.options(), one.rve.reference()),
                  tile_state(one.state, nx * ny), one.report};
}

double relative_stress(const RveProblem& rve, const Strain& dEds) {
  const auto& L = rve.pattern().rest_length;
  const double total = std::accumulate(L.begin(), L.end(), 0.0);
  return dEds.head<3>().norm() / (rve.stretch_stiffness() * total);
}

double areal_density(const RveProblem& rve) {
  const auto& L = rve.pattern().rest_length;
  const double r = rve.radius();
  return rve.material().density * M_PI * r * r * std::accumulate(L.begin(), L.end(), 0.0) / rve.area();
}

std::string RestReport::summary() const {
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "%s after %d period updates (%d Newton iterations), in-plane stress %.2g, relaxed tile "
                "s_x %.6g s_a %.6g s_y %.6g, %.3f s",
                converged ? "stress free" : "NOT stress free", iterations, inner_iterations, stress, strain[0],
                strain[1], strain[2], seconds);
  return buf;
}

namespace {

Strain flat(const Eigen::Vector3d& s) {
  Strain out = Strain::Zero();
  out.head<3>() = s;
  return out;
}

// The relaxation at rest (relax_tile): the fluctuations at the pattern's own period, then
// (free_period) Newton on the period.
class RestRelaxation {
 public:
  RestRelaxation(const Pattern& pattern, const Material& material, const RestOptions& opt, const RveOptions& rve_options)
      : pattern_(pattern), material_(material), opt_(opt), rve_options_(rve_options),
        tile_{RveProblem(pattern, material, rve_options), RveState{}, RestReport{}} {
    inner_ = opt.solve;
    inner_.tolerance = std::min(inner_.tolerance, 1e-12);  // G is only as good as the equilibrium
    inner_.verbose = false;
    if (opt.free_period) inner_.sensitivity_directions = axes_;
  }

  RestTile run() {
    RestReport& rep = tile_.report;
    first_solve();
    if (!opt_.free_period) {
      rep.converged = true;  // nothing asked beyond the fluctuations
      finish();
      return std::move(tile_);
    }
    // 2. The period: Newton on E(s) = min_y E(s, y) over s = (s_x, s_a, s_y), II = 0.
    du_ = rep.first.sensitivity;
    for (;;) {
      const RveProblem& P = tile_.rve;
      rep.stress = relative_stress(P, dE_);
      if (opt_.verbose)
        std::fprintf(stderr, "  rest %2d  E %.12g  stress %.3e  s %.6g %.6g %.6g\n", rep.iterations,
                     rep.last.energy, rep.stress, in_plane_strain(P.reference())[0],
                     in_plane_strain(P.reference())[1], in_plane_strain(P.reference())[2]);
      if (rep.stress <= opt_.tolerance) {
        rep.converged = true;
        break;
      }
      if (rep.iterations >= opt_.max_iterations) break;
      if (opt_.max_seconds > 0 && left() <= 1e-9) break;
      if (du_.size() != 3) du_ = equilibrium_sensitivity(P, Strain::Zero(), tile_.state, axes_);
      if (du_.size() != 3) break;
      if (!period_step()) break;
    }
    finish();
    if (!rep.converged)
      throw std::runtime_error("relaxing the period of pattern '" + display_name(pattern_) + "' failed: " + rep.summary() +
                               (opt_.max_seconds > 0 && left() <= 1e-9 ? " (time limit reached)" : ""));
    return std::move(tile_);
  }

 private:
  // The guard covers the whole relaxation: every solve gets what is left of it.
  double left() const {
    if (opt_.max_seconds <= 0) return 0.0;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    return std::max(opt_.max_seconds - el, 1e-9);
  }

  void finish() {
    tile_.report.strain = in_plane_strain(tile_.rve.reference());
    tile_.report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
  }

  // 1. The fluctuations at the pattern's own period (cold, from the stored geometry).
  void first_solve() {
    RestReport& rep = tile_.report;
    SolveOptions first = inner_;
    first.max_iterations = opt_.first_max_iterations;
    first.max_seconds = left();
    first.verbose = opt_.solve.verbose;
    tile_.state = tile_.rve.initial_state(opt_.record_path);
    if (!tile_.state.certificate.valid)
      throw std::runtime_error("pattern '" + pattern_.name + "': " + summary(tile_.state.certificate, 2 * pattern_.radius));
    rep.first = solve(tile_.rve, Strain::Zero(), tile_.state, first);
    rep.last = rep.first;
    rep.inner_iterations = rep.first.iterations;
    if (!rep.first.converged())
      throw std::runtime_error("relaxing pattern '" + display_name(pattern_) + "' at rest failed: " + rep.first.summary());
    tile_.rve.evaluate(Strain::Zero(), tile_.state, nullptr, nullptr, nullptr, &dE_);
    rep.stress = relative_stress(tile_.rve, dE_);
  }

  // The reduced Hessian: central differences of the envelope gradient along the equilibrium
  // path. A tile that is not a minimum in its period (buckling under compression) has an
  // indefinite K: it is shifted so that the step still descends.
  Eigen::Matrix3d period_hessian() const {
    const RveProblem& P = tile_.rve;
    constexpr double h = 1e-5;
    Eigen::Matrix3d K;
    for (int j = 0; j < 3; ++j) {
      RveState p = tile_.state, m = tile_.state;
      P.apply_step(du_[j], h, p);
      P.apply_step(du_[j], -h, m);
      Strain dp, dm;
      P.evaluate(h * axes_[j], p, nullptr, nullptr, nullptr, &dp);
      P.evaluate(-h * axes_[j], m, nullptr, nullptr, nullptr, &dm);
      K.col(j) = (dp - dm).head<3>() / (2 * h);
    }
    K = 0.5 * (K + K.transpose()).eval();
    const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(K).eigenvalues();
    const double floor = 1e-6 * std::max(ev.cwiseAbs().maxCoeff(), 1e-300);
    if (ev.minCoeff() < floor) K += (floor - ev.minCoeff()) * Eigen::Matrix3d::Identity();
    return K;
  }

  // One Newton step on the period, with Armijo backtracking on the total energy
  // (numerics/newton.hpp): every trial re-solves the fluctuations in the moved reference,
  // starting from the first-order prediction of the equilibrium; a trial whose solve does not
  // converge counts as a failed one. false: no step accepted.
  bool period_step() {
    RestReport& rep = tile_.report;
    const RveProblem& P = tile_.rve;
    const Eigen::Vector3d G = dE_.head<3>();
    Eigen::Vector3d d = -period_hessian().ldlt().solve(G);
    const double big = d.cwiseAbs().maxCoeff();
    if (big > opt_.max_step) d *= opt_.max_step / big;
    const double slope = G.dot(d), E0 = rep.last.energy;
    bool out_of_time = false;
    std::optional<RveProblem> moved_kept;
    RveState trial_kept;
    SolveReport r_kept;
    auto energy = [&](double alpha) {
      if (out_of_time) return std::numeric_limits<double>::quiet_NaN();
      const Strain ds = flat(alpha * d);
      RveState trial = tile_.state;
      Eigen::VectorXd step = Eigen::VectorXd::Zero(P.num_dofs());
      for (int j = 0; j < 3; ++j) step += ds[j] * du_[j];
      P.apply_step(step, 1.0, trial);
      trial = carry_to_reference(trial, ds);
      RveProblem moved(pattern_, material_, rve_options_, in_plane_map(ds.head<3>()) * P.reference());
      if (opt_.max_seconds > 0 && left() <= 1e-9) {
        out_of_time = true;
        return std::numeric_limits<double>::quiet_NaN();
      }
      inner_.max_seconds = left();
      const SolveReport r = solve(moved, Strain::Zero(), trial, inner_);
      rep.inner_iterations += r.iterations;
      if (!r.converged()) return std::numeric_limits<double>::quiet_NaN();
      moved_kept.emplace(std::move(moved));
      trial_kept = std::move(trial);
      r_kept = r;
      return r.energy;
    };
    numerics::LineSearchOptions ls;
    ls.max_trials = 14;  // alpha = 1, 1/2, ..., 2^-13: above 1e-4
    if (!numerics::armijo_backtracking(E0, slope, 1.0, energy, ls).accepted) return false;
    tile_.rve = std::move(*moved_kept);
    tile_.state = std::move(trial_kept);
    rep.last = r_kept;
    du_ = r_kept.sensitivity;
    tile_.rve.evaluate(Strain::Zero(), tile_.state, nullptr, nullptr, nullptr, &dE_);
    ++rep.iterations;
    return true;
  }

  const Pattern& pattern_;
  const Material& material_;
  const RestOptions& opt_;
  const RveOptions& rve_options_;
  const std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  const std::vector<Strain> axes_ = {flat({1, 0, 0}), flat({0, 1, 0}), flat({0, 0, 1})};
  RestTile tile_;
  SolveOptions inner_;
  Strain dE_;
  std::vector<Eigen::VectorXd> du_;
};

}  // namespace

RestTile relax_tile(const Pattern& pattern, const Material& material, const RestOptions& opt,
                    const RveOptions& rve_options) {
  return RestRelaxation(pattern, material, opt, rve_options).run();
}

}  // namespace yarnhom::yarn
