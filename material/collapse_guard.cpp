#include "material/collapse_guard.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace yarnhom {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kShearClamp = 0.9;     // shear edges within [-0.9, 0.9]
constexpr double kStretchClamp = -0.6;  // stretch lower edges >= -0.6
constexpr double kStretchTop = 3.0;     // stretch upper edges <= 3
constexpr double kCurvatureLimit = 10.5;  // c_lim / c

// k psi(z(u)) with z = sign (u - edge) / width, added to (v, d, dd) in u.
void add_side(double k, double u, double edge, double sign, double width, double& v, double& d, double& dd) {
  const double z = sign * (u - edge) / width;
  if (!(z > 0)) return;
  const GuardJet p = guard_profile(z);
  v += k * p.v;
  d += k * sign * p.d1 / width;
  dd += k * p.d2 / (width * width);
}

}  // namespace

GuardJet guard_profile(double z) {
  if (!(z > 0)) return {0, 0, 0, 0};
  if (!(z < 1)) return {kInf, kInf, kInf, kInf};
  const double w = 1 - z, w2 = w * w, w3 = w2 * w;
  // psi = z^3/w^2, psi' = z^2 (3 - z)/w^3, psi'' = 6 z/w^4, psi''' = 6 (1 + 3z)/w^5.
  return {z * z * z / w2, z * z * (3 - z) / w3, 6 * z / (w3 * w), 6 * (1 + 3 * z) / (w3 * w2)};
}

GuardBox baked_guard_box(const BakedMaterial& mat) {
  GuardBox b;
  const auto& terms = all_terms();
  double c = 0;
  for (size_t k = 0; k < terms.size(); ++k) {
    if (!mat.terms[k] || terms[k].dim() != 1) continue;
    const BakedTerm& t = *mat.terms[k];
    const int i = terms[k].indices[0];
    if (i < 3) {
      b.lo[i] = t.lo[0];
      b.hi[i] = t.hi[0];
    } else {
      c = std::max({c, std::abs(t.lo[0]), std::abs(t.hi[0])});
    }
  }
  if (c > 0) b.curvature = c;
  return b;
}

CollapseGuard make_collapse_guard(const GuardBox& box, const std::function<MaterialEval(const Strain6&)>& psi) {
  CollapseGuard g;
  g.box = box;
  g.box.lo[1] = std::clamp(box.lo[1], -kShearClamp, 0.0);
  g.box.hi[1] = std::clamp(box.hi[1], 0.0, kShearClamp);
  g.box.lo[0] = std::clamp(box.lo[0], kStretchClamp, 0.0);
  g.box.lo[2] = std::clamp(box.lo[2], kStretchClamp, 0.0);
  g.box.hi[0] = std::clamp(box.hi[0], 0.0, kStretchTop);
  g.box.hi[2] = std::clamp(box.hi[2], 0.0, kStretchTop);
  g.box.curvature = box.curvature > 0 && std::isfinite(box.curvature) ? box.curvature : 200;
  g.curvature_limit = kCurvatureLimit * g.box.curvature;
  // k: the largest energy above rest on a 5 x 5 x 5 grid of the in-plane box, at zero curvature
  // and at the bending bound along each axis (a material whose energy never rises gets k = 1e-3
  // J/m^2, so that collapse is still refused).
  const double rest = psi(Strain6::Zero()).psi;
  double top = 0;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      for (int l = 0; l < 5; ++l)
        for (int b = 0; b < 3; ++b) {
          Strain6 s = Strain6::Zero();
          s[0] = g.box.lo[0] + (g.box.hi[0] - g.box.lo[0]) * i / 4.0;
          s[1] = g.box.lo[1] + (g.box.hi[1] - g.box.lo[1]) * j / 4.0;
          s[2] = g.box.lo[2] + (g.box.hi[2] - g.box.lo[2]) * l / 4.0;
          if (b == 1) s[3] = g.box.curvature;
          if (b == 2) s[5] = g.box.curvature;
          const double e = psi(s).psi - rest;
          if (std::isfinite(e)) top = std::max(top, e);
        }
  g.scale = std::max(top, 1e-3);
  return g;
}

void add_collapse_guard(const CollapseGuard& g, const Strain6& s, MaterialEval& e) {
  if (!(g.scale > 0)) return;
  const double k = g.scale;
  // In-plane: each side is a function of one strain.
  for (int i : {0, 2}) {
    double v = 0, d = 0, dd = 0;
    add_side(k, s[i], g.box.lo[i], -1, 1 + g.box.lo[i], v, d, dd);
    add_side(k, s[i], g.box.hi[i], +1, 1 + g.box.hi[i], v, d, dd);
    e.psi += v;
    e.grad[i] += d;
    e.hess(i, i) += dd;
  }
  {
    double v = 0, d = 0, dd = 0;
    add_side(k, s[1], g.box.lo[1], -1, 1 + g.box.lo[1], v, d, dd);
    add_side(k, s[1], g.box.hi[1], +1, 1 - g.box.hi[1], v, d, dd);
    e.psi += v;
    e.grad[1] += d;
    e.hess(1, 1) += dd;
  }
  // Bending: tr g(K) over the principal curvatures, zero while both are within the bound.
  const double m = 0.5 * (s[3] + s[5]), r = std::hypot(0.5 * (s[3] - s[5]), s[4]);
  const double c = g.box.curvature, width = g.curvature_limit - c;
  if (!(std::abs(m) + r > c)) return;
  auto jet = [&](double, double l, int order, double* out) {
    const double sg = l < 0 ? -1 : 1;
    const GuardJet p = guard_profile((std::abs(l) - c) / width);
    const double d[4] = {p.v, p.d1, p.d2, p.d3};
    double f = 1, sgn = 1;
    for (int o = 0; o <= order; ++o) {
      out[o] = k * d[o] * f * sgn;  // d^o/dl^o of k psi((|l| - c)/width)
      f /= width;
      sgn *= sg;
    }
  };
  const double tau = 1e-3 * width;
  for (int which : {3, 5}) {
    const BendingEval b = eval_bending_general(jet, false, tau, which, 0.0, s[3], s[4], s[5]);
    e.psi += b.value;
    for (int a = 1; a < 4; ++a) {
      e.grad[2 + a] += b.grad[a];
      for (int bb = 1; bb < 4; ++bb) e.hess(2 + a, 2 + bb) += b.hess(a, bb);
    }
  }
}

double add_collapse_guard_value(const CollapseGuard& g, const Strain6& s, double psi) {
  if (!(g.scale > 0)) return psi;
  const double m = 0.5 * (s[3] + s[5]), r = std::hypot(0.5 * (s[3] - s[5]), s[4]);
  if (std::abs(m) + r > g.box.curvature) {  // (beyond the bending bound: the whole guard)
    MaterialEval e;
    e.psi = psi;
    add_collapse_guard(g, s, e);
    return e.psi;
  }
  const double k = g.scale;
  double unused_d = 0, unused_dd = 0;
  for (int i : {0, 2}) {
    double v = 0;
    add_side(k, s[i], g.box.lo[i], -1, 1 + g.box.lo[i], v, unused_d, unused_dd);
    add_side(k, s[i], g.box.hi[i], +1, 1 + g.box.hi[i], v, unused_d, unused_dd);
    psi += v;
  }
  double v = 0;
  add_side(k, s[1], g.box.lo[1], -1, 1 + g.box.lo[1], v, unused_d, unused_dd);
  add_side(k, s[1], g.box.hi[1], +1, 1 - g.box.hi[1], v, unused_d, unused_dd);
  return psi + v;
}

std::string describe(const CollapseGuard& g) {
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "collapse guard: k = %.4g J/m^2 outside s_x in [%.3g, %.3g], s_y in [%.3g, %.3g], s_a in [%.3g, %.3g], "
                "principal curvatures within +-%.4g /m (infinite at s_x, s_y = -1, s_x = %.3g, s_y = %.3g, |s_a| = 1, "
                "|curvature| = %.4g /m)",
                g.scale, g.box.lo[0], g.box.hi[0], g.box.lo[2], g.box.hi[2], g.box.lo[1], g.box.hi[1], g.box.curvature,
                2 * g.box.hi[0] + 1, 2 * g.box.hi[2] + 1, g.curvature_limit);
  return buf;
}

}  // namespace yarnhom
