#include "bake/pair_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/jet_layout.hpp"

namespace yarnhom {

namespace {

// The 1D term's slope and curvature at x, the curvature one-sided toward `sigma` (outward).
void one_d(const BakedTerm* t, double x, double sigma, double& slope, double& curv) {
  slope = curv = 0;
  if (!t) return;
  const double eps = 1e-12 * (1 + std::abs(x)) + 1e-9 * (t->hi[0] - t->lo[0]) / (t->n[0] - 1);
  const BakedJet1 at = eval_baked_1d(*t, x);
  const BakedJet1 out = eval_baked_1d(*t, x + sigma * eps);
  slope = at.df;
  curv = out.d2f;
}

}  // namespace

bool PairCheck::any() const {
  for (int k = 0; k < 4; ++k)
    if (falling[k] || corner_bends[k]) return true;
  return false;
}

std::string PairCheck::summary() const {
  std::string out;
  char buf[256];
  for (int e = 0; e < 4; ++e)
    if (falling[e]) {
      std::snprintf(buf, sizeof buf, "%stotal falls outward at %d of %d points of the %s edge (slope down to %.3g, %.2g%% of "
                    "the largest on the boundary)", out.empty() ? "" : "; ", falling[e], points[e], kBakedEdgeNames[e] + 5,
                    worst_slope[e], slope_scale > 0 ? 100 * -worst_slope[e] / slope_scale : 0.0);
      out += buf;
    }
  for (int c = 0; c < 4; ++c)
    if (corner_bends[c]) {
      std::snprintf(buf, sizeof buf, "%stotal bends down on diagonal rays of %s (twist %.3g, 1D curvatures %.3g, %.3g)",
                    out.empty() ? "" : "; ", kBakedCornerNames[c], twist[c], k_first[c], k_second[c]);
      out += buf;
    }
  return out;
}

PairCheck check_pair(const BakedTerm& t, const BakedTerm* ti, const BakedTerm* tj) {
  PairCheck p;
  p.pair = t.term.name;
  p.has_1d[0] = ti != nullptr;
  p.has_1d[1] = tj != nullptr;
  const BakedTerm* one[2] = {ti, tj};
  // Edges: the total's outward slope sigma (dPsi_IJ/dn + Psi_n'(X)) at 4 points per cell.
  std::array<std::vector<double>, 4> slopes;
  for (int e = 0; e < 4; ++e) {
    const int axis = e / 2, along = 1 - axis;
    const double sigma = e % 2 ? 1.0 : -1.0, X = e % 2 ? t.hi[axis] : t.lo[axis];
    double s1d, k1d;
    one_d(one[axis], X, sigma, s1d, k1d);
    const int m = 4 * (t.n[along] - 1) + 1;
    for (int k = 0; k < m; ++k) {
      double s[2];
      s[axis] = X;
      s[along] = k == m - 1 ? t.hi[along] : t.lo[along] + (t.hi[along] - t.lo[along]) * k / (m - 1);
      double jet[3];
      eval_baked_jet(t, s, 1, jet);
      const double v = sigma * (jet[1 + axis] + s1d);
      slopes[e].push_back(v);
      p.slope_scale = std::max(p.slope_scale, std::abs(v));
    }
    p.points[e] = m;
  }
  for (int e = 0; e < 4; ++e)
    for (double v : slopes[e])
      if (v < -1e-9 * p.slope_scale) {
        ++p.falling[e];
        p.worst_slope[e] = std::min(p.worst_slope[e], v);
      }
  // Rounding of a corner's twist: 1e-12 of the table's largest stored mixed derivative.
  double twist_scale = 0;
  for (double v : t.coef) twist_scale = std::max(twist_scale, std::abs(v));
  twist_scale *= 1e-12 * t.inv_h[0] * t.inv_h[1];
  for (int c = 0; c < 4; ++c) {
    const double sx = c & 1 ? 1.0 : -1.0, sy = c & 2 ? 1.0 : -1.0;
    const double s[2] = {c & 1 ? t.hi[0] : t.lo[0], c & 2 ? t.hi[1] : t.lo[1]};
    double jet[6];
    eval_baked_jet(t, s, 2, jet);
    double d;
    one_d(ti, s[0], sx, d, p.k_first[c]);
    one_d(tj, s[1], sy, d, p.k_second[c]);
    p.twist[c] = sx * sy * jet[jet_ch2(2, 0, 1)];
    const double T = p.twist[c];
    p.corner_bends[c] = T < -twist_scale && T * T * (1 - 1e-9) > std::max(p.k_first[c], 0.0) * std::max(p.k_second[c], 0.0);
  }
  return p;
}

const BakedTerm* find_one_d(const std::vector<BakedTerm>& terms, int strain) {
  for (const BakedTerm& t : terms)
    if (t.dim == 1 && t.term.indices[0] == strain) return &t;
  return nullptr;
}

std::vector<PairCheck> check_pairs(const BakedModel& m) {
  std::vector<BakedTerm> terms;
  for (const BakedTable& tb : m.tables) terms.push_back(make_baked_term(tb));
  std::vector<PairCheck> out(terms.size());
  for (size_t k = 0; k < terms.size(); ++k)
    if (terms[k].dim == 2)
      out[k] = check_pair(terms[k], find_one_d(terms, terms[k].term.indices[0]), find_one_d(terms, terms[k].term.indices[1]));
  return out;
}

}  // namespace yarnhom
