#include "produce/branch_check.hpp"

#include <cmath>
#include <stdexcept>

namespace yarnhom::yarn {

namespace {

// Calls f(a, b, axis) for every grid edge (a before b along the axis).
template <class F>
void for_each_edge(int dim, int m, F f) {
  if (dim == 1) {
    for (int i = 0; i + 1 < m; ++i) f(i, i + 1, 0);
    return;
  }
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      if (i + 1 < m) f(i * m + j, (i + 1) * m + j, 0);
      if (j + 1 < m) f(i * m + j, i * m + j + 1, 1);
    }
}

void check_sizes(int dim, int m, size_t n, size_t t, size_t g, size_t ok, size_t psi) {
  if (dim != 1 && dim != 2) throw std::invalid_argument("grid_edges: a term has 1 or 2 axes");
  const size_t want = dim == 1 ? size_t(m) : size_t(m) * size_t(m);
  if (m < 2 || n != want || t != want || g != want || ok != want || psi != want)
    throw std::invalid_argument("grid_edges: " + std::to_string(want) + " nodes expected for a grid of " +
                                std::to_string(m) + " per axis");
}

}  // namespace

std::vector<double> edge_scales(int dim, int m, const std::vector<Eigen::VectorXd>& t,
                                const std::vector<Eigen::VectorXd>& g, const std::vector<bool>& ok) {
  check_sizes(dim, m, t.size(), t.size(), g.size(), ok.size(), t.size());
  std::vector<double> sum(dim, 0.0);
  std::vector<int> count(dim, 0);
  for_each_edge(dim, m, [&](int a, int b, int d) {
    if (!ok[a] || !ok[b]) return;
    sum[d] += std::abs(0.5 * (g[a][d] + g[b][d]) * (t[b][d] - t[a][d]));
    ++count[d];
  });
  std::vector<double> s(dim);
  // A term flat along an axis (no change anywhere) has no scale of its own: any gap is then
  // measured against the smallest positive double rather than dividing by zero.
  for (int d = 0; d < dim; ++d) s[d] = count[d] && sum[d] > 0 ? sum[d] / count[d] : 1e-300;
  return s;
}

std::vector<GridEdge> grid_edges(int dim, int m, const std::vector<Eigen::VectorXd>& t, const std::vector<double>& psi,
                                 const std::vector<Eigen::VectorXd>& g, const std::vector<bool>& ok) {
  check_sizes(dim, m, t.size(), t.size(), g.size(), ok.size(), psi.size());
  const std::vector<double> scale = edge_scales(dim, m, t, g, ok);
  std::vector<GridEdge> out;
  for_each_edge(dim, m, [&](int a, int b, int d) {
    if (!ok[a] || !ok[b]) return;
    const double mismatch = (psi[b] - psi[a]) - 0.5 * (g[a][d] + g[b][d]) * (t[b][d] - t[a][d]);
    out.push_back({a, b, d, std::abs(mismatch) / scale[d]});
  });
  return out;
}

std::vector<GridEdge> inconsistent_edges(const std::vector<GridEdge>& edges, double tolerance) {
  std::vector<GridEdge> out;
  for (const GridEdge& e : edges)
    if (!(e.relative <= tolerance)) out.push_back(e);
  return out;
}

}  // namespace yarnhom::yarn
