#include "accuracy/spline_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "material/baked_eval.hpp"
#include "accuracy/lsi.hpp"
#include "core/jet_layout.hpp"

namespace yarnhom {

KnotAxis choose_knots(double lower, double upper, int n) {
  if (!(lower < upper) || !std::isfinite(lower) || !std::isfinite(upper))
    throw std::invalid_argument("choose_knots: empty or non-finite range");
  if (n < 2) throw std::invalid_argument("choose_knots: fewer than 2 knots");
  KnotAxis ax{lower, upper, n, -1};
  if (lower == 0) ax.zero = 0;
  if (upper == 0) ax.zero = n - 1;
  if (!(lower < 0 && upper > 0) || n < 3) return ax;
  // a knots below 0, b = n - 1 - a above; spacing h(a) = max(-lower / a, upper / b).
  int best = 1;
  double best_h = std::numeric_limits<double>::infinity();
  for (int a = 1; a <= n - 2; ++a) {
    const double h = std::max(-lower / a, upper / (n - 1 - a));
    if (h < best_h) { best_h = h; best = a; }
  }
  ax.lower = -best * best_h;
  ax.upper = (n - 1 - best) * best_h;
  ax.zero = best;
  return ax;
}

int hermite_axis_terms(const KnotAxis& ax, double x, int m, int knot[4], int kind[4], double w[4]) {
  const double h = ax.spacing();
  if (x < ax.lower || x > ax.upper) {  // the tangent at the nearest end knot
    const int k = x < ax.lower ? 0 : ax.n - 1;
    const double dx = x - (x < ax.lower ? ax.lower : ax.upper);
    knot[0] = knot[1] = k;
    kind[0] = 0;
    kind[1] = 1;
    w[0] = m == 0 ? 1.0 : 0.0;
    w[1] = m == 0 ? dx / h : m == 1 ? 1.0 / h : 0.0;
    return 2;
  }
  const double q = (x - ax.lower) / h;
  const int c = std::clamp(int(std::floor(q)), 0, ax.n - 2);
  const double u = q - c, u2 = u * u, u3 = u2 * u;
  double H[4];  // H00, H10, H01, H11 and derivatives in u
  if (m == 0) {
    H[0] = 1 - 3 * u2 + 2 * u3; H[1] = u - 2 * u2 + u3; H[2] = 3 * u2 - 2 * u3; H[3] = u3 - u2;
  } else if (m == 1) {
    H[0] = -6 * u + 6 * u2; H[1] = 1 - 4 * u + 3 * u2; H[2] = 6 * u - 6 * u2; H[3] = 3 * u2 - 2 * u;
  } else {
    H[0] = -6 + 12 * u; H[1] = -4 + 6 * u; H[2] = 6 - 12 * u; H[3] = 6 * u - 2;
  }
  const double s = std::pow(h, -m);
  knot[0] = c; kind[0] = 0; w[0] = s * H[0];
  knot[1] = c; kind[1] = 1; w[1] = s * H[1];
  knot[2] = c + 1; kind[2] = 0; w[2] = s * H[2];
  knot[3] = c + 1; kind[3] = 1; w[3] = s * H[3];
  return 4;
}

namespace {

// Gauss-Legendre, 4 points on [0, 1]: exact for the squared second derivatives of a cubic.
constexpr double kGaussX[4] = {0.0694318442029737, 0.3300094782075719, 0.6699905217924281, 0.9305681557970263};
constexpr double kGaussW[4] = {0.1739274225687269, 0.3260725774312731, 0.3260725774312731, 0.1739274225687269};

// Rows of the least squares problem over the unknowns of a term, before the fixed unknowns are
// removed: a growing dense matrix and right-hand side.
struct Rows {
  int nunk = 0;
  std::vector<Eigen::VectorXd> a;
  std::vector<double> b;
  Eigen::VectorXd& add(double rhs) {
    a.emplace_back(Eigen::VectorXd::Zero(nunk));
    b.push_back(rhs);
    return a.back();
  }
};

struct Problem {
  int d = 1;
  KnotAxis ax[2];
  int nunk = 0;
  std::vector<int> col;  // unknown -> column of the reduced problem, -1 when fixed at 0
  int ncols = 0;
  int idx(int i, int j, int kx, int ky) const {
    return d == 1 ? 2 * i + kx : 4 * (i * ax[1].n + j) + 2 * kx + ky;
  }
  void fix(int u) {
    if (col[u] >= 0) col[u] = -2;  // renumbered in finish()
  }
  void finish() {
    ncols = 0;
    for (int& c : col) c = c == -2 ? -1 : ncols++;
  }
  // Adds the row of the (mx, my)-th derivative at s, times `scale`.
  void basis(const double* s, int mx, int my, double scale, Eigen::VectorXd& row) const {
    int kn[2][4], ki[2][4];
    double w[2][4];
    const int cx = hermite_axis_terms(ax[0], s[0], mx, kn[0], ki[0], w[0]);
    if (d == 1) {
      for (int a = 0; a < cx; ++a) row[idx(kn[0][a], 0, ki[0][a], 0)] += scale * w[0][a];
      return;
    }
    const int cy = hermite_axis_terms(ax[1], s[1], my, kn[1], ki[1], w[1]);
    for (int a = 0; a < cx; ++a)
      for (int b = 0; b < cy; ++b)
        row[idx(kn[0][a], kn[1][b], ki[0][a], ki[1][b])] += scale * w[0][a] * w[1][b];
  }
};

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / v.size();
}

// The unknowns of a term's fit: knots on the data's own box (the sampling box when it is
// wider), and the coefficients fixed at 0 where the term vanishes on an axis (s_I = 0).
Problem make_fit_problem(const TermData& data, const SplineFitOptions& opt) {
  const int d = data.dim(), N = data.n;
  Problem P;
  P.d = d;
  // The box: the data's own extent (the sampling box when it is wider).
  for (int k = 0; k < d; ++k) {
    double lo = data.lower[k], hi = data.upper[k];
    for (int p = 0; p < N; ++p) {
      lo = std::min(lo, data.strain[size_t(p) * d + k]);
      hi = std::max(hi, data.strain[size_t(p) * d + k]);
    }
    P.ax[k] = choose_knots(lo, hi, d == 1 ? opt.knots1d : opt.knots2d);
  }
  P.nunk = d == 1 ? 2 * P.ax[0].n : 4 * P.ax[0].n * P.ax[1].n;
  P.col.assign(P.nunk, 0);
  if (d == 1) {
    if (P.ax[0].zero >= 0) P.fix(P.idx(P.ax[0].zero, 0, 0, 0));
  } else {
    const int n0 = P.ax[0].n, n1 = P.ax[1].n;
    if (P.ax[0].zero >= 0)
      for (int j = 0; j < n1; ++j) { P.fix(P.idx(P.ax[0].zero, j, 0, 0)); P.fix(P.idx(P.ax[0].zero, j, 0, 1)); }
    if (P.ax[1].zero >= 0)
      for (int i = 0; i < n0; ++i) { P.fix(P.idx(i, P.ax[1].zero, 0, 0)); P.fix(P.idx(i, P.ax[1].zero, 1, 0)); }
  }
  P.finish();
  return P;
}

// One row per sample's energy, and per gradient component when the gradient has weight.
void add_data_rows(const Problem& P, const TermData& data, double sigma, const double L[2], double gradient_weight,
                   Rows& R) {
  const int d = data.dim(), N = data.n;
  const double wg = std::sqrt(gradient_weight);
  for (int p = 0; p < N; ++p) {
    const double* s = &data.strain[size_t(p) * d];
    P.basis(s, 0, 0, 1.0 / sigma, R.add(data.energy[p] / sigma));
    if (wg > 0)
      for (int k = 0; k < d; ++k) {
        const double sc = wg * L[k] / sigma;
        P.basis(s, k == 0 ? 1 : 0, k == 1 ? 1 : 0, sc, R.add(sc * data.gradient[size_t(p) * d + k]));
      }
  }
}

// The curvature penalty: int over the box (in box-normalized coordinates) of |D^2 f|^2, by
// 4-point Gauss-Legendre per cell and axis, weighted by smoothing x (number of samples).
void add_curvature_rows(const Problem& P, int N, double smoothing, double sigma, const double L[2], Rows& R) {
  const int d = P.d;
  const double lam = smoothing * N;
  const int c0 = P.ax[0].n - 1, c1 = d == 2 ? P.ax[1].n - 1 : 1;
  const double h0 = P.ax[0].spacing(), h1 = d == 2 ? P.ax[1].spacing() : 1.0;
  for (int i = 0; i < c0; ++i)
    for (int j = 0; j < c1; ++j)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < (d == 2 ? 4 : 1); ++b) {
          double s[2] = {P.ax[0].lower + (i + kGaussX[a]) * h0, d == 2 ? P.ax[1].lower + (j + kGaussX[b]) * h1 : 0.0};
          const double vol = (kGaussW[a] / c0) * (d == 2 ? kGaussW[b] / c1 : 1.0);
          const double r = std::sqrt(lam * vol) / sigma;
          if (d == 1) {
            P.basis(s, 2, 0, r * L[0] * L[0], R.add(0));
          } else {
            P.basis(s, 2, 0, r * L[0] * L[0], R.add(0));
            P.basis(s, 0, 2, r * L[1] * L[1], R.add(0));
            P.basis(s, 1, 1, std::sqrt(2.0) * r * L[0] * L[1], R.add(0));
          }
        }
}

// The reduced dense system: the rows over the free unknowns only.
void dense_system(const Problem& P, const Rows& R, Eigen::MatrixXd& E, Eigen::VectorXd& rhs) {
  E.resize(R.a.size(), P.ncols);
  rhs.resize(R.a.size());
  for (size_t r = 0; r < R.a.size(); ++r) {
    for (int u = 0; u < P.nunk; ++u)
      if (P.col[u] >= 0) E(r, P.col[u]) = R.a[r][u];
    rhs[r] = R.b[r];
  }
}

// The 1D fit monotone away from one knot m (the minimum), the best m over all: for a cell
// (i, i+1) with secant D = f_{i+1} - f_i and end slopes g (times the spacing), Fritsch-Carlson's
// box 0 <= g/D <= 3 at both ends, as linear inequalities with the sign of the side.
Eigen::VectorXd solve_monotone(const Problem& P, const Eigen::MatrixXd& E, const Eigen::VectorXd& rhs,
                               const std::string& name, int& min_knot, int& active) {
  Eigen::VectorXd x;
  const int n = P.ax[0].n;
  double best = std::numeric_limits<double>::infinity();
  for (int m = 0; m < n; ++m) {
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(4 * (n - 1), P.ncols);
    int r = 0;
    auto put = [&](int row, int unk, double v) {
      if (P.col[unk] >= 0) G(row, P.col[unk]) += v;
    };
    for (int i = 0; i + 1 < n; ++i) {
      const double sgn = i >= m ? 1.0 : -1.0;  // increasing right of the minimum
      for (int e = 0; e < 2; ++e) {
        const int gk = P.idx(i + e, 0, 1, 0);
        put(r, gk, sgn);  // sgn g >= 0
        ++r;
        put(r, P.idx(i + 1, 0, 0, 0), 3 * sgn);  // sgn (3 D - g) >= 0
        put(r, P.idx(i, 0, 0, 0), -3 * sgn);
        put(r, gk, -sgn);
        ++r;
      }
    }
    const LsiResult res = solve_lsi(E, rhs, G, Eigen::VectorXd::Zero(G.rows()));
    if (!res.feasible) continue;
    const double obj = (E * res.x - rhs).squaredNorm();
    if (obj < best) {
      best = obj;
      x = res.x;
      min_knot = m;
      active = int(((G * res.x).array().abs() < 1e-9 * (1 + res.x.cwiseAbs().maxCoeff())).count());
    }
  }
  if (min_knot < 0) throw std::runtime_error("term " + name + ": no monotone fit found");
  return x;
}

// The baked table of the fitted coefficients (slopes from knot spacings back to strain units),
// with the fit's normalization as its provenance and the safeguard outside the box.
BakedTable table_of_fit(const Problem& P, const Eigen::VectorXd& c, const TermData& data, double emean,
                        double sigma, const double L[2]) {
  const int d = P.d;
  BakedTable t;
  t.term = data.term;
  t.extrapolation = kBakedLinear;
  for (int k = 0; k < d; ++k) {
    t.lower.push_back(P.ax[k].lower);
    t.upper.push_back(P.ax[k].upper);
    t.knots.push_back(P.ax[k].n);
  }
  const size_t nk = t.num_knots();
  t.f.resize(nk);
  t.f_x.resize(nk);
  const double hx = P.ax[0].spacing();
  if (d == 1) {
    for (int i = 0; i < P.ax[0].n; ++i) {
      t.f[i] = c[P.idx(i, 0, 0, 0)];
      t.f_x[i] = c[P.idx(i, 0, 1, 0)] / hx;
    }
  } else {
    const double hy = P.ax[1].spacing();
    t.f_y.resize(nk);
    t.f_xy.resize(nk);
    for (int i = 0; i < P.ax[0].n; ++i)
      for (int j = 0; j < P.ax[1].n; ++j) {
        const size_t q = size_t(i) * P.ax[1].n + j;
        t.f[q] = c[P.idx(i, j, 0, 0)];
        t.f_x[q] = c[P.idx(i, j, 1, 0)] / hx;
        t.f_y[q] = c[P.idx(i, j, 0, 1)] / hy;
        t.f_xy[q] = c[P.idx(i, j, 1, 1)] / (hx * hy);
      }
  }
  // Provenance: no network; the normalization that the fit used.
  t.desc.input_dim = d;
  t.desc.hidden = {};
  t.desc.activation = "none (spline fit)";
  for (int k = 0; k < d; ++k) {
    t.norm.center.push_back(0.5 * (P.ax[k].lower + P.ax[k].upper));
    t.norm.halfwidth.push_back(0.5 * L[k]);
  }
  t.norm.out_mean = emean;
  t.norm.out_std = sigma;
  t.epochs = 0;
  t.backend = "fit-splines";
  t.status = "ok";
  compute_safeguard(t);

  return t;
}

// The fit's own errors on its data: energy RMSE relative to the range, gradient error relative.
void fill_report(const BakedTable& t, const Problem& P, const TermData& data, const double L[2], double emin,
                 double emax, int min_knot, int active, SplineFitReport* report) {
  const int d = data.dim(), N = data.n;
  report->term = data.term.name;
  report->knots[0] = P.ax[0].n;
  report->knots[1] = d == 2 ? P.ax[1].n : 0;
  report->minimum_knot = min_knot;
  report->constraints_active = active;
  const BakedTerm bt = make_baked_term(t);
  double se = 0, ge = 0, gm = 0;
  for (int p = 0; p < N; ++p) {
    const double* s = &data.strain[size_t(p) * d];
    double j[kMaxJetChannels];
    eval_baked_jet(bt, s, 1, j);
    se += (j[0] - data.energy[p]) * (j[0] - data.energy[p]);
    double e2 = 0, g2 = 0;
    for (int k = 0; k < d; ++k) {
      const double gd = data.gradient[size_t(p) * d + k] * L[k];
      e2 += (j[1 + k] * L[k] - gd) * (j[1 + k] * L[k] - gd);
      g2 += gd * gd;
    }
    ge += std::sqrt(e2);
    gm += std::sqrt(g2);
  }
  report->energy_rmse_rel = std::sqrt(se / N) / std::max(emax - emin, 1e-300);
  report->gradient_err_rel = gm > 0 ? ge / gm : 0;
}

}  // namespace

BakedTable fit_spline_term(const TermData& data, const SplineFitOptions& opt, SplineFitReport* report) {
  const int d = data.dim(), N = data.n;
  if (N < 2) throw std::invalid_argument("term " + data.term.name + ": fewer than 2 samples");
  if (opt.knots1d < 3 || opt.knots2d < 3) throw std::invalid_argument("fit-splines: at least 3 knots per axis");
  if (!(opt.smoothing >= 0) || !(opt.gradient_weight >= 0))
    throw std::invalid_argument("fit-splines: smoothing and gradient weight must be >= 0");
  const Problem P = make_fit_problem(data, opt);
  // Normalization: energies by their standard deviation, strains by the box width.
  const double emean = mean(data.energy);
  double var = 0, emin = data.energy[0], emax = data.energy[0];
  for (double e : data.energy) { var += (e - emean) * (e - emean); emin = std::min(emin, e); emax = std::max(emax, e); }
  double sigma = std::sqrt(var / N);
  if (!(sigma > 0)) sigma = std::max(1.0, std::abs(emean));
  double L[2] = {P.ax[0].upper - P.ax[0].lower, d == 2 ? P.ax[1].upper - P.ax[1].lower : 1.0};

  Rows R;
  R.nunk = P.nunk;
  add_data_rows(P, data, sigma, L, opt.gradient_weight, R);
  if (opt.smoothing > 0) add_curvature_rows(P, N, opt.smoothing, sigma, L, R);
  // A tiny ridge keeps the matrix of full rank where nothing else reaches a coefficient.
  for (int u = 0; u < P.nunk; ++u) R.add(0)[u] = 1e-7 / sigma;

  Eigen::MatrixXd E;
  Eigen::VectorXd rhs;
  dense_system(P, R, E, rhs);
  Eigen::VectorXd x;
  int min_knot = -1, active = 0;
  if (d == 1 && opt.monotone) {
    x = solve_monotone(P, E, rhs, data.term.name, min_knot, active);
  } else {
    x = solve_lsi(E, rhs, Eigen::MatrixXd(0, P.ncols), Eigen::VectorXd(0)).x;
  }
  Eigen::VectorXd c = Eigen::VectorXd::Zero(P.nunk);
  for (int u = 0; u < P.nunk; ++u)
    if (P.col[u] >= 0) c[u] = x[P.col[u]];

  BakedTable t = table_of_fit(P, c, data, emean, sigma, L);
  if (report) fill_report(t, P, data, L, emin, emax, min_knot, active, report);
  return t;
}

BakedModel fit_splines(const Dataset& ds, const std::string& dataset_path, const SplineFitOptions& opt,
                       std::vector<SplineFitReport>* reports) {
  BakedModel m;
  m.model = "fit-splines";
  m.dataset = dataset_path;
  m.psi0 = ds.psi0;
  m.psi0_known = true;
  m.areal_density = ds.areal_density;  // the simulator's gravity and inertia, as bake carries it
  for (const Term& term : all_terms()) {
    const TermData* td = ds.find(term.name);
    if (!td) continue;
    SplineFitReport r;
    m.tables.push_back(fit_spline_term(*td, opt, &r));
    if (reports) reports->push_back(r);
  }
  return m;
}

}  // namespace yarnhom
