// yarnhom study architectures: supplement Table 3. The four networks of the paper, trained on one term
// with the same recipe, seed and split, one after the other on the same threads, side by side:
// validation loss (normalized units, as the paper's) and training time, with the fit in
// physical units (core/fit_metrics.hpp) and a PNG.
#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/dataset.hpp"
#include "train/recipe.hpp"
#include "train/trainer.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"
#include "tools/python_env.hpp"

namespace yarnhom::tools {

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

void register_architectures(CLI::App* study) {
  struct Opts {
    std::string dataset, term = "0", out = "study_architectures", recipe = "paper", backend = "cpu";
    int threads = 1, epochs = 0;
    uint64_t seed = 0;
    bool no_plot = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = study->add_subcommand(
      "architectures",
      "Supplement Table 3: train the paper's four networks Net-1 [16,16], Net-2 [32,32], Net-3 "
      "[16,32,16] and Net-4 [32,64,32] on one term with the same recipe, seed and split, one after "
      "the other, and print their validation loss (normalized units, as the paper's) and "
      "training time side by side with the paper's figures (basket term 0: 0.232, 0.181, 0.148, "
      "0.197; 83.5-114.3 s on its GPU), with the fit in physical units. Writes OUT/architectures.csv "
      "and OUT/architectures.png.");
  cmd->add_option("DATASET", o->dataset, "Dataset file (HDF5) written by 'produce' or 'synth'")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--term", o->term, "The term to train, e.g. 0 or 02 (the paper's table: basket term 0)")
      ->capture_default_str();
  cmd->add_option("-o,--output", o->out, "Folder for architectures.csv and architectures.png (created)")
      ->capture_default_str();
  cmd->add_option("--recipe", o->recipe, "Training recipe, as train-all's (the paper's table used the paper's)")
      ->check(CLI::IsMember(recipe_names()))
      ->capture_default_str();
  cmd->add_option("--epochs", o->epochs, "Epochs (0: the recipe's, 500)")->check(CLI::NonNegativeNumber)->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of split, initialization, shuffling")->capture_default_str();
  cmd->add_option("--threads", o->threads,
                  "CPU threads per network (1: each network's time is one core's, comparable across runs)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--backend", o->backend, "Compute backend for the epochs: cpu, or cuda when built with CUDA")
      ->capture_default_str();
  cmd->add_flag("--no-plot", o->no_plot, "Do not draw the PNG (the CSV is written anyway)");
  cmd->callback([o] {
    const Dataset ds = read_dataset(o->dataset);
    const Term term = term_by_name(o->term);
    if (!ds.find(term.name)) throw std::invalid_argument(o->dataset + ": the dataset has no term '" + term.name + "'");
    fs::create_directories(o->out);
    std::fprintf(stderr, "study architectures: term %s of %s, recipe %s, seed %llu, %d thread(s) per network\n",
                 term.name.c_str(), o->dataset.c_str(), o->recipe.c_str(), static_cast<unsigned long long>(o->seed),
                 o->threads);
    struct Row {
      const Architecture* arch;
      int params = 0;
      double val = 0, seconds = 0;
      FitQuality fit;
      std::string status;
    };
    std::vector<Row> rows;
    for (const Architecture& a : table3()) {
      TrainerOptions opt = recipe_options(o->recipe);
      if (o->epochs > 0) opt.config.epochs = o->epochs;
      opt.seed = o->seed;
      opt.net.hidden = a.hidden;
      opt.hidden_2d.clear();  // the architecture under study, whatever the recipe gives 2D terms
      opt.config.threads = o->threads;
      auto backend = make_backend(o->backend);
      std::fprintf(stderr, "  %s [%s] ...", a.name, join(a.hidden).c_str());
      const double t0 = omp_get_wtime();
      TrainResult res = train_terms(ds, o->dataset, {term}, opt, *backend);
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
      rows.push_back(r);
    }
    std::printf("Supplement Table 3 on term %s of %s (recipe %s, seed %llu; validation loss in normalized units%s)\n",
                term.name.c_str(), o->dataset.c_str(), o->recipe.c_str(), static_cast<unsigned long long>(o->seed),
                o->recipe == "default" ? ", the polish's data loss L_Z + w_F L_F" : ", the recipe's loss L");
    std::printf("%-6s %-12s %7s %12s %10s  %10s %10s  %14s\n", "net", "hidden", "weights", "val loss", "time",
                "val E/rng", "val G/avg", "paper val loss");
    const std::string csv = (fs::path(o->out) / "architectures.csv").string();
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
    if (o->no_plot) return;
    const std::string py = find_python();
    if (py.empty()) {
      std::fprintf(stderr, "yarnhom study: no python3 with matplotlib was found; the numbers are in %s\n", csv.c_str());
      return;
    }
    const std::string png = (fs::path(o->out) / "architectures.png").string();
    const std::vector<std::string> argv = {py, scripts_dir() + "/plot/plot_study.py", "architectures", csv, png,
                                           "term " + term.name + " of " + fs::path(o->dataset).filename().string() +
                                               ", recipe " + o->recipe};
    if (run_child(argv, "/dev/null", "") != 0) {
      std::fprintf(stderr, "yarnhom study: drawing %s failed; the numbers are in %s\n", png.c_str(), csv.c_str());
      throw ExitCode{2};
    }
    std::printf("wrote %s\n", png.c_str());
  });
}

}  // namespace

void register_study_architectures(CLI::App& app) {
  // The `study` group is shared with the accuracy studies (tools/cmd_study.cpp): whichever
  // registers first creates it.
  CLI::App* study = nullptr;
  for (CLI::App* s : app.get_subcommands([](CLI::App*) { return true; }))
    if (s->get_name() == "study") study = s;
  if (!study) {
    study = app.add_subcommand("study", "Studies that reproduce the supplement's tables (docs/accuracy.md, docs/training.md)");
    study->require_subcommand(1);
  }
  register_architectures(study);
}

}  // namespace yarnhom::tools
