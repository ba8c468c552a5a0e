#include "yarn/strip/strip_stretch.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace yarnhom::yarn {

std::vector<signed char> clamp_flags(const Strip& s, double band) {
  if (!(band > 0)) throw std::invalid_argument("clamp band must be positive");
  if (2 * band >= s.length) throw std::invalid_argument("clamp bands cover the whole strip (band >= length / 2)");
  const Eigen::Vector3d a = s.long_axis();
  const double end = 0.5 * s.length;
  std::vector<signed char> c(s.size(), 0);
  for (int v = 0; v < s.size(); ++v) {
    const double t = s.x[v].dot(a);
    if (t >= end - band) c[v] = 1;
    else if (t <= -end + band) c[v] = -1;
  }
  return c;
}

StripStretch::StripStretch(const StripProblem& P, Eigen::Vector3d axis, std::vector<Eigen::Vector3d> reference)
    : P_(P), axis_(axis.normalized()), ref_(std::move(reference)) {
  if (static_cast<int>(ref_.size()) != P_.strip().size()) throw std::invalid_argument("stretch: one reference position per vertex expected");
}

void StripStretch::place_clamps(StripState& st, double stretch) const {
  const double D = 0.5 * (stretch - 1.0) * P_.strip().length;
  const auto& c = P_.clamp();
  for (int v = 0; v < P_.strip().size(); ++v)
    if (c[v] != 0) st.x[v] = ref_[v] + (c[v] * D) * axis_;
}

void StripStretch::predict(StripState& st, double from, double to) const {
  const double D = 0.5 * (to - from) * P_.strip().length;
  const auto& c = P_.clamp();
  double lo = -1e300, hi = 1e300;  // inner edges of the clamps along the axis
  for (int v = 0; v < P_.strip().size(); ++v) {
    const double t = st.x[v].dot(axis_);
    if (c[v] < 0) lo = std::max(lo, t);
    if (c[v] > 0) hi = std::min(hi, t);
  }
  const std::vector<Eigen::Vector3d> before = st.x;
  for (int v = 0; v < P_.strip().size(); ++v) {
    double f;  // -1 .. 1
    if (c[v] != 0) f = c[v];
    else if (!(hi > lo)) f = 0;
    else f = std::clamp(2 * (st.x[v].dot(axis_) - lo) / (hi - lo) - 1, -1.0, 1.0);
    st.x[v] += (f * D) * axis_;
  }
  place_clamps(st, to);  // exactly where the clamps are (no drift from round-off)
  // Checked like every other move (it cannot bring two points closer when to > from).
  add_move(st.certificate, P_.safe_fraction(before, st.x), std::numeric_limits<double>::infinity(), "predictor");
}

StretchStep StripStretch::measure(const StripState& st, double stretch) const {
  StretchStep r;
  r.stretch = stretch;
  std::vector<Eigen::Vector3d> vg;
  r.energy = P_.evaluate(st, nullptr, nullptr, &r.parts, &vg);
  const auto& c = P_.clamp();
  for (int v = 0; v < P_.strip().size(); ++v) {
    if (c[v] < 0) r.force_low += vg[v].dot(axis_);
    if (c[v] > 0) r.force_high += vg[v].dot(axis_);
  }
  r.force = 0.5 * (r.force_high - r.force_low);
  r.tension = r.force / P_.strip().width;
  r.min_distance = P_.min_distance(st);
  r.certificate = st.certificate;
  return r;
}

StretchStep StripStretch::step(StripState& st, double from, double to, const StripSolveOptions& opt) const {
  if (to != from) {
    predict(st, from, to);
  } else {
    const std::vector<Eigen::Vector3d> before = st.x;
    place_clamps(st, to);
    if (st.x != before)
      add_move(st.certificate, P_.safe_fraction(before, st.x), std::numeric_limits<double>::infinity(), "clamps");
  }
  const StripSolveReport rep = solve_strip(P_, st, opt);
  StretchStep r = measure(st, to);
  r.solve = rep;
  if (rep.converged()) P_.rebase_frames(st);
  return r;
}

}  // namespace yarnhom::yarn
