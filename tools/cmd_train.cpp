// yarnhom train-all / train: fit one MLP per energy term (the default recipe: the paper's Adam
// epochs, then a full-batch L-BFGS polish; --recipe paper: the paper's recipe exactly).
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "core/dataset.hpp"
#include "core/model.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"
#include "train/recipe.hpp"
#include "train/trainer.hpp"

namespace yarnhom::tools {
namespace {

struct TrainOpts {
  std::string dataset, out, backend = "cpu", terms = "all", term, hidden = "16,32,16", hidden_2d, recipe = "default";
  int epochs = 500, threads = 0;
  uint64_t seed = 0;
  double lr = 1e-3;
  double wz = 1.0, wf = 0.05, wc = 1e-3, ws = 1e2, wx = 0.0;
  bool stencil = false, quiet = false;
  double stencil_eps = 1e-2;
  int batch1 = 4, batch2 = 128, off = 50;
  int polish = recipe_options("default").polish.iterations;  // shown by --help; the recipe sets it
  double polish_wc = 0, polish_ws = 0, relative = 0.1, relative_2d = 0;
  bool polish_float = false;
  double rest_weight = 0.1, rest_mixed = 0;
  bool polish_keep_last = false;
};

void add_common(CLI::App* cmd, TrainOpts& o) {
  cmd->add_option("DATASET", o.dataset, "Dataset file (HDF5) written by 'produce' or 'synth'")
      ->required()
      ->check(existing_regular_file());
  cmd->add_option("-o,--output", o.out,
                  "Model file to write (HDF5). Written under a temporary name and renamed at the "
                  "end: an interrupted run never leaves a partial model or destroys an old one")
      ->required();
  cmd->add_option("--backend", o.backend, "Compute backend: cpu, or cuda when built with CUDA")
      ->check(backend_validator())
      ->capture_default_str();
  cmd->add_option("--epochs", o.epochs, "Epochs per network (the paper: 500)")
      ->check(CLI::Range(1, 100000000))
      ->capture_default_str();
  cmd->add_option("--seed", o.seed,
                  "Seed of the split, initialization, shuffling and off-domain points; the same "
                  "seed and backend give identical weights (on the CPU for any thread count)")
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "CPU threads (0: all cores)")->check(CLI::Range(0, kMaxThreads))->capture_default_str();
  cmd->add_option("--recipe", o.recipe,
                  "'default': the paper's 500 Adam epochs (lr 1e-3, batch 4 (1D) / 128 (2D), plateau "
                  "schedule, losses L_Z L_F L_C L_S), then a full-batch L-BFGS polish of up to --polish "
                  "iterations on the data losses L_Z + w_F L_F (the 1D terms in double, weighted for a relative "
                  "fit and held to the data's curvature at rest: --relative-fit, --rest-curvature), ending on "
                  "the iterate with the lowest validation data loss (docs/training.md, \"The default recipe\"); the 2D terms' "
                  "networks are Net-2 [32,32] (--hidden-2d). 'paper': the paper's "
                  "recipe exactly (no polish). 'improved': lr 3e-3 and 2D batch 32, no polish (the "
                  "earlier improvement). --lr, --batch-2d and --polish override the recipe's values")
      ->check(CLI::IsMember({"default", "paper", "improved"}))
      ->capture_default_str();
  cmd->add_option("--lr", o.lr, "Initial Adam learning rate (the recipe's: 1e-3; improved: 3e-3)")->check(finite_positive())->capture_default_str();
  auto sizes_check = [](const char* flag) {
    return CLI::Validator(
        [flag](std::string& in) -> std::string {
          try {
            NetworkDesc desc;
            desc.hidden = parse_ints(in, flag, 1024);
            desc.validate();
          } catch (const std::exception& e) {
            return e.what();
          }
          return "";
        },
        "SIZES");
  };
  cmd->add_option("--hidden", o.hidden,
                  "Hidden layer sizes of every network (the paper's Net-3: 16,32,16). Given explicitly, it "
                  "replaces the recipe's 2D sizes too, unless --hidden-2d is also given")
      ->check(sizes_check("--hidden"))
      ->capture_default_str();
  cmd->add_option("--hidden-2d", o.hidden_2d,
                  "Hidden layer sizes of the 2D terms' networks only (the default recipe: 32,32, the paper's "
                  "Net-2, which fits the shear and bending couplings better than Net-3; docs/training.md; the "
                  "'paper' and 'improved' recipes: as --hidden)")
      ->check(sizes_check("--hidden-2d"));
  cmd->add_option("--w-z", o.wz, "Weight of L_Z (energy)")->check(finite_non_negative())->capture_default_str();
  cmd->add_option("--w-f", o.wf, "Weight of L_F (force = gradient)")->check(finite_non_negative())->capture_default_str();
  cmd->add_option("--w-c", o.wc, "Weight of L_C (third-order smoothness)")->check(finite_non_negative())->capture_default_str();
  cmd->add_option("--w-s", o.ws, "Weight of L_S (strain concentration, off-domain)")->check(finite_non_negative())->capture_default_str();
  cmd->add_option("--w-x", o.wx, "Weight of L_X (convexity; 0 as in the paper)")->check(finite_non_negative())->capture_default_str();
  cmd->add_flag("--stencil-c", o.stencil,
                "Compute L_C with the paper's finite-difference stencil instead of exact third "
                "derivatives");
  cmd->add_option("--stencil-eps", o.stencil_eps, "Stencil step in normalized units")->check(finite_range(1e-8, 0.5, "in [1e-8, 0.5]"))->capture_default_str();
  cmd->add_option("--batch-1d", o.batch1, "Batch size of 1D terms")->check(CLI::Range(1, 1 << 20))->capture_default_str();
  cmd->add_option("--batch-2d", o.batch2, "Batch size of 2D terms (the recipe's: 128; improved: 32)")->check(CLI::Range(1, 1 << 20))->capture_default_str();
  cmd->add_option("--off-domain", o.off, "Fresh off-domain points per batch for L_S")
      ->check(CLI::Range(0, 1 << 20))
      ->capture_default_str();
  cmd->add_option("--polish", o.polish,
                  "Maximum L-BFGS iterations of the full-batch polish after the epochs, every term (0: none; "
                  "the 'paper' and 'improved' recipes have none; the default recipe: 16000 (the 2D terms; they stop earlier where they converge), and 8000 for the "
                  "1D terms, which also hold their curvature at rest)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--polish-w-c", o.polish_wc,
                  "Weight of L_C in the polish (negative: as --w-c). 0 by default: the absolute value "
                  "of the third derivatives is not smooth, and L-BFGS stalls on it")
      ->capture_default_str();
  cmd->add_option("--polish-w-s", o.polish_ws,
                  "Weight of L_S in the polish (negative: as --w-s). 0 by default: the baked safeguard "
                  "makes the energy rise outside the box by construction, and L_S fights the data where "
                  "a term's own outward slope is negative")
      ->capture_default_str();
  cmd->add_option("--relative-fit", o.relative,
                  "F: the polish weights each point of a 1D term by 1 + 1 / (|g|^2 / G^2 + F^2), G the "
                  "term's RMS gradient: where the stress is small (near rest) the fit is relative to it, "
                  "down to F times the typical one; where it is large the fit stays absolute (the "
                  "default recipe: 0.1; 0: unweighted; docs/training.md, \"Relative fit\")")
      ->check(finite_non_negative())
      ->capture_default_str();
  cmd->add_option("--relative-fit-2d", o.relative_2d, "The same for the 2D terms (0: unweighted)")
      ->check(finite_non_negative())
      ->capture_default_str();
  cmd->add_option("--rest-curvature", o.rest_weight,
                  "W > 0: the polish holds each 1D term's curvature at rest to the data's with a penalty "
                  "W (y'' - k)^2 in normalized units: k is the dataset's measured rest Hessian (produce, "
                  "yarn/rest_hessian.hpp), or for datasets without one the central difference of the "
                  "gradients on either side of s = 0 (the default recipe: 0.1; 0: off)")
      ->check(finite_non_negative())
      ->capture_default_str();
  cmd->add_option("--rest-mixed", o.rest_mixed,
                  "W > 0: the same for each 2D term's mixed derivative at rest, held to the measured rest "
                  "Hessian's (datasets that have one; off by default: it costs the shear-bending couplings' "
                  "fit, docs/training.md \"Rest Hessian\")")
      ->check(finite_non_negative())
      ->capture_default_str();
  cmd->add_flag("--polish-float", o.polish_float,
                "Compute the 1D terms' polish in float instead of double (faster, but L-BFGS stops "
                "early on rounding once the fit is good; the 2D terms' polish is in float anyway)");
  cmd->add_flag("--polish-keep-last", o.polish_keep_last,
                "End the polish on its last iterate, not the one with the lowest validation data loss");
  cmd->add_flag("-q,--quiet", o.quiet, "No live progress, only the final table");
}

// Live progress: on a terminal, one line per network redrawn in place (at most 5 times a
// second); otherwise a block of lines at every tenth of the run.
class Progress {
 public:
  Progress(bool quiet, size_t nets) : quiet_(quiet), tty_(stderr_is_tty()), nets_(nets) { t0_ = omp_get_wtime(); }

  void operator()(int epoch, int epochs, const std::vector<ProgressRow>& rows) {
    if (quiet_) return;
    const double now = omp_get_wtime(), el = now - t0_;
    const bool last = epoch == epochs;
    if (tty_) {
      if (!last && now - last_draw_ < 0.2) return;
    } else {
      const int step = std::max(1, epochs / 10);
      if (!last && epoch % step != 0) return;
    }
    last_draw_ = now;
    const double eta = el / epoch * (epochs - epoch);
    if (tty_ && drawn_) std::fprintf(stderr, "\x1b[%zuA", rows.size() + 1);
    std::fprintf(stderr, "%sepoch %d/%d  elapsed %s  ETA %s\n", tty_ ? "\x1b[2K" : "", epoch,
                 epochs, format_seconds(el).c_str(), format_seconds(eta).c_str());
    for (const ProgressRow& r : rows) {
      std::fprintf(stderr, "%s  %-3s epoch %4d  train %.3e  val %.3e  (Z %.2e F %.2e C %.2e S %.2e)  lr %.2e  %s\n",
                   tty_ ? "\x1b[2K" : "", r.name.c_str(), r.epochs_done, r.stats.train.total,
                   r.stats.val.total, r.stats.train.z, r.stats.train.f, r.stats.train.c,
                   r.stats.train.s, r.lr, r.status == "ok" ? "" : r.status.c_str());
    }
    drawn_ = true;
  }

 private:
  bool quiet_, tty_, drawn_ = false;
  size_t nets_;
  double t0_, last_draw_ = -1;
};

// terms empty: every term the dataset has.
void run_training(TrainOpts o, std::vector<Term> terms, const CLI::App& cmd) {
  // The recipe's values, then whatever the command line gives explicitly.
  TrainerOptions opt = recipe_options(o.recipe);
  auto given = [&](const char* name) { return cmd.count(name) > 0; };
  if (given("--lr")) opt.config.adam.lr = o.lr;
  if (given("--batch-1d")) opt.batch_1d = o.batch1;
  if (given("--batch-2d")) opt.batch_2d = o.batch2;
  if (given("--epochs")) opt.config.epochs = o.epochs;
  if (given("--polish")) opt.polish.iterations = o.polish, opt.polish.iterations_1d = -1;
  if (given("--polish-w-c")) opt.polish.w_c = o.polish_wc;
  if (given("--polish-w-s")) opt.polish.w_s = o.polish_ws;
  if (given("--polish-keep-last")) opt.polish.keep_best = false;
  if (given("--relative-fit")) opt.polish.relative_floor[0] = o.relative;
  if (given("--relative-fit-2d")) opt.polish.relative_floor[1] = o.relative_2d;
  if (given("--rest-curvature")) opt.polish.rest_weight = o.rest_weight;
  if (given("--rest-mixed")) opt.polish.rest_weight_2d = o.rest_mixed;
  if (given("--polish-float")) opt.polish.in_double[0] = opt.polish.in_double[1] = false;
  o.epochs = opt.config.epochs;
  o.polish = opt.polish.iterations;
  prepare_output(o.out, {o.dataset});
  Dataset ds = read_dataset(o.dataset);
  if (terms.empty())
    for (auto& t : ds.terms) terms.push_back(t.term);
  opt.seed = o.seed;
  opt.net.hidden = parse_ints(o.hidden, "--hidden");
  if (given("--hidden")) opt.hidden_2d.clear();
  if (given("--hidden-2d")) opt.hidden_2d = parse_ints(o.hidden_2d, "--hidden-2d");
  opt.config.threads = o.threads > 0 ? o.threads : default_threads();
  opt.config.off_domain = o.off;
  opt.config.loss.w = LossWeights{o.wz, o.wf, o.wc, o.ws, o.wx};
  opt.config.loss.stencil_c = o.stencil;
  opt.config.loss.stencil_eps = o.stencil_eps;
  auto backend = make_backend(o.backend);
  for (const Term& t : terms)
    if (!ds.find(t.name))
      throw std::invalid_argument(o.dataset + ": the dataset has no term '" + t.name + "'");
  std::fprintf(stderr, "training %zu network(s) on %s (%s data) with backend %s, %d thread(s), recipe %s: %d epochs%s\n",
               terms.size(), o.dataset.c_str(), ds.source.c_str(), backend->name().c_str(), opt.config.threads,
               o.recipe.c_str(), o.epochs,
               o.polish > 0 ? (", then up to " + std::to_string(o.polish) + " L-BFGS iterations" +
                               (opt.polish.iterations_1d >= 0 && opt.polish.iterations_1d != o.polish
                                    ? " (" + std::to_string(opt.polish.iterations_1d) + " for the 1D terms)"
                                    : std::string()) +
                               " (CPU)").c_str()
                            : "");
  Progress progress(o.quiet, terms.size());
  const double t0 = omp_get_wtime();
  TrainResult res = train_terms(ds, o.dataset, terms, opt, *backend, std::ref(progress));
  const double wall = omp_get_wtime() - t0;

  // The table: losses in the normalized units training works in, then the fit in physical
  // meaning on the held-out validation points (core/fit_metrics.hpp), with the verdict.
  // "data G" is the data's own inconsistency (gradients against the slopes of their energies,
  // same unit as G err/avg): a term whose data are not smooth cannot be fitted below it.
  // "S err" is the small-stress error of a 1D term (1-20 % of its largest stress, relative).
  std::printf("%-5s %11s %11s %6s %6s %8s  %9s %9s %7s %7s  %s\n", "term", "train loss", "val loss", "epochs", "polish",
              "time", "E err/rng", "G err/avg", "S err", "data G",
              "validation fit (limits: energy RMSE < 3% of range, gradient error < 10% of mean, small stresses < 10%)");
  int failed_fit = 0;
  for (size_t j = 0; j < res.rows.size(); ++j) {
    const ProgressRow& r = res.rows[j];
    const PolishResult& p = res.polish[j];
    const double val = p.iterations > 0 ? p.val_end : r.stats.val.total;
    const double tr = p.iterations > 0 ? p.train_end : r.stats.train.total;
    std::string verdict = r.status;
    char e[32] = "-", g[32] = "-", ss[32] = "-", dg[32] = "-";
    if (r.status == "ok") {
      const FitQuality& q = res.val_fit[j];
      std::snprintf(e, sizeof e, "%.2f%%", 100 * q.energy_rel);
      std::snprintf(g, sizeof g, "%.2f%%", 100 * q.grad_rel);
      if (q.small_stress_rel >= 0) std::snprintf(ss, sizeof ss, "%.1f%%", 100 * q.small_stress_rel);
      if (q.data_inconsistency >= 0) std::snprintf(dg, sizeof dg, "%.1f%%", 100 * q.data_inconsistency);
      verdict = fit_verdict(q);
      failed_fit += !q.ok();
    }
    std::printf("%-5s %11.4e %11.4e %6d %6d %8s  %9s %9s %7s %7s  %s\n", r.name.c_str(), tr, val, r.epochs_done,
                p.iterations, format_seconds(res.seconds[j]).c_str(), e, g, ss, dg, verdict.c_str());
  }
  if (failed_fit)
    std::printf("%d term(s) do not fit their validation data within the limits (see docs/training.md, \"Fit quality\")\n",
                failed_fit);
  std::printf("total wall time %s (per-network times are compute time; networks ran in parallel)\n",
              format_seconds(wall).c_str());
  if (res.model.networks.empty()) {
    std::fprintf(stderr, "yarnhom: error: no network trained successfully; %s not written\n", o.out.c_str());
    throw ExitCode{2};
  }
  write_model(o.out, res.model);
  std::printf("wrote %s (%zu network(s))\n", o.out.c_str(), res.model.networks.size());
  if (!res.all_ok()) {
    std::fprintf(stderr, "yarnhom: error: some networks failed (see the status column); the model holds the others\n");
    throw ExitCode{2};
  }
}

}  // namespace

void register_train(CLI::App& app) {
  auto oa = std::make_shared<TrainOpts>();
  auto* all = app.add_subcommand(
      "train-all",
      "Train every energy term of a dataset (one MLP per term; by default the paper's 500 Adam "
      "epochs then a full-batch L-BFGS polish, --recipe paper for the paper's recipe exactly), "
      "networks in parallel, and write the model file. The final table shows each term's fit to "
      "its held-out validation points in physical units and says which terms fail the limits "
      "(energy RMSE < 3% of the data range, gradient error < 10% of the mean gradient, gradients "
      "in box coordinates), with the data's own inconsistency beside it ('data G': how far the "
      "data's gradients disagree with the slopes of their energies; no smooth fit does better). Exit "
      "status 2 if a network failed (its loss became non-finite).");
  add_common(all, *oa);
  all->add_option("--terms", oa->terms, "Terms to train, e.g. 0,02,15 (default: all in the dataset)")
      ->check(term_list_validator())
      ->capture_default_str();
  all->callback([oa, all] {
    run_training(*oa, oa->terms == "all" ? std::vector<Term>{} : parse_term_list(oa->terms), *all);
  });

  auto o1 = std::make_shared<TrainOpts>();
  auto* one = app.add_subcommand("train", "Train one energy term's network (see train-all for the recipe)");
  add_common(one, *o1);
  one->add_option("--term", o1->term, "The term, e.g. 02")->required()->check(term_list_validator(true));
  one->callback([o1, one] { run_training(*o1, {term_by_name(o1->term)}, *one); });
}

}  // namespace yarnhom::tools
