#include "material/baked_eval.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/jet_layout.hpp"

namespace yarnhom {

namespace {

// Cubic Hermite data of a cell [f0, h f0', f1, h f1'] -> power coefficients in u in [0, 1]:
// p(u) = f0 H00 + h f0' H10 + f1 H01 + h f1' H11, expanded.
constexpr double kM[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {-3, -2, 3, -1}, {2, 1, -2, 1}};

// d^a/du^a of u^k for a, k in 0..3.
inline void power_derivs(double u, double p[4][4]) {
  const double u2 = u * u;
  p[0][0] = 1; p[0][1] = u;  p[0][2] = u2;    p[0][3] = u2 * u;
  p[1][0] = 0; p[1][1] = 1;  p[1][2] = 2 * u; p[1][3] = 3 * u2;
  p[2][0] = 0; p[2][1] = 0;  p[2][2] = 2;     p[2][3] = 6 * u;
  p[3][0] = 0; p[3][1] = 0;  p[3][2] = 0;     p[3][3] = 6;
}

// Cell index and local coordinate of x on axis k; x is inside the box (clamped by the caller).
// The last knot belongs to the last cell, so a boundary point uses the inside cell.
// A NaN strain (a diverging simulation) takes cell 0 and comes out as NaN, never as an index
// out of range.
inline int locate(const BakedTerm& t, int k, double x, double& u) {
  const double q = (x - t.lo[k]) * t.inv_h[k];
  const int last = t.n[k] - 2;
  const int i = q >= 0 ? (q < last ? static_cast<int>(q) : last) : 0;
  u = q - i;
  return i;
}

// One-sided partials D[a] (a <= 3) of a 1D table at x inside the box, physical units.
void partials_1d(const BakedTerm& t, double x, double D[4]) {
  double u;
  const int i = locate(t, 0, x, u);
  const double* c = t.coef.data() + 4 * size_t(i);
  double p[4][4];
  power_derivs(u, p);
  double s = 1;
  for (int a = 0; a < 4; ++a, s *= t.inv_h[0])
    D[a] = s * (p[a][0] * c[0] + p[a][1] * c[1] + p[a][2] * c[2] + p[a][3] * c[3]);
}

// Partials D[a][b] (a < na, b < nb; na, nb <= 4) of a 2D table at (x, y) inside the box,
// physical units. Only what the caller needs is computed: the simulator's calls want na, nb <= 3.
void partials_2d(const BakedTerm& t, double x, double y, int na, int nb, double D[4][4]) {
  double u, v;
  const int i = locate(t, 0, x, u), j = locate(t, 1, y, v);
  const double* A = t.coef.data() + 16 * (size_t(i) * (t.n[1] - 1) + j);
  double pu[4][4], pv[4][4];
  power_derivs(u, pu);
  power_derivs(v, pv);
  double R[4][4];  // R[b][k] = sum_l A[k][l] pv[b][l]
  for (int b = 0; b < nb; ++b)
    for (int k = 0; k < 4; ++k)
      R[b][k] = A[4 * k] * pv[b][0] + A[4 * k + 1] * pv[b][1] + A[4 * k + 2] * pv[b][2] +
                A[4 * k + 3] * pv[b][3];
  double sa = 1;
  for (int a = 0; a < na; ++a, sa *= t.inv_h[0]) {
    double sb = sa;
    for (int b = 0; b < nb; ++b, sb *= t.inv_h[1])
      D[a][b] = sb * (pu[a][0] * R[b][0] + pu[a][1] * R[b][1] + pu[a][2] * R[b][2] + pu[a][3] * R[b][3]);
  }
}

// Weights w[m][i] with which the m-th derivative along one axis combines the partials D_i at
// the clamped point: inside, w = delta(i, m); outside by dx, the extension
// sum_{i<=p} D_i dx^i / i! differentiated m times, p = 2 (safeguard) or 1 (linear).
void axis_weights(bool outside, double dx, double w[4][4], int p = 2) {
  for (int m = 0; m < 4; ++m)
    for (int i = 0; i < 4; ++i) w[m][i] = 0;
  if (!outside) {
    for (int m = 0; m < 4; ++m) w[m][m] = 1;
    return;
  }
  for (int m = 0; m <= p; ++m)
    for (int i = m; i <= p; ++i) {
      const int e = i - m;
      w[m][i] = e == 0 ? 1.0 : e == 1 ? dx : 0.5 * dx * dx;
    }
}

int side(const BakedTerm& t, int k, double x) { return x < t.lo[k] ? -1 : x > t.hi[k] ? 1 : 0; }

// Builds the per-cell coefficients; no safeguard check.
BakedTerm build(const BakedTable& tb) {
  const int d = tb.dim();
  if (d != 1 && d != 2) throw std::invalid_argument("baked table of dimension other than 1 or 2");
  if (tb.knots.size() != size_t(d) || tb.lower.size() != size_t(d) || tb.upper.size() != size_t(d))
    throw std::invalid_argument("baked table '" + tb.term.name + "': box or knots of the wrong size");
  BakedTerm t;
  t.term = tb.term;
  t.dim = d;
  t.linear = tb.extrapolation == kBakedLinear;
  for (int k = 0; k < d; ++k) {
    if (tb.knots[k] < 2 || !(tb.lower[k] < tb.upper[k]))
      throw std::invalid_argument("baked table '" + tb.term.name + "': empty box or < 2 knots");
    t.lo[k] = tb.lower[k];
    t.hi[k] = tb.upper[k];
    t.n[k] = tb.knots[k];
    t.inv_h[k] = (tb.knots[k] - 1) / (tb.upper[k] - tb.lower[k]);
  }
  const size_t nk = tb.num_knots();
  if (tb.f.size() != nk || tb.f_x.size() != nk || (d == 2 && (tb.f_y.size() != nk || tb.f_xy.size() != nk)))
    throw std::invalid_argument("baked table '" + tb.term.name + "': knot arrays of the wrong size");
  if (d == 1) {
    const double h = 1.0 / t.inv_h[0];
    t.coef.resize(4 * size_t(t.n[0] - 1));
    for (int i = 0; i + 1 < t.n[0]; ++i) {
      const double g[4] = {tb.f[i], h * tb.f_x[i], tb.f[i + 1], h * tb.f_x[i + 1]};
      for (int k = 0; k < 4; ++k)
        t.coef[4 * i + k] = kM[k][0] * g[0] + kM[k][1] * g[1] + kM[k][2] * g[2] + kM[k][3] * g[3];
    }
    return t;
  }
  const double hx = 1.0 / t.inv_h[0], hy = 1.0 / t.inv_h[1];
  const int n1 = t.n[1];
  t.coef.resize(16 * size_t(t.n[0] - 1) * (n1 - 1));
  for (int i = 0; i + 1 < t.n[0]; ++i)
    for (int j = 0; j + 1 < n1; ++j) {
      // G[alpha][beta]: alpha over x data (f0, h f_x0, f1, h f_x1), beta likewise over y.
      double G[4][4];
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
          const size_t q = size_t(i + a) * n1 + (j + b);
          G[2 * a][2 * b] = tb.f[q];
          G[2 * a][2 * b + 1] = hy * tb.f_y[q];
          G[2 * a + 1][2 * b] = hx * tb.f_x[q];
          G[2 * a + 1][2 * b + 1] = hx * hy * tb.f_xy[q];
        }
      double MG[4][4];  // M G
      for (int k = 0; k < 4; ++k)
        for (int b = 0; b < 4; ++b)
          MG[k][b] = kM[k][0] * G[0][b] + kM[k][1] * G[1][b] + kM[k][2] * G[2][b] + kM[k][3] * G[3][b];
      double* A = t.coef.data() + 16 * (size_t(i) * (n1 - 1) + j);
      for (int k = 0; k < 4; ++k)
        for (int l = 0; l < 4; ++l)
          A[4 * k + l] = MG[k][0] * kM[l][0] + MG[k][1] * kM[l][1] + MG[k][2] * kM[l][2] + MG[k][3] * kM[l][3];
    }
  return t;
}

void check_close(const std::string& what, double stored, double computed, double scale,
                 const BakedTable& tb, const std::string& file) {
  if (std::abs(stored - computed) <= 1e-8 * (scale + std::abs(computed)) + 1e-300) return;
  throw std::invalid_argument((file.empty() ? "" : file + ": ") + "/tables/" + tb.term.name +
                              ": stored safeguard coefficient " + what + " = " +
                              std::to_string(stored) + " disagrees with the knots (" +
                              std::to_string(computed) + "); the file is corrupt or was edited, or "
                              "was baked by a yarnhom older than the safeguard that rises outward by "
                              "construction (docs/bake.md): bake the model again");
}

}  // namespace

bool SafeguardDepartures::any() const {
  for (const Side& s : sides)
    if (s.curvature_raised || s.curvature_dropped > 0) return true;
  return false;
}

void compute_safeguard(BakedTable& tb, SafeguardDepartures* dep) {
  const BakedTerm t = build(tb);
  if (dep) *dep = {};
  if (t.dim == 1) {
    for (int e = 0; e < 2; ++e) {
      const double X = e == 0 ? t.lo[0] : t.hi[0];
      double D[4];
      partials_1d(t, X, D);
      // The paper's form a s^2 + b s + c of the quadratic matching f, f' and the curvature at
      // X; a negative curvature (only possible without bake's 1D end repair) is continued
      // as 0, which costs C2 but never lets the energy turn down. A linear table continues
      // with its tangent (a = 0).
      SafeguardDepartures::Side side;
      side.knots = 1;
      double gmax = 0;
      for (double g : tb.f_x) gmax = std::max(gmax, std::abs(g));
      if (!t.linear && D[2] < -1e-9 * gmax * t.inv_h[0]) side.curvature_raised = 1;
      const double a = t.linear ? 0.0 : 0.5 * std::max(D[2], 0.0), b = D[1] - 2 * a * X, c = D[0] - a * X * X - b * X;
      (e == 0 ? tb.safeguard_lower : tb.safeguard_upper) = {a, b, c};
      if (dep) dep->sides.push_back(side);
    }
    return;
  }
  // 2D: first order across every edge and in every corner (see the header). Per edge: g0, g0',
  // g1, g1' from the table, g2 = g2' = 0; the boundary curvature d2f/dn2 the paper would have
  // continued is only measured, for the report.
  std::vector<SafeguardDepartures::Side> sides(4);
  for (int e = 0; e < 4; ++e) {
    const int axis = e / 2, along = 1 - axis;  // the edge's normal axis and its own axis
    const double X = (e % 2 == 0) ? t.lo[axis] : t.hi[axis];
    const int n = t.n[along];
    std::vector<double>& out = tb.edges[e];
    out.assign(size_t(n) * 6, 0.0);
    sides[e].knots = n;
    double kmax = 0;
    std::vector<double> K(n);
    for (int j = 0; j < n; ++j) {
      const double y = j == n - 1 ? t.hi[along] : t.lo[along] + j / t.inv_h[along];
      double D[4][4];
      if (axis == 0) partials_2d(t, X, y, 3, 3, D);
      else partials_2d(t, y, X, 3, 3, D);
      for (int k = 0; k < 2; ++k) {
        out[6 * j + 2 * k] = axis == 0 ? D[k][0] : D[0][k];
        out[6 * j + 2 * k + 1] = axis == 0 ? D[k][1] : D[1][k];
      }
      K[j] = axis == 0 ? D[2][0] : D[0][2];
      kmax = std::max(kmax, std::abs(K[j]));
    }
    if (!t.linear) {
      for (double k : K)
        if (k < -1e-9 * kmax) ++sides[e].curvature_raised;
      sides[e].curvature_dropped = kmax;
    }
  }
  for (int c = 0; c < 4; ++c) {
    const bool ux = c & 1, uy = c & 2;
    const double X = ux ? t.hi[0] : t.lo[0], Y = uy ? t.hi[1] : t.lo[1];
    double D[4][4];
    partials_2d(t, X, Y, 2, 2, D);
    tb.corners[c] = {D[0][0], D[1][0], D[0][1], 0.0, D[1][1], 0.0, 0.0, 0.0};
  }
  if (dep) {
    dep->sides = sides;
    dep->first_order = !t.linear;
  }
}

BakedTerm make_baked_term(const BakedTable& tb, const std::string& file) {
  BakedTerm t;
  try {
    t = build(tb);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument((file.empty() ? "" : file + ": ") + e.what());
  }
  BakedTable ref = tb;
  compute_safeguard(ref);
  if (t.dim == 1) {
    for (int e = 0; e < 2; ++e) {
      const auto& s = e == 0 ? tb.safeguard_lower : tb.safeguard_upper;
      const auto& r = e == 0 ? ref.safeguard_lower : ref.safeguard_upper;
      const double X = e == 0 ? t.lo[0] : t.hi[0];
      // c = f - a X^2 - b X cancels: compare at the scale of its parts.
      const double scale = std::abs(r[0]) * X * X + std::abs(r[1] * X) + std::abs(r[2]);
      const char* names[3] = {"a", "b", "c"};
      for (int k = 0; k < 3; ++k)
        check_close(std::string(e == 0 ? "lower " : "upper ") + names[k], s[k], r[k],
                    k == 0 ? std::abs(r[0]) : k == 1 ? std::abs(r[1]) + std::abs(2 * r[0] * X) : scale, tb, file);
    }
    return t;
  }
  // The first-order columns (g0, g0', g1, g1'; a00 a10 a01 a11) must match the knots. The
  // curvature columns (g2, g2'; a20 a02 a21 a12) are 0 in a file of this bake; a file baked
  // before the first-order continuation (the same format, version 1) holds its rising band
  // curvatures there: it is read, and continued to first order like every other (docs/bake.md).
  // A first-order entry must match the reference; a curvature entry must be finite, and a
  // nonzero one marks a file of the older bake.
  auto check_entry = [&](const std::string& what, double v, double r, double scale, bool curvature) {
    if (curvature) {
      if (!std::isfinite(v)) check_close(what, v, 0.0, scale, tb, file);
      t.legacy_safeguard = t.legacy_safeguard || v != 0;
    } else {
      check_close(what, v, r, scale, tb, file);
    }
  };
  auto curvature_column = [](size_t q) { return q % 6 >= 4; };
  auto corner_curvature = [](int q) { return q == 3 || q >= 5; };
  for (int e = 0; e < 4; ++e) {
    double scale = 0;
    for (size_t q = 0; q < ref.edges[e].size(); ++q)
      if (!curvature_column(q)) scale = std::max(scale, std::abs(ref.edges[e][q]));
    if (tb.edges[e].size() != ref.edges[e].size())
      throw std::invalid_argument((file.empty() ? "" : file + ": ") + "/tables/" + tb.term.name + ": safeguard/" +
                                  kBakedEdgeNames[e] + " has the wrong size");
    for (size_t q = 0; q < ref.edges[e].size(); ++q) {
      check_entry(std::string(kBakedEdgeNames[e]) + "[" + std::to_string(q) + "]", tb.edges[e][q], ref.edges[e][q],
                  scale, curvature_column(q));
    }
  }
  for (int c = 0; c < 4; ++c) {
    double scale = 0;
    for (int q = 0; q < 8; ++q)
      if (!corner_curvature(q)) scale = std::max(scale, std::abs(ref.corners[c][q]));
    for (int q = 0; q < 8; ++q) {
      check_entry(std::string(kBakedCornerNames[c]) + "[" + std::to_string(q) + "]", tb.corners[c][q],
                  ref.corners[c][q], scale, corner_curvature(q));
    }
  }
  return t;
}

int baked_sector(const BakedTerm& t, const double* s) {
  if (t.dim == 1) {
    const int a = side(t, 0, s[0]);
    return a < 0 ? 1 : a > 0 ? 2 : 0;
  }
  const int a = side(t, 0, s[0]), b = side(t, 1, s[1]);
  if (a == 0 && b == 0) return 0;
  if (b == 0) return a < 0 ? 1 : 2;
  if (a == 0) return b < 0 ? 3 : 4;
  return 5 + (a > 0 ? 1 : 0) + (b > 0 ? 2 : 0);
}

void eval_baked_jet(const BakedTerm& t, const double* s, int order, double* out) {
  if (order < 0 || order > 3) throw std::invalid_argument("eval_baked_jet: order must be 0..3");
  if (t.dim == 1) {
    const double xc = std::clamp(s[0], t.lo[0], t.hi[0]), dx = s[0] - xc;
    double D[4], w[4][4];
    partials_1d(t, xc, D);
    if (s[0] != xc && !t.linear) D[2] = std::max(D[2], 0.0);  // the continuation's curvature (see the header)
    axis_weights(s[0] != xc, dx, w, t.linear ? 1 : 2);
    for (int m = 0; m <= order; ++m) out[m] = w[m][0] * D[0] + w[m][1] * D[1] + w[m][2] * D[2] + w[m][3] * D[3];
    return;
  }
  const double xc = std::clamp(s[0], t.lo[0], t.hi[0]), yc = std::clamp(s[1], t.lo[1], t.hi[1]);
  const bool ox = s[0] != xc, oy = s[1] != yc;
  // Partials needed: along an axis inside, up to the requested order; outside, up to 1: every
  // 2D table continues to first order across its edges (the tensor product of the 1D linear
  // extensions, see the header).
  const int p = 1;
  const int na = ox ? p + 1 : order + 1, nb = oy ? p + 1 : order + 1;
  double D[4][4], wx[4][4], wy[4][4];
  partials_2d(t, xc, yc, na, nb, D);
  axis_weights(ox, s[0] - xc, wx, p);
  axis_weights(oy, s[1] - yc, wy, p);
  auto deriv = [&](int m, int n) {
    double acc = 0;
    for (int i = 0; i < na; ++i) {
      if (wx[m][i] == 0) continue;
      double r = 0;
      for (int j = 0; j < nb; ++j) r += wy[n][j] * D[i][j];
      acc += wx[m][i] * r;
    }
    return acc;
  };
  out[0] = deriv(0, 0);
  if (order >= 1) {
    out[1] = deriv(1, 0);
    out[2] = deriv(0, 1);
  }
  for (int q = 0; order >= 2 && q < 3; ++q) {
    const JetPair e = jet_pair(2, q);
    out[jet_first(2, 2) + q] = deriv(2 - e.i - e.j, e.i + e.j);
  }
  for (int q = 0; order >= 3 && q < 4; ++q) {
    const JetTriple e = jet_triple(2, q);
    const int ny = e.i + e.j + e.k;
    out[jet_first(2, 3) + q] = deriv(3 - ny, ny);
  }
}

BakedJet1 eval_baked_1d(const BakedTerm& t, double x) {
  if (x < t.lo[0] || x > t.hi[0]) {
    double j[3];
    eval_baked_jet(t, &x, 2, j);
    return {j[0], j[1], j[2]};
  }
  // Inside: the cell's cubic and its two derivatives.
  double u;
  const int i = locate(t, 0, x, u);
  const double* c = t.coef.data() + 4 * size_t(i);
  const double ih = t.inv_h[0];
  return {c[0] + u * (c[1] + u * (c[2] + u * c[3])), ih * (c[1] + u * (2 * c[2] + 3 * u * c[3])),
          ih * ih * (2 * c[2] + 6 * u * c[3])};
}

double eval_baked_1d_value(const BakedTerm& t, double x) {
  if (x < t.lo[0] || x > t.hi[0]) return eval_baked_1d(t, x).f;
  double u;
  const int i = locate(t, 0, x, u);
  const double* c = t.coef.data() + 4 * size_t(i);
  return c[0] + u * (c[1] + u * (c[2] + u * c[3]));
}

double eval_baked_2d_value(const BakedTerm& t, const Eigen::Vector2d& s) {
  if (s[0] < t.lo[0] || s[0] > t.hi[0] || s[1] < t.lo[1] || s[1] > t.hi[1]) return eval_baked_2d(t, s).f;
  // (eval_baked_2d's f, the same operations in the same order)
  double u, v;
  const int i = locate(t, 0, s[0], u), jc = locate(t, 1, s[1], v);
  const double* A = t.coef.data() + 16 * (size_t(i) * (t.n[1] - 1) + jc);
  const double v2 = v * v;
  const double pv0[4] = {1, v, v2, v2 * v};
  double R0[4];
  for (int k = 0; k < 4; ++k) {
    const double* a = A + 4 * k;
    R0[k] = a[0] + a[1] * pv0[1] + a[2] * pv0[2] + a[3] * pv0[3];
  }
  const double u2 = u * u;
  const double pu0[4] = {1, u, u2, u2 * u};
  return R0[0] + pu0[1] * R0[1] + pu0[2] * R0[2] + pu0[3] * R0[3];
}

BakedJet2 eval_baked_2d(const BakedTerm& t, const Eigen::Vector2d& s) {
  BakedJet2 r;
  if (s[0] < t.lo[0] || s[0] > t.hi[0] || s[1] < t.lo[1] || s[1] > t.hi[1]) {
    double j[6];
    eval_baked_jet(t, s.data(), 2, j);
    r.f = j[0];
    r.g << j[1], j[2];
    r.H << j[3], j[4], j[4], j[5];
    return r;
  }
  // Inside: only the six partials of order <= 2, straight from the cell polynomial.
  double u, v;
  const int i = locate(t, 0, s[0], u), jc = locate(t, 1, s[1], v);
  const double* A = t.coef.data() + 16 * (size_t(i) * (t.n[1] - 1) + jc);
  const double v2 = v * v;
  const double pv0[4] = {1, v, v2, v2 * v}, pv1[4] = {0, 1, 2 * v, 3 * v2}, pv2[4] = {0, 0, 2, 6 * v};
  double R0[4], R1[4], R2[4];
  for (int k = 0; k < 4; ++k) {
    const double* a = A + 4 * k;
    R0[k] = a[0] + a[1] * pv0[1] + a[2] * pv0[2] + a[3] * pv0[3];
    R1[k] = a[1] + a[2] * pv1[2] + a[3] * pv1[3];
    R2[k] = 2 * a[2] + a[3] * pv2[3];
  }
  const double u2 = u * u;
  const double pu0[4] = {1, u, u2, u2 * u}, pu1[4] = {0, 1, 2 * u, 3 * u2};
  const double ix = t.inv_h[0], iy = t.inv_h[1];
  r.f = R0[0] + pu0[1] * R0[1] + pu0[2] * R0[2] + pu0[3] * R0[3];
  const double fx = R0[1] + pu1[2] * R0[2] + pu1[3] * R0[3];
  const double fy = R1[0] + pu0[1] * R1[1] + pu0[2] * R1[2] + pu0[3] * R1[3];
  const double fxx = 2 * R0[2] + 6 * u * R0[3];
  const double fxy = R1[1] + pu1[2] * R1[2] + pu1[3] * R1[3];
  const double fyy = R2[0] + pu0[1] * R2[1] + pu0[2] * R2[2] + pu0[3] * R2[3];
  r.g << fx * ix, fy * iy;
  r.H << fxx * ix * ix, fxy * ix * iy, fxy * ix * iy, fyy * iy * iy;
  return r;
}

}  // namespace yarnhom
