// yarnhom plot RUN_DIR: the pictures of a run (supplement Fig. 1, 3, 4 and 1D fits). The
// numbers are computed here, with the project's own evaluators, and written to
// RUN_DIR/plots/plotdata.h5; tools/plot/plot_run.py only draws them (matplotlib, h5py), so
// that no formula exists twice.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>

#include <Eigen/Eigenvalues>

#include "bake/bake_table.hpp"
#include "bake/baked_eval.hpp"
#include "core/baked.hpp"
#include "core/dataset.hpp"
#include "core/h5.hpp"
#include "core/jet_layout.hpp"
#include "core/model.hpp"
#include "cpu/network_eval.hpp"
#include "tools/commands.hpp"

namespace yarnhom::tools {

namespace fs = std::filesystem;

namespace {

// Grid over the box widened by `extend` box widths on each side.
std::vector<double> axis_grid(double lo, double hi, double extend, int n) {
  std::vector<double> g(n);
  const double a = lo - extend * (hi - lo), b = hi + extend * (hi - lo);
  for (int i = 0; i < n; ++i) g[i] = a + (b - a) * i / (n - 1);
  return g;
}

void write_plot_data(const std::string& path, const std::optional<Model>& model,
                     const std::optional<BakedModel>& baked, const std::optional<Dataset>& ds) {
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
    }
  }
  h5::Node surf = root.create_group("surface"), conv = root.create_group("convexity"), line = root.create_group("line");
  for (const BakedTable& tb : baked->tables) {
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
    std::vector<double> jets;
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
    }
    h5::Node c = conv.create_group(tb.term.name);
    c.set_attr("symbol_x", sym[0]);
    c.set_attr("symbol_y", sym[1]);
    c.set_attr("source", net ? "network" : "baked");
    c.write("x", cx, {hsize_t(m)});
    c.write("y", cy, {hsize_t(m)});
    c.write("lam_min", lam, {hsize_t(m), hsize_t(m)});
  }
}

// A python3 that imports matplotlib, h5py and numpy: $YARNHOM_PYTHON, then the system's
// /usr/bin/python3 (Debian's python3-matplotlib), then python3 on PATH.
std::string find_python() {
  std::vector<std::string> candidates;
  if (const char* e = std::getenv("YARNHOM_PYTHON")) candidates.push_back(e);
  candidates.push_back("/usr/bin/python3");
  candidates.push_back("python3");
  for (const std::string& c : candidates) {
    const std::string cmd = "'" + c + "' -c 'import matplotlib, h5py, numpy' >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) return c;
  }
  return "";
}

std::string scripts_dir() {
  if (const char* e = std::getenv("YARNHOM_SCRIPTS")) return e;
#ifdef YARNHOM_SCRIPTS_DIR
  return YARNHOM_SCRIPTS_DIR;
#else
  return "tools";
#endif
}

}  // namespace

void register_plot(CLI::App& app) {
  struct Opts {
    std::string run, model, baked, data, out;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "plot",
      "Draw a run's pictures as PNG files: loss curves with the learning rate (supplement Fig. 1), "
      "each 2D term's surface with the safeguard coloured by sector and the magnitude of its third "
      "derivatives (Fig. 3), the sign of the Hessian's smallest eigenvalue (Fig. 4), and data "
      "against network along each 1D term. Needs a python3 with matplotlib and h5py "
      "($YARNHOM_PYTHON, /usr/bin/python3 or python3 on PATH).");
  cmd->add_option("RUN_DIR", o->run, "Run folder holding model.h5, baked.h5 and dataset.h5 (any may be missing)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--model", o->model, "Model file (default RUN_DIR/model.h5)");
  cmd->add_option("--baked", o->baked, "Baked file (default RUN_DIR/baked.h5; baked in memory from the model if absent)");
  cmd->add_option("--data", o->data, "Dataset (default RUN_DIR/dataset.h5)");
  cmd->add_option("-o,--output", o->out, "Folder for the PNGs (default RUN_DIR/plots)");
  cmd->callback([o] {
    const fs::path run(o->run);
    auto pick = [&](const std::string& given, const char* name) {
      if (!given.empty()) {
        if (!fs::exists(given)) throw std::invalid_argument(given + ": no such file");
        return given;
      }
      const fs::path p = run / name;
      return fs::exists(p) ? p.string() : std::string();
    };
    const std::string mp = pick(o->model, "model.h5"), bp = pick(o->baked, "baked.h5"), dp = pick(o->data, "dataset.h5");
    std::optional<Model> model;
    std::optional<BakedModel> baked;
    std::optional<Dataset> ds;
    if (!mp.empty()) model = read_model(mp);
    if (!bp.empty()) baked = read_baked(bp);
    if (!dp.empty()) ds = read_dataset(dp);
    if (!baked && model) {
      std::fprintf(stderr, "yarnhom plot: no baked file; baking the model in memory (200 / 100x100)\n");
      baked = bake_model(*model, mp, 200, 100, 0, false);
    }
    if (!baked) throw std::invalid_argument(o->run + ": neither model.h5 nor baked.h5 found (give --model or --baked)");
    const fs::path out = o->out.empty() ? run / "plots" : fs::path(o->out);
    fs::create_directories(out);
    const std::string data = (out / "plotdata.h5").string();
    write_plot_data(data, model, baked, ds);
    const std::string py = find_python();
    if (py.empty()) {
      std::fprintf(stderr,
                   "yarnhom plot: no python3 with matplotlib, h5py and numpy was found (tried "
                   "$YARNHOM_PYTHON, /usr/bin/python3, python3); the numbers are in %s. Install "
                   "python3-matplotlib python3-h5py (Debian) or set YARNHOM_PYTHON.\n",
                   data.c_str());
      throw ExitCode{2};
    }
    const std::string script = (fs::path(scripts_dir()) / "plot" / "plot_run.py").string();
    if (!fs::exists(script)) throw std::invalid_argument(script + ": plot script not found (set YARNHOM_SCRIPTS to the tools folder)");
    const std::string cmdline = "'" + py + "' '" + script + "' '" + data + "' '" + out.string() + "'";
    const int rc = std::system(cmdline.c_str());
    if (rc != 0) {
      std::fprintf(stderr, "yarnhom plot: the plot script failed (%s)\n", cmdline.c_str());
      throw ExitCode{1};
    }
  });
}

}  // namespace yarnhom::tools
