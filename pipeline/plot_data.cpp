#include "pipeline/plot_data.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "material/baked_eval.hpp"
#include "core/atomic_file.hpp"
#include "core/h5.hpp"
#include "core/jet_layout.hpp"
#include "bake/term_function.hpp"
#include "core/fit_metrics.hpp"
#include "cpu/network_eval.hpp"

namespace yarnhom {

namespace {

// Grid over the box widened by `extend` box widths on each side.
std::vector<double> axis_grid(double lo, double hi, double extend, int n) {
  std::vector<double> g(n);
  const double a = lo - extend * (hi - lo), b = hi + extend * (hi - lo);
  for (int i = 0; i < n; ++i) g[i] = a + (b - a) * i / (n - 1);
  return g;
}

// The term's fit verdict as the pipeline's report gives it (the network on its validation rows,
// core/fit_metrics.hpp), so that a figure can mark a failing term: attrs fit_ok (1/0) and verdict.
void write_fit(const h5::Node& g, const ModelNetwork* net, const TermData* td) {
  if (!net || !td || td->n == 0) return;
  const std::vector<double> jet = network_function(*net)(td->strain.data(), td->n, 1);
  const bool val = !net->val_index.empty() && net->val_index.back() < td->n;
  const FitQuality q = val ? fit_quality(*td, jet, net->val_index) : fit_quality(*td, jet);
  g.set_attr("fit_ok", q.ok() ? 1 : 0);
  g.set_attr("verdict", fit_verdict(q));
}

}  // namespace

namespace {

void write_plot_data_to(const std::string& path, const std::optional<Model>& model, const BakedModel& baked,
                        const std::optional<Dataset>& ds) {
  h5::Node root = h5::create_file(path);
  root.set_attr("format", "yarnhom-plotdata");
  if (model) {
    h5::Node hist = root.create_group("history");
    for (const ModelNetwork& n : model->networks) {
      if (n.history.size() == 0) continue;
      h5::Node g = hist.create_group(n.term.name);
      const hsize_t e = n.history.size();
      g.write("train_loss", n.history.train_loss, {e});
      g.write("val_loss", n.history.val_loss, {e});
      g.write("lr", n.history.lr, {e});
      // The full-batch L-BFGS polish after the epochs (train/), per iteration.
      if (!n.history.polish_train.empty())
        g.write("polish_train_loss", n.history.polish_train, {hsize_t(n.history.polish_train.size())});
      if (!n.history.polish_val.empty())
        g.write("polish_val_loss", n.history.polish_val, {hsize_t(n.history.polish_val.size())});
    }
  }
  h5::Node surf = root.create_group("surface"), conv = root.create_group("convexity"), line = root.create_group("line");
  for (const BakedTable& tb : baked.tables) {
    const BakedTerm t = make_baked_term(tb);
    const ModelNetwork* net = model ? model->find(tb.term.name) : nullptr;
    std::vector<std::string> sym;
    for (int i : tb.term.indices) sym.push_back(kStrainSymbols[i]);
    if (tb.dim() == 1) {
      const int n = 601;
      auto x = axis_grid(tb.lower[0], tb.upper[0], 0.5, n);
      std::vector<double> b(n), sec(n);
      for (int i = 0; i < n; ++i) {
        b[i] = eval_baked_1d(t, x[i]).f;
        sec[i] = baked_sector(t, &x[i]);
      }
      h5::Node g = line.create_group(tb.term.name);
      g.set_attr("lower", tb.lower);
      g.set_attr("upper", tb.upper);
      g.set_attr("symbol", sym[0]);
      g.write("x", x, {hsize_t(n)});
      g.write("baked", b, {hsize_t(n)});
      g.write("sector", sec, {hsize_t(n)});
      if (net) g.write("network", cpu::eval_network_physical(*net, x.data(), n, 0), {hsize_t(n)});
      if (const TermData* td = ds ? ds->find(tb.term.name) : nullptr) {
        g.write("data_x", td->strain, {hsize_t(td->n)});
        g.write("data_psi", td->energy, {hsize_t(td->n)});
        write_fit(g, net, td);
      }
      continue;
    }
    // Fig. 3: the safeguarded surface over the box widened by half its width on each side,
    // coloured by sector, and the magnitude of its third derivatives.
    const int n = 121;
    auto x = axis_grid(tb.lower[0], tb.upper[0], 0.5, n), y = axis_grid(tb.lower[1], tb.upper[1], 0.5, n);
    std::vector<double> psi(n * n), sec(n * n), d3(n * n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double s[2] = {x[i], y[j]};
        double jet[10];
        eval_baked_jet(t, s, 3, jet);
        psi[i * n + j] = jet[0];
        sec[i * n + j] = baked_sector(t, s);
        // Frobenius norm of the symmetric third-derivative tensor, in units where the box is
        // [-1, 1]^2 (so that the two strains, of different units, count alike).
        const double hx = 0.5 * (tb.upper[0] - tb.lower[0]), hy = 0.5 * (tb.upper[1] - tb.lower[1]);
        const double a = jet[6] * hx * hx * hx, b = jet[7] * hx * hx * hy, c = jet[8] * hx * hy * hy, e = jet[9] * hy * hy * hy;
        d3[i * n + j] = std::sqrt(a * a + 3 * b * b + 3 * c * c + e * e);
      }
    h5::Node g = surf.create_group(tb.term.name);
    g.set_attr("lower", tb.lower);
    g.set_attr("upper", tb.upper);
    g.set_attr("symbol_x", sym[0]);
    g.set_attr("symbol_y", sym[1]);
    g.write("x", x, {hsize_t(n)});
    g.write("y", y, {hsize_t(n)});
    g.write("psi", psi, {hsize_t(n), hsize_t(n)});
    g.write("sector", sec, {hsize_t(n), hsize_t(n)});
    g.write("d3", d3, {hsize_t(n), hsize_t(n)});
    if (const TermData* td = ds ? ds->find(tb.term.name) : nullptr) {  // the data points, over the surface
      std::vector<double> dx(size_t(td->n)), dy(size_t(td->n));
      for (int p = 0; p < td->n; ++p) {
        dx[size_t(p)] = td->strain[2 * size_t(p)];
        dy[size_t(p)] = td->strain[2 * size_t(p) + 1];
      }
      g.write("data_x", dx, {hsize_t(td->n)});
      g.write("data_y", dy, {hsize_t(td->n)});
      g.write("data_psi", td->energy, {hsize_t(td->n)});
      if (net && !net->val_index.empty() && net->val_index.back() < td->n)
        g.write("data_val", std::vector<double>(net->val_index.begin(), net->val_index.end()), {hsize_t(net->val_index.size())});
      write_fit(g, net, td);
    }
    // Fig. 4: sign of the smallest Hessian eigenvalue over the box, from the network when it is
    // at hand (exact second derivatives), else from the table. Computed in box-normalized units
    // ([-1, 1]^2): the sign of the smallest eigenvalue depends on the units, so we choose the
    // ones the network is trained in.
    const int m = 101;
    auto cx = axis_grid(tb.lower[0], tb.upper[0], 0.0, m), cy = axis_grid(tb.lower[1], tb.upper[1], 0.0, m);
    std::vector<double> pts(2 * m * m), lam(m * m);
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) {
        pts[2 * (i * m + j)] = cx[i];
        pts[2 * (i * m + j) + 1] = cy[j];
      }
    std::vector<double> jets, lam_pair(m * m);
    std::optional<BakedTerm> one_d[2];  // the 1D terms of the pair's two strains
    for (const BakedTable& t1 : baked.tables)
      for (int a = 0; a < 2; ++a)
        if (t1.dim() == 1 && t1.term.indices[0] == tb.term.indices[a]) one_d[a] = make_baked_term(t1);
    if (net) jets = cpu::eval_network_physical(*net, pts.data(), m * m, 2);
    const double hx = 0.5 * (tb.upper[0] - tb.lower[0]), hy = 0.5 * (tb.upper[1] - tb.lower[1]);
    for (int p = 0; p < m * m; ++p) {
      double j[10];
      if (net) {
        for (int c = 0; c < 6; ++c) j[c] = jets[size_t(c) * m * m + p];
      } else {
        eval_baked_jet(t, &pts[2 * p], 2, j);
      }
      Eigen::Matrix2d H;
      H << j[3] * hx * hx, j[4] * hx * hy, j[4] * hx * hy, j[5] * hy * hy;
      lam[p] = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(H, Eigen::EigenvaluesOnly).eigenvalues()[0];
      // The pair's total Psi_I(s_I) + Psi_J(s_J) + Psi_IJ(s_I, s_J): a residual coupling alone
      // is indefinite almost everywhere (c s_I s_J has eigenvalues +-c); what the material
      // feels is the total (docs/bake.md, "Convexity").
      if (one_d[0] && one_d[1]) {
        H(0, 0) += eval_baked_1d(*one_d[0], pts[2 * p]).d2f * hx * hx;
        H(1, 1) += eval_baked_1d(*one_d[1], pts[2 * p + 1]).d2f * hy * hy;
        lam_pair[p] = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(H, Eigen::EigenvaluesOnly).eigenvalues()[0];
      }
    }
    h5::Node c = conv.create_group(tb.term.name);
    c.set_attr("symbol_x", sym[0]);
    c.set_attr("symbol_y", sym[1]);
    c.set_attr("source", net ? "network" : "baked");
    c.write("x", cx, {hsize_t(m)});
    c.write("y", cy, {hsize_t(m)});
    c.write("lam_min", lam, {hsize_t(m), hsize_t(m)});
    if (one_d[0] && one_d[1]) c.write("lam_min_pair", lam_pair, {hsize_t(m), hsize_t(m)});
  }
}


}  // namespace

// Atomic like every other output, so that an interrupted plot never leaves half a file.
void write_plot_data(const std::string& path, const std::optional<Model>& model, const BakedModel& baked,
                     const std::optional<Dataset>& ds) {
  AtomicOutput out(path);
  write_plot_data_to(out.temp_path(), model, baked, ds);
  out.commit();
}

}  // namespace yarnhom
