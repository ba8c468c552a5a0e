#include "accuracy/quadratic_error.hpp"

#include <cmath>
#include <stdexcept>

#include "core/jet_layout.hpp"
#include "core/terms.hpp"

namespace yarnhom {

std::vector<double> expansion_error_per_point(const TermFunction& f, int d, const std::vector<double>& points,
                                              const std::vector<double>& width, int samples) {
  if (d != 1 && d != 2) throw std::invalid_argument("quadratic expansion error: dimension must be 1 or 2");
  if (width.size() != size_t(d)) throw std::invalid_argument("quadratic expansion error: width needs d entries");
  const int side = d == 1 ? samples : static_cast<int>(std::lround(std::sqrt(double(samples))));
  if (side < 1 || (d == 2 && side * side != samples))
    throw std::invalid_argument("quadratic expansion error: in 2D the sample count must be a square");
  const int n = static_cast<int>(points.size()) / d;
  // Offsets of the midpoints from the centre, the same for every point.
  std::vector<double> off(size_t(samples) * d);
  for (int k = 0; k < samples; ++k) {
    const int a = d == 1 ? k : k / side, b = d == 1 ? 0 : k % side;
    off[k * d] = ((a + 0.5) / side - 0.5) * width[0];
    if (d == 2) off[k * d + 1] = ((b + 0.5) / side - 0.5) * width[1];
  }
  auto centre = f(points.data(), n, 2);  // jets at the points, [C, n]
  std::vector<double> out(n);
  // Evaluate a chunk of points' neighbourhoods per call (the network backend is batched).
  const int chunk = 16;
  std::vector<double> s;
  for (int p0 = 0; p0 < n; p0 += chunk) {
    const int np = std::min(chunk, n - p0);
    s.resize(size_t(np) * samples * d);
    for (int q = 0; q < np; ++q)
      for (int k = 0; k < samples; ++k)
        for (int i = 0; i < d; ++i) s[(size_t(q) * samples + k) * d + i] = points[(p0 + q) * d + i] + off[k * d + i];
    auto v = f(s.data(), np * samples, 0);
    for (int q = 0; q < np; ++q) {
      const int p = p0 + q;
      auto J = [&](int c) { return centre[size_t(c) * n + p]; };
      double acc = 0;
      for (int k = 0; k < samples; ++k) {
        const double* o = &off[k * d];
        double t2 = J(0);
        if (d == 1) {
          t2 += J(1) * o[0] + 0.5 * J(2) * o[0] * o[0];
        } else {
          t2 += J(1) * o[0] + J(2) * o[1] + 0.5 * J(3) * o[0] * o[0] + J(4) * o[0] * o[1] + 0.5 * J(5) * o[1] * o[1];
        }
        acc += std::abs(v[size_t(q) * samples + k] - t2);
      }
      out[p] = acc / samples;
    }
  }
  return out;
}

double quadratic_expansion_error(const TermFunction& f, int d, const std::vector<double>& points,
                                 const std::vector<double>& width, int samples) {
  auto D = expansion_error_per_point(f, d, points, width, samples);
  if (D.empty()) throw std::invalid_argument("quadratic expansion error: no points");
  double s = 0;
  for (double x : D) s += x;
  return s / D.size();
}

double combine_expansion_errors(const std::map<std::string, double>& per_term) {
  double s1 = 0, s2 = 0;
  int n1 = 0, n2 = 0;
  for (const auto& [name, e] : per_term) {
    if (term_by_name(name).dim() == 1) { s1 += e; ++n1; }
    else { s2 += e; ++n2; }
  }
  return (n1 ? s1 / n1 : 0.0) + (n2 ? s2 / n2 : 0.0);
}

}  // namespace yarnhom
