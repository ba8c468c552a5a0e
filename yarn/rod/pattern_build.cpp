#include "yarn/rod/pattern_build.hpp"

#include <cmath>
#include <stdexcept>

#include "yarn/rod/rod.hpp"

namespace yarnhom::yarn {

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

std::vector<Eigen::Vector3d> sample_equal_arc(const std::function<Eigen::Vector3d(double)>& c, int n) {
  if (n < 3) throw std::invalid_argument("generator: at least 3 vertices per yarn");
  const int m = 64 * n;
  std::vector<double> s(m + 1, 0.0);
  Eigen::Vector3d prev = c(0.0);
  for (int k = 1; k <= m; ++k) {
    const Eigen::Vector3d cur = c(double(k) / m);
    s[k] = s[k - 1] + (cur - prev).norm();
    prev = cur;
  }
  std::vector<Eigen::Vector3d> pts;
  int k = 0;
  for (int j = 0; j < n; ++j) {
    const double target = s[m] * j / n;
    while (k < m && s[k + 1] < target) ++k;
    const double f = s[k + 1] > s[k] ? (target - s[k]) / (s[k + 1] - s[k]) : 0.0;
    pts.push_back(c((k + f) / m));
  }
  return pts;
}

void set_rest_to_shape(Pattern& p) {
  complete_rest_state(p);
  const Topology t = topology(p);
  const int n = p.size();
  for (int v = 0; v < n; ++v) {
    const int a = t.prev[v];
    // The joint's three points as seen from v: the previous vertex moved back by its edge's
    // offset, the next forward by v's.
    const Eigen::Vector3d xa = p.x[v] - stored_edge(p, t, a), xb = p.x[v] + stored_edge(p, t, v);
    Vec11 q;
    q << xa, p.x[v], xb, p.theta[a], p.theta[v];
    const JointFrames f{{stored_edge(p, t, a).normalized(), p.ref_d1[a]},
                        {stored_edge(p, t, v).normalized(), p.ref_d1[v]},
                        p.ref_twist[v]};
    const JointStrain js = joint_strain(q, f);
    p.rest_kappa[v] = Eigen::Vector2d(js.k1, js.k2);
    p.rest_twist[v] = js.twist;
  }
}

double total_rest_length(const Pattern& p) {
  double L = 0;
  for (double l : p.rest_length) L += l;
  return L;
}

}  // namespace yarnhom::yarn
