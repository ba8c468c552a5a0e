#include "yarn/rest.hpp"

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
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

}  // namespace

RestTile relax_tile(const Pattern& pattern, const Material& material, const RestOptions& opt,
                    const RveOptions& rve_options) {
  const auto t0 = std::chrono::steady_clock::now();
  RestTile tile{RveProblem(pattern, material, rve_options), RveState{}, RestReport{}};
  RestReport& rep = tile.report;
  const std::vector<Strain> axes = {flat({1, 0, 0}), flat({0, 1, 0}), flat({0, 0, 1})};
  SolveOptions inner = opt.solve;
  inner.tolerance = std::min(inner.tolerance, 1e-12);  // G is only as good as the equilibrium
  inner.verbose = false;
  if (opt.free_period) inner.sensitivity_directions = axes;
  SolveOptions first = inner;
  first.max_iterations = opt.first_max_iterations;
  // The guard covers the whole relaxation: every solve gets what is left of it.
  auto left = [&] {
    if (opt.max_seconds <= 0) return 0.0;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return std::max(opt.max_seconds - el, 1e-9);
  };
  first.max_seconds = left();
  first.verbose = opt.solve.verbose;

  // 1. The fluctuations at the pattern's own period (cold, from the stored geometry).
  tile.state = tile.rve.initial_state(opt.record_path);
  if (!tile.state.certificate.valid)
    throw std::runtime_error("pattern '" + pattern.name + "': " + summary(tile.state.certificate, 2 * pattern.radius));
  rep.first = solve(tile.rve, Strain::Zero(), tile.state, first);
  rep.last = rep.first;
  rep.inner_iterations = rep.first.iterations;
  auto finish = [&] {
    rep.strain = in_plane_strain(tile.rve.reference());
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  if (!rep.first.converged())
    throw std::runtime_error("relaxing pattern '" + display_name(pattern) + "' at rest failed: " + rep.first.summary());
  Strain dE;
  tile.rve.evaluate(Strain::Zero(), tile.state, nullptr, nullptr, nullptr, &dE);
  rep.stress = relative_stress(tile.rve, dE);
  if (!opt.free_period) {
    rep.converged = true;  // nothing asked beyond the fluctuations
    finish();
    return tile;
  }

  // 2. The period: Newton on E(s) = min_y E(s, y) over s = (s_x, s_a, s_y), II = 0.
  std::vector<Eigen::VectorXd> du = rep.first.sensitivity;
  for (;;) {
    const RveProblem& P = tile.rve;
    const Eigen::Vector3d G = dE.head<3>();
    rep.stress = relative_stress(P, dE);
    if (opt.verbose)
      std::fprintf(stderr, "  rest %2d  E %.12g  stress %.3e  s %.6g %.6g %.6g\n", rep.iterations,
                   rep.last.energy, rep.stress, in_plane_strain(P.reference())[0],
                   in_plane_strain(P.reference())[1], in_plane_strain(P.reference())[2]);
    if (rep.stress <= opt.tolerance) {
      rep.converged = true;
      break;
    }
    if (rep.iterations >= opt.max_iterations) break;
    if (opt.max_seconds > 0 && left() <= 1e-9) break;
    if (du.size() != 3) du = equilibrium_sensitivity(P, Strain::Zero(), tile.state, axes);
    if (du.size() != 3) break;
    // Reduced Hessian: central differences of the envelope gradient along the equilibrium path.
    constexpr double h = 1e-5;
    Eigen::Matrix3d K;
    for (int j = 0; j < 3; ++j) {
      RveState p = tile.state, m = tile.state;
      P.apply_step(du[j], h, p);
      P.apply_step(du[j], -h, m);
      Strain dp, dm;
      P.evaluate(h * axes[j], p, nullptr, nullptr, nullptr, &dp);
      P.evaluate(-h * axes[j], m, nullptr, nullptr, nullptr, &dm);
      K.col(j) = (dp - dm).head<3>() / (2 * h);
    }
    K = 0.5 * (K + K.transpose()).eval();
    // A tile that is not a minimum in its period (buckling under compression) has an
    // indefinite K: shift it so that the step still descends.
    const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(K).eigenvalues();
    const double floor = 1e-6 * std::max(ev.cwiseAbs().maxCoeff(), 1e-300);
    if (ev.minCoeff() < floor) K += (floor - ev.minCoeff()) * Eigen::Matrix3d::Identity();
    Eigen::Vector3d d = -K.ldlt().solve(G);
    const double big = d.cwiseAbs().maxCoeff();
    if (big > opt.max_step) d *= opt.max_step / big;
    const double slope = G.dot(d), E0 = rep.last.energy;

    // Line search on the total energy; every trial re-solves the fluctuations in the moved
    // reference, starting from the first-order prediction of the equilibrium.
    bool accepted = false;
    for (double alpha = 1.0; alpha > 1e-4; alpha *= 0.5) {
      const Strain ds = flat(alpha * d);
      RveState trial = tile.state;
      Eigen::VectorXd step = Eigen::VectorXd::Zero(P.num_dofs());
      for (int j = 0; j < 3; ++j) step += ds[j] * du[j];
      P.apply_step(step, 1.0, trial);
      trial = carry_to_reference(trial, ds);
      RveProblem moved(pattern, material, rve_options, in_plane_map(ds.head<3>()) * P.reference());
      if (opt.max_seconds > 0 && left() <= 1e-9) break;
      inner.max_seconds = left();
      const SolveReport r = solve(moved, Strain::Zero(), trial, inner);
      rep.inner_iterations += r.iterations;
      if (!r.converged()) continue;
      if (!(r.energy <= E0 + 1e-4 * alpha * slope || -slope < 1e-13 * std::abs(E0))) continue;
      tile.rve = std::move(moved);
      tile.state = std::move(trial);
      rep.last = r;
      du = r.sensitivity;
      tile.rve.evaluate(Strain::Zero(), tile.state, nullptr, nullptr, nullptr, &dE);
      ++rep.iterations;
      accepted = true;
      break;
    }
    if (!accepted) break;
  }
  finish();
  if (!rep.converged)
    throw std::runtime_error("relaxing the period of pattern '" + display_name(pattern) + "' failed: " + rep.summary() +
                             (opt.max_seconds > 0 && left() <= 1e-9 ? " (time limit reached)" : ""));
  return tile;
}

}  // namespace yarnhom::yarn
