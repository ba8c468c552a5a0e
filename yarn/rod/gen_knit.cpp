// Weft knits from their stitch chart (KnitParams, generate.hpp): knit, purl and slipped stitches.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "yarn/rod/generate.hpp"
#include "yarn/rod/pattern_build.hpp"
#include "yarn/rod/yarn_spacing.hpp"

namespace yarnhom::yarn {
namespace {

struct Chart {
  const KnitParams& p;
  int nc, nw;
  double w, h;
  char at(int k, int j) const { return p.chart[((k % nc) + nc) % nc][((j % nw) + nw) % nw]; }
  // Courses above k that slip wale j before one knits or purls it; the stitch that catches the
  // loop (k, j) is then at course k + 1 + slipped_above.
  int slipped_above(int k, int j) const {
    int m = 0;
    while (at(k + 1 + m, j) == 'S') ++m;
    return m;
  }
  // The stitch that course k pulls its loop through in wale j: the last one below that is not
  // slipped.
  char below(int k, int j) const {
    int m = 1;
    while (at(k - m, j) == 'S') ++m;
    return at(k - m, j);
  }
  // The z of a float in course k, wale j: float_depth from the mid-plane on the face where the
  // course holds its yarn, the face of the worked stitch before it (the last one to its left
  // that is not slipped): in front (+z) after a purl, behind (-z) after a knit.
  double float_z(int k, int j) const {
    int m = 1;
    while (at(k, j - m) == 'S' && m < nw) ++m;
    return at(k, j - m) == 'K' ? -std::abs(p.float_depth) : std::abs(p.float_depth);
  }
  // Where the yarn of a stitch lies between wales (its sinkers): a knit stitch's behind the legs
  // of the loop it is pulled through, a purl stitch's in front of them, sinker_gap away (0: 2
  // depths); a float's on its face.
  double side(int k, int j) const {
    const char s = at(k, j);
    if (s == 'S') return float_z(k, j);
    const double old = below(k, j) == 'K' ? p.depth : -p.depth;
    const double gap = p.sinker_gap > 0 ? p.sinker_gap : 2 * p.depth;
    return s == 'K' ? old - gap : old + gap;
  }
  // Two neighbours' sinker: the farther of two on the same side, else between them.
  static double sinker(double a, double b) {
    if (a < 0 && b < 0) return std::min(a, b);
    if (a > 0 && b > 0) return std::max(a, b);
    return 0.5 * (a + b);
  }

  // The yarn of course k over wale j, th in [-pi, pi]: th = +-pi are the wale's edges, where
  // the course passes from one stitch to the next at the sinker level y_k - b - waist, at the
  // two stitches' sinker().
  Eigen::Vector3d point(int k, int j, double th) const {
    const double xj = -p.px / 2 + (j + 0.5) * w, yk = -p.py / 2 + (k + 0.5) * h;
    const double b = p.loop_height, c = p.depth;
    const double zs = sinker(side(k, j), side(k, th < 0 ? j - 1 : j + 1));
    const char s = at(k, j);
    double zh, zl;
    Eigen::Vector3d q;
    if (s == 'S') {
      // A float: straight across the wale, on its face, in front of (or behind) the slipped
      // loop's legs.
      zh = zl = float_z(k, j);
      q[0] = xj + w / (2 * M_PI) * th;
      q[1] = yk - b - p.waist + p.float_lift * 0.5 * (1 + std::cos(th));
    } else {
      // A loop (generate_stockinette's shape), held up through the courses that slip it: legs
      // at the stitch's face (+z knit, -z purl), head on the side away from the legs of the
      // stitch that catches it.
      const int m = slipped_above(k, j);
      const double sig = s == 'K' ? 1 : -1, sig_next = at(k + 1 + m, j) == 'K' ? 1 : -1;
      zl = (m > 0 && p.held_depth > 0 ? p.held_depth : c) * sig;
      // The catching stitch held itself (its legs at held_depth): with held_head_gap the head
      // lies that far from those legs, on the side away from them.
      if (p.held_head_gap > 0 && p.held_depth > 0 && slipped_above(k + 1 + m, j) > 0)
        zh = sig_next * (p.held_depth - p.held_head_gap);
      else
        zh = -(p.head_depth > 0 ? p.head_depth : c) * sig_next;
      const double u = 0.5 * (1 + std::cos(th));
      const double a = m > 0 && p.held_bulb > 0 ? p.held_bulb : p.bulb;
      q[0] = xj + w / (2 * M_PI) * (th + a * std::sin(2 * th)) + p.leg_spread * std::sin(th);
      q[1] = yk + b * std::cos(th) + p.waist * std::cos(3 * th) + p.held_height * m * h * u * u;
    }
    // z = A + B cos th + C cos 2th through the head (th = 0), the legs (+-pi/2) and the sinker
    // (+-pi), level at both ends.
    const double A = 0.5 * (0.5 * (zh + zs) + zl), C = 0.5 * (0.5 * (zh + zs) - zl), B = 0.5 * (zh - zs);
    q[2] = A + B * std::cos(th) + C * std::cos(2 * th);
    return q;
  }
};

}  // namespace

Pattern generate_knit(const KnitParams& prm) {
  const int nc = static_cast<int>(prm.chart.size());
  if (nc < 1) throw std::invalid_argument("knit: at least one course");
  const int nw = static_cast<int>(prm.chart[0].size());
  if (nw < 1) throw std::invalid_argument("knit: at least one wale");
  for (const auto& row : prm.chart)
    if (static_cast<int>(row.size()) != nw || row.find_first_not_of("KPS") != std::string::npos)
      throw std::invalid_argument("knit: courses of equal length made of 'K', 'P' and 'S'");
  for (int j = 0; j < nw; ++j) {
    bool held = false;
    for (int k = 0; k < nc; ++k) held |= prm.chart[k][j] != 'S';
    if (!held) throw std::invalid_argument("knit: a wale slipped in every course");
  }
  if (!(prm.radius > 0 && prm.px > 0 && prm.py > 0 && prm.loop_height > 0 && prm.depth > 0 && prm.edge > 0))
    throw std::invalid_argument("knit: radius, periods, loop height, depth and edge must be positive");
  const Chart ch{prm, nc, nw, prm.px / nw, prm.py / nc};
  Pattern pat;
  pat.name = prm.name;
  pat.px = prm.px;
  pat.py = prm.py;
  pat.radius = prm.radius;
  for (int k = 0; k < nc; ++k) {
    const auto curve = [&](double t) {
      const double s = t * nw;
      const int j = std::min(static_cast<int>(std::floor(s)), nw - 1);
      return ch.point(k, j, -M_PI + 2 * M_PI * (s - j));
    };
    double len = 0;
    const int fine = 256 * nw;
    for (int i = 0; i < fine; ++i) len += (curve(double(i + 1) / fine) - curve(double(i) / fine)).norm();
    const int n = std::max(3 * nw, static_cast<int>(std::lround(len / prm.edge)));
    add_yarn(pat, sample_equal_arc(curve, n), {1, 0});
  }
  if (prm.spacing > 0) space_yarns(pat, prm.spacing, prm.spacing_smoothing);
  set_rest_to_shape(pat);
  return pat;
}

}  // namespace yarnhom::yarn
