// Woven patterns from their weave matrix (generate.hpp, WeaveParams): plain, basket, satin.
#include <cmath>
#include <complex>
#include <stdexcept>

#include "yarn/rod/generate.hpp"
#include "yarn/rod/pattern_build.hpp"

namespace yarnhom::yarn {
namespace {

// The height profile of a yarn that crosses n yarns at phases 2 pi j / n with sides s_j = +-1
// (+1: over): the mean of s lifts the yarn (a float rides on one side), the sequence's
// fundamental harmonic shapes it, so that the yarn rises where it passes over and sinks where
// it passes under, as smoothly as the sequence allows.
struct Profile {
  double mean = 0, phase = 0;
};
Profile profile(const std::vector<int>& s) {
  const int n = static_cast<int>(s.size());
  std::complex<double> c1 = 0;
  Profile p;
  for (int j = 0; j < n; ++j) {
    p.mean += double(s[j]) / n;
    c1 += double(s[j]) * std::polar(1.0, -2 * M_PI * j / n);
  }
  if (std::abs(c1) < 1e-12) throw std::invalid_argument("weave: a yarn whose crossings have no fundamental harmonic");
  p.phase = std::arg(c1);
  return p;
}

// The fundamental cos(phi), flattened by its third harmonic: (cos phi - k cos 3 phi) / (1 - k)
// (k = 0: a cosine; k = 1/6: flat over the middle half of each half period).
double shape(double phi, double k) { return (std::cos(phi) - k * std::cos(3 * phi)) / (1 - k); }

// The profile of a yarn whose side mean is m: one that mostly passes under (m < 0) rises to a
// peak narrowed by the power p >= 1, 2 u^p - 1 with u = (1 + cos phi) / 2, and lies lower and
// flatter elsewhere; one mostly over (m > 0) dips the same way; p = 1 (or m = 0): shape() above.
double profile_shape(double phi, double k, double p, double m) {
  if (p == 1 || m == 0) return shape(phi, k);
  const double u = 0.5 * (1 + std::cos(phi));
  return m < 0 ? 2 * std::pow(u, p) - 1 : 1 - 2 * std::pow(1 - u, p);
}

}  // namespace

Pattern generate_weave(const WeaveParams& prm) {
  const int nw = static_cast<int>(prm.weave.size());
  if (nw < 2) throw std::invalid_argument("weave: at least 2 wefts");
  const int nj = static_cast<int>(prm.weave[0].size());
  if (nj < 2) throw std::invalid_argument("weave: at least 2 warps");
  for (const auto& row : prm.weave)
    if (static_cast<int>(row.size()) != nj || row.find_first_not_of("01") != std::string::npos)
      throw std::invalid_argument("weave: rows of equal length made of '0' and '1'");
  if (!(prm.peak >= 1)) throw std::invalid_argument("weave: peak must be at least 1");
  if (!(prm.radius > 0 && prm.px > 0 && prm.py > 0)) throw std::invalid_argument("weave: radius and periods must be positive");
  if (prm.px / nj < 2 * prm.radius || prm.py / nw < 2 * prm.radius)
    throw std::invalid_argument("weave: parallel yarns closer than a diameter");
  Pattern pat;
  pat.name = prm.name;
  pat.px = prm.px;
  pat.py = prm.py;
  pat.radius = prm.radius;
  const double ax = prm.px / nj, ay = prm.py / nw;
  const int nsx = prm.samples_weft > 0 ? prm.samples_weft : static_cast<int>(std::ceil(prm.px / (1.2 * prm.radius)));
  const int nsy = prm.samples_warp > 0 ? prm.samples_warp : static_cast<int>(std::ceil(prm.py / (1.2 * prm.radius)));
  for (int i = 0; i < nw; ++i) {  // wefts along x: over warp j where weave[i][j] == '1'
    std::vector<int> s(nj);
    for (int j = 0; j < nj; ++j) s[j] = prm.weave[i][j] == '1' ? 1 : -1;
    const Profile pr = profile(s);
    const double y = -prm.py / 2 + (i + 0.5) * ay, x0 = -prm.px / 2 + 0.5 * ax;
    add_yarn(pat, sample_equal_arc([&](double t) {
               const double x = -prm.px / 2 + t * prm.px;
               return Eigen::Vector3d(x, y, prm.float_lift * pr.mean +
                                                prm.weft_amplitude * profile_shape(2 * M_PI * (x - x0) / prm.px + pr.phase, prm.flatness, prm.peak, pr.mean));
             }, nsx), {1, 0});
  }
  for (int j = 0; j < nj; ++j) {  // warps along y: over weft i where weave[i][j] == '0'
    std::vector<int> s(nw);
    for (int i = 0; i < nw; ++i) s[i] = prm.weave[i][j] == '1' ? -1 : 1;
    const Profile pr = profile(s);
    const double x = -prm.px / 2 + (j + 0.5) * ax, y0 = -prm.py / 2 + 0.5 * ay;
    add_yarn(pat, sample_equal_arc([&](double t) {
               const double y = -prm.py / 2 + t * prm.py;
               return Eigen::Vector3d(x, y, prm.float_lift * pr.mean +
                                                prm.warp_amplitude * profile_shape(2 * M_PI * (y - y0) / prm.py + pr.phase, prm.flatness, prm.peak, pr.mean));
             }, nsy), {0, 1});
  }
  set_rest_to_shape(pat);
  return pat;
}

}  // namespace yarnhom::yarn
