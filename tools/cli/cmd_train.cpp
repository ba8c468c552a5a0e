// yarnhom train-all / train: fit one MLP per energy term (train/train_run.hpp).
#include <unistd.h>

#include <filesystem>

#include "core/atomic_file.hpp"
#include "tools/cli/cli_util.hpp"
#include "train/train_run.hpp"

namespace yarnhom::tools {
namespace {

// Hidden layer sizes: positive integers that make a valid network.
CLI::Validator sizes_check(const char* flag) {
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
}

void add_recipe_options(CLI::App* cmd, TrainRunOptions& o) {
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
}

void add_loss_options(CLI::App* cmd, TrainRunOptions& o) {
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
}

void add_polish_options(CLI::App* cmd, TrainRunOptions& o) {
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
                  "yarn/rve/rest_hessian.hpp), or for datasets without one the central difference of the "
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
  cmd->add_option("--polish-memory-2d", o.polish_memory_2d,
                  "L-BFGS history pairs of the 2D terms' polish (1-32; the 1D terms keep 10; the default "
                  "recipe: 30, which ends their polishes after about a third fewer evaluations; "
                  "docs/training.md, \"The polish's memory and stops\")")
      ->check(CLI::Range(1, 32))
      ->capture_default_str();
  cmd->add_flag("--polish-keep-last", o.polish_keep_last,
                "End the polish on its last iterate, not the one with the lowest validation data loss");
}

// The options train-all and train share.
void add_common(CLI::App* cmd, TrainRunOptions& o) {
  cmd->add_option("DATASET", o.dataset, "Dataset file (HDF5) written by 'produce' or 'synth'")
      ->required()
      ->check(existing_regular_file());
  add_output_option(cmd, o.out,
                    "Model file to write (HDF5). Written under a temporary name and renamed at the "
                    "end: an interrupted run never leaves a partial model or destroys an old one");
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
  add_threads_option(cmd, o.threads, "CPU threads (0: all cores, or OMP_NUM_THREADS where set)")->capture_default_str();
  add_recipe_options(cmd, o);
  add_loss_options(cmd, o);
  add_polish_options(cmd, o);
  add_quiet_flag(cmd, o.quiet, "No live progress, only the final table");
}

// A failed run leaves the previous model as it was: the model goes to a temporary beside -o
// (AtomicOutput's name, which the next write of -o removes if this process is killed) and is
// renamed over -o only when every network trained. When some failed (exit 2), the networks
// that trained are kept in STEM.failed.h5 beside it, saying so.
int train_keeping_previous(TrainRunOptions o, const std::set<std::string>& given) {
  namespace fs = std::filesystem;
  const std::string target = prepare_output(o.out, {o.dataset});
  const std::string out = o.out;
  o.out = AtomicOutput::temporary_name(target, ::getpid());
  int status = 0;
  try {
    status = run_training(o, given);
  } catch (...) {
    std::error_code ec;
    fs::remove(o.out, ec);
    throw;
  }
  std::error_code ec;
  if (status == 0) {
    fs::rename(o.out, target);
    std::printf("renamed to %s\n", out.c_str());
    return 0;
  }
  if (fs::exists(o.out)) {
    const fs::path t(target);
    const fs::path failed = t.parent_path() / (t.stem().string() + ".failed" + t.extension().string());
    fs::rename(o.out, failed, ec);
    if (ec) fs::remove(o.out, ec);
    else std::fprintf(stderr, "yarnhom: the networks that trained are in %s\n", failed.string().c_str());
  }
  std::fprintf(stderr, "yarnhom: %s %s\n", out.c_str(),
               fs::exists(target) ? "left as it was (this run failed)" : "not written (this run failed)");
  return status;
}

}  // namespace

void register_train(CLI::App& app) {
  auto [all, oa] = add_command<TrainRunOptions>(app, "train-all");
  add_common(all, *oa);
  all->add_option("--terms", oa->terms, "Terms to train, e.g. 0,02,15 (default: all in the dataset)")
      ->check(term_list_validator())
      ->capture_default_str();
  CLI::App* all_cmd = all;
  all->callback([oa, all_cmd] { exit_with(train_keeping_previous(*oa, given_options(*all_cmd))); });

  auto [one, o1] = add_command<TrainRunOptions>(app, "train");
  add_common(one, *o1);
  one->add_option("--term", o1->term, "The term, e.g. 02")->required()->check(term_list_validator(true));
  CLI::App* one_cmd = one;
  one->callback([o1, one_cmd] { exit_with(train_keeping_previous(*o1, given_options(*one_cmd))); });
}

}  // namespace yarnhom::tools
