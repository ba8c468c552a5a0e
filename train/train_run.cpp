#include "train/train_run.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "core/console.hpp"
#include "core/dataset.hpp"
#include "core/model.hpp"
#include "core/number_list.hpp"
#include "train/trainer.hpp"

namespace yarnhom {
namespace {

// Live progress: on a terminal, one line per network redrawn in place (at most 5 times a
// second); otherwise a block of lines at every tenth of the run.
class Progress {
 public:
  explicit Progress(bool quiet) : quiet_(quiet), tty_(stderr_is_tty()) { t0_ = omp_get_wtime(); }

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
  double t0_, last_draw_ = -1;
};

// The recipe's values, then whatever the command line gives explicitly.
TrainerOptions trainer_options(const TrainRunOptions& o, const std::set<std::string>& given_set) {
  TrainerOptions opt = recipe_options(o.recipe);
  auto given = [&](const char* name) { return given_set.count(name) > 0; };
  if (given("--lr")) opt.config.adam.lr = o.lr;
  if (given("--batch-1d")) opt.batch_1d = o.batch1;
  if (given("--batch-2d")) opt.batch_2d = o.batch2;
  if (given("--epochs")) opt.config.epochs = o.epochs;
  if (given("--polish")) opt.polish.iterations = o.polish, opt.polish.iterations_1d = -1;
  if (given("--polish-w-c")) opt.polish.w_c = o.polish_wc;
  if (given("--polish-w-s")) opt.polish.w_s = o.polish_ws;
  if (given("--polish-keep-last")) opt.polish.keep_best = false;
  if (given("--polish-memory-2d")) opt.polish.memory_2d = o.polish_memory_2d;
  if (given("--relative-fit")) opt.polish.relative_floor[0] = o.relative;
  if (given("--relative-fit-2d")) opt.polish.relative_floor[1] = o.relative_2d;
  if (given("--rest-curvature")) opt.polish.rest_weight = o.rest_weight;
  if (given("--rest-mixed")) opt.polish.rest_weight_2d = o.rest_mixed;
  if (given("--polish-float")) opt.polish.in_double[0] = opt.polish.in_double[1] = false;
  opt.seed = o.seed;
  opt.net.hidden = parse_ints(o.hidden, "--hidden");
  if (given("--hidden")) opt.hidden_2d.clear();
  if (given("--hidden-2d")) opt.hidden_2d = parse_ints(o.hidden_2d, "--hidden-2d");
  opt.config.threads = o.threads > 0 ? o.threads : omp_get_max_threads();  // all cores, or OMP_NUM_THREADS
  opt.config.off_domain = o.off;
  opt.config.loss.w = LossWeights{o.wz, o.wf, o.wc, o.ws, o.wx};
  opt.config.loss.stencil_c = o.stencil;
  opt.config.loss.stencil_eps = o.stencil_eps;
  return opt;
}

// The table: losses in the normalized units training works in, then the fit in physical
// meaning on the held-out validation points (core/fit_metrics.hpp), with the verdict.
// "data G" is the data's own inconsistency (gradients against the slopes of their energies,
// same unit as G err/avg): a term whose data are not smooth cannot be fitted below it.
// "S err" is the small-stress error of a 1D term (1-20 % of its largest stress, relative).
void print_table(const TrainResult& res, double wall) {
  std::printf("%-5s %11s %11s %6s %6s %8s  %9s %9s %7s %7s  %s\n", "term", "train loss", "val loss", "epochs", "polish",
              "time", "E err/rng", "G err/avg", "S err", "data G",
              "validation fit (limits: energy RMSE < 3% of range, gradient error < 10% of mean or, where data G >= 10%, < 1.25 x data G; small stresses < 10%)");
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
}

}  // namespace

int run_training(const TrainRunOptions& o, const std::set<std::string>& given) {
  std::vector<Term> terms;
  if (!o.term.empty()) terms = {term_by_name(o.term)};
  else if (o.terms != "all") terms = parse_term_list(o.terms);
  TrainerOptions opt = recipe_options(o.recipe);
  const int epochs = given.count("--epochs") ? o.epochs : opt.config.epochs;
  const int polish = given.count("--polish") ? o.polish : opt.polish.iterations;
  prepare_output(o.out, {o.dataset});
  Dataset ds = read_dataset(o.dataset);
  if (terms.empty())
    for (auto& t : ds.terms) terms.push_back(t.term);
  opt = trainer_options(o, given);
  auto backend = make_backend(o.backend);
  for (const Term& t : terms)
    if (!ds.find(t.name))
      throw std::invalid_argument(o.dataset + ": the dataset has no term '" + t.name + "'");
  std::fprintf(stderr, "training %zu network(s) on %s (%s data) with backend %s, %d thread(s), recipe %s: %d epochs%s\n",
               terms.size(), o.dataset.c_str(), ds.source.c_str(), backend->name().c_str(), opt.config.threads,
               o.recipe.c_str(), epochs,
               polish > 0 ? (", then up to " + std::to_string(polish) + " L-BFGS iterations" +
                             (opt.polish.iterations_1d >= 0 && opt.polish.iterations_1d != polish
                                  ? " (" + std::to_string(opt.polish.iterations_1d) + " for the 1D terms)"
                                  : std::string()) +
                             (backend->name() == "cuda" ? " (GPU)" : " (CPU)")).c_str()
                          : "");
  Progress progress(o.quiet);
  const double t0 = omp_get_wtime();
  TrainResult res = train_terms(ds, o.dataset, terms, opt, *backend, std::ref(progress));
  print_table(res, omp_get_wtime() - t0);
  if (res.model.networks.empty()) {
    std::fprintf(stderr, "yarnhom: error: no network trained successfully; %s not written\n", o.out.c_str());
    return 2;
  }
  write_model(o.out, res.model);
  std::printf("wrote %s (%zu network(s))\n", o.out.c_str(), res.model.networks.size());
  if (!res.all_ok()) {
    std::fprintf(stderr, "yarnhom: error: some networks failed (see the status column); the model holds the others\n");
    return 2;
  }
  return 0;
}

}  // namespace yarnhom
