#include "yarn/rod/generate.hpp"

#include <cmath>
#include <stdexcept>

namespace yarnhom::yarn {
namespace {

// Appends one closed yarn given its unwrapped polyline over exactly one period (the point
// after the last is the first shifted by `period_shift` tiles), wrapping vertices into the
// tile [-px/2, px/2) x [-py/2, py/2) and recording edge offsets.
void add_yarn(Pattern& pat, const std::vector<Eigen::Vector3d>& pts, Eigen::Vector2i period_shift) {
  const int base = pat.size(), n = static_cast<int>(pts.size());
  std::vector<Eigen::Vector2i> cell(n);
  for (int k = 0; k < n; ++k) {
    const int cx = static_cast<int>(std::floor(pts[k][0] / pat.px + 0.5));
    const int cy = static_cast<int>(std::floor(pts[k][1] / pat.py + 0.5));
    cell[k] = {cx, cy};
    pat.x.push_back(pts[k] - Eigen::Vector3d(cx * pat.px, cy * pat.py, 0));
    pat.theta.push_back(0.0);
  }
  for (int k = 0; k < n; ++k) {
    const int next = (k + 1) % n;
    const Eigen::Vector2i cn = cell[next] + (k + 1 == n ? period_shift : Eigen::Vector2i::Zero());
    const Eigen::Vector2i o = cn - cell[k];
    if (o.cwiseAbs().maxCoeff() > 1) throw std::invalid_argument("generator: an edge spans more than one tile");
    pat.edges.push_back({base + k, base + next, o[0], o[1]});
  }
}

}  // namespace

Pattern generate_woven(const WovenParams& prm) {
  if (prm.group < 1 || prm.group > 2) throw std::invalid_argument("woven: group must be 1 (plain) or 2 (basket)");
  if (!(prm.radius > 0)) throw std::invalid_argument("woven: radius must be positive");
  const double r = prm.radius, a = prm.spacing > 0 ? prm.spacing : 4 * r;
  if (a < 2.5 * r) throw std::invalid_argument("woven: spacing must be at least 2.5 radii");
  const int g = prm.group, m = prm.samples_per_spacing, ny = 2 * g;
  Pattern pat;
  pat.name = g == 1 ? "plain" : "basket";
  pat.px = pat.py = 2 * g * a;
  pat.radius = r;
  // Crossing heights +-r (centrelines 2r apart: touching); c_g lifts the profile so that the
  // outermost crossing of a group sits at exactly r.
  const double cg = 1.0 / std::cos(M_PI * (g - 1) / (2.0 * g));
  const double L = pat.px, start = -L / 2, centre = -L / 2 + a / 2 + (g - 1) * a / 2;
  const int N = m * ny;
  for (int k = 0; k < ny; ++k) {  // wefts along x, at y_k
    const double y = -L / 2 + (k + 0.5) * a;
    std::vector<Eigen::Vector3d> pts;
    for (int j = 0; j < N; ++j) {
      const double x = start + L * j / N;
      pts.emplace_back(x, y, r * cg * std::cos(M_PI * (x - centre) / (g * a) + M_PI * (k / g)));
    }
    add_yarn(pat, pts, {1, 0});
  }
  for (int i = 0; i < ny; ++i) {  // warps along y, at x_i
    const double x = -L / 2 + (i + 0.5) * a;
    std::vector<Eigen::Vector3d> pts;
    for (int j = 0; j < N; ++j) {
      const double y = start + L * j / N;
      pts.emplace_back(x, y, -r * cg * std::cos(M_PI * (y - centre) / (g * a) + M_PI * (i / g)));
    }
    add_yarn(pat, pts, {0, 1});
  }
  complete_rest_state(pat);
  return pat;
}

Pattern generate_stockinette(const StockinetteParams& prm) {
  if (!(prm.radius > 0)) throw std::invalid_argument("stockinette: radius must be positive");
  const double r = prm.radius;
  const double w = prm.wale > 0 ? prm.wale : 7.2 * r, h = prm.course > 0 ? prm.course : 4.4 * r;
  const double b = prm.loop_height > 0 ? prm.loop_height : 3.2 * r, c = prm.depth > 0 ? prm.depth : 1.2 * r;
  if (prm.samples < 8) throw std::invalid_argument("stockinette: at least 8 samples per loop");
  Pattern pat;
  pat.name = "stockinette";
  pat.px = w;
  pat.py = h;
  pat.radius = r;
  std::vector<Eigen::Vector3d> pts;
  for (int k = 0; k < prm.samples; ++k) {
    const double th = -M_PI + 2 * M_PI * k / prm.samples;
    pts.emplace_back(w / (2 * M_PI) * (th + prm.bulb * std::sin(2 * th)), b * std::cos(th), -c * std::cos(2 * th));
  }
  add_yarn(pat, pts, {1, 0});
  complete_rest_state(pat);
  return pat;
}

std::vector<std::string> builtin_pattern_names() { return {"basket", "plain", "stockinette"}; }

bool is_builtin_pattern(const std::string& name) {
  for (const auto& n : builtin_pattern_names())
    if (n == name) return true;
  return false;
}

Pattern builtin_pattern(const std::string& name) {
  if (name == "basket") return generate_woven({});
  if (name == "plain") {
    WovenParams p;
    p.group = 1;
    return generate_woven(p);
  }
  if (name == "stockinette") return generate_stockinette({});
  throw std::invalid_argument("unknown built-in pattern '" + name + "' (known: basket, plain, stockinette)");
}

}  // namespace yarnhom::yarn
