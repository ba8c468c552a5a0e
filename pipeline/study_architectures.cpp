// yarnhom study architectures: supplement Table 3. The four networks of the paper, trained on one
// term with the same recipe, seed and split, one after the other on the same threads, side by
// side: validation loss (normalized units, as the paper's) and training time, with the fit in
// physical units (core/fit_metrics.hpp) and a PNG (pipeline/study.hpp).
#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "core/console.hpp"
#include "core/dataset.hpp"
#include "core/file_checks.hpp"
#include "pipeline/child_process.hpp"
#include "pipeline/python_env.hpp"
#include "pipeline/study.hpp"
#include "pipeline/study_util.hpp"
#include "train/recipe.hpp"
#include "train/trainer.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

namespace {

struct Architecture {
  const char* name;
  std::vector<int> hidden;
  double paper_val_loss;  // supplement Table 3, basket term 0
};

const std::vector<Architecture>& table3() {
  static const std::vector<Architecture> a = {{"Net-1", {16, 16}, 0.232},
                                              {"Net-2", {32, 32}, 0.181},
                                              {"Net-3", {16, 32, 16}, 0.148},
                                              {"Net-4", {32, 64, 32}, 0.197}};
  return a;
}

std::string join(const std::vector<int>& v) {
  std::string s;
  for (int x : v) s += (s.empty() ? "" : ",") + std::to_string(x);
  return s;
}

struct Row {
  const Architecture* arch;
  int params = 0;
  double val = 0, seconds = 0;
  FitQuality fit;
  std::string status;
};

Row train_architecture(const ArchitecturesOptions& o, const Dataset& ds, const Term& term, const Architecture& a,
                       const std::string& progress) {
  TrainerOptions opt = recipe_options(o.recipe);
  if (o.epochs > 0) opt.config.epochs = o.epochs;
  opt.seed = o.seed;
  opt.net.hidden = a.hidden;
  opt.hidden_2d.clear();  // the architecture under study, whatever the recipe gives 2D terms
  opt.config.threads = o.threads;
  auto backend = make_backend(o.backend);
  std::fprintf(stderr, "  %s [%s] (%s) ...", a.name, join(a.hidden).c_str(), progress.c_str());
  const double t0 = omp_get_wtime();
  TrainResult res = train_terms(ds, o.dataset, {term}, opt, *backend);
  Row r;
  r.arch = &a;
  r.seconds = omp_get_wtime() - t0;
  NetworkDesc desc = opt.net;
  desc.input_dim = term.dim();
  r.params = desc.num_params();
  r.status = res.rows[0].status;
  const PolishResult& p = res.polish[0];
  r.val = p.iterations > 0 ? p.val_end : res.rows[0].stats.val.total;
  if (r.status == "ok") r.fit = res.val_fit[0];
  std::fprintf(stderr, " %.1fs\n", r.seconds);
  return r;
}

// The table on stdout and in OUT/architectures.csv (its path returned).
std::string write_table(const ArchitecturesOptions& o, const Term& term, const std::vector<Row>& rows) {
  std::printf("Supplement Table 3 on term %s of %s (recipe %s, seed %llu; validation loss in normalized units%s)\n",
              term.name.c_str(), o.dataset.c_str(), o.recipe.c_str(), static_cast<unsigned long long>(o.seed),
              o.recipe == "default" ? ", the polish's data loss L_Z + w_F L_F" : ", the recipe's loss L");
  std::printf("%-6s %-12s %7s %12s %10s  %10s %10s  %14s\n", "net", "hidden", "weights", "val loss", "time",
              "val E/rng", "val G/avg", "paper val loss");
  const std::string csv = (fs::path(o.out) / "architectures.csv").string();
  std::ofstream out(csv);
  if (!out) throw std::invalid_argument(csv + ": cannot write");
  out << "net,hidden,weights,val_loss,seconds,val_energy_rel_range,val_grad_rel_mean,paper_val_loss,status\n";
  for (const Row& r : rows) {
    std::printf("%-6s %-12s %7d %12.4e %10s  %9.3g%% %9.3g%%  %14.3f  %s\n", r.arch->name,
                ("[" + join(r.arch->hidden) + "]").c_str(), r.params, r.val, format_seconds(r.seconds).c_str(),
                100 * r.fit.energy_rel, 100 * r.fit.grad_rel, r.arch->paper_val_loss,
                r.status == "ok" ? "" : r.status.c_str());
    out << r.arch->name << ",\"" << join(r.arch->hidden) << "\"," << r.params << ',' << r.val << ',' << r.seconds << ','
        << r.fit.energy_rel << ',' << r.fit.grad_rel << ',' << r.arch->paper_val_loss << ',' << r.status << '\n';
  }
  out.close();
  std::printf("paper (basket term 0, PyTorch on an RTX 3060): training times 83.5-114.3 s per network; its loss "
              "normalization is not stated, so compare the ranking, not the values\n");
  std::printf("wrote %s\n", csv.c_str());
  return csv;
}

}  // namespace

int run_study_architectures(const ArchitecturesOptions& o) {
  check_output_folder(o.out);  // before any work: a file, a FIFO, /dev/null, /proc/...
  const Dataset ds = read_dataset(o.dataset);
  const Term term = term_by_name(o.term);
  if (!ds.find(term.name)) throw std::invalid_argument(o.dataset + ": the dataset has no term '" + term.name + "'");
  fs::create_directories(o.out);
  std::fprintf(stderr, "study architectures: term %s of %s, recipe %s, seed %llu, %d thread(s) per network\n",
               term.name.c_str(), o.dataset.c_str(), o.recipe.c_str(), static_cast<unsigned long long>(o.seed), o.threads);
  std::vector<Row> rows;
  // The ETA counts weights: a network's time grows with them.
  auto weights = [&](const Architecture& a) {
    NetworkDesc desc = recipe_options(o.recipe).net;
    desc.hidden = a.hidden;
    desc.input_dim = term.dim();
    return double(desc.num_params());
  };
  double w_total = 0, w_done = 0;
  for (const Architecture& a : table3()) w_total += weights(a);
  const double t0 = omp_get_wtime();
  for (const Architecture& a : table3()) {
    rows.push_back(train_architecture(
        o, ds, term, a, study_progress(int(rows.size()), int(table3().size()), omp_get_wtime() - t0, w_done, w_total)));
    w_done += weights(a);
  }
  const std::string csv = write_table(o, term, rows);
  if (o.no_plot) return 0;
  const std::string py = find_python();
  if (py.empty()) {
    std::fprintf(stderr, "yarnhom study: no python3 with matplotlib was found; the numbers are in %s\n", csv.c_str());
    return 0;
  }
  const std::string png = (fs::path(o.out) / "architectures.png").string();
  const std::vector<std::string> argv = {py, scripts_dir() + "/plot/plot_study.py", "architectures", csv, png,
                                         "term " + term.name + " of " + fs::path(o.dataset).filename().string() +
                                             ", recipe " + o.recipe};
  if (run_child(argv, "/dev/null", "") != 0) {
    std::fprintf(stderr, "yarnhom study: drawing %s failed; the numbers are in %s\n", png.c_str(), csv.c_str());
    return 2;
  }
  std::printf("wrote %s\n", png.c_str());
  return 0;
}

}  // namespace yarnhom::pipeline
