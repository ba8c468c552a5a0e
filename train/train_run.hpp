#pragma once
// `yarnhom train-all` / `train`: fit one MLP per energy term (the default recipe: the paper's
// Adam epochs, then a full-batch L-BFGS polish; --recipe paper: the paper's recipe exactly),
// with live progress and the final table of each term's fit in physical units.
#include <cstdint>
#include <set>
#include <string>

#include "train/recipe.hpp"

namespace yarnhom {

struct TrainRunOptions {
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
  int polish_memory_2d = recipe_options("default").polish.memory_2d;
};

// Trains `term` when set (train), else `terms` ("all": every term the dataset has; train-all),
// and writes the model. `given`: the options given on the command line ("--lr", ...), which
// override the recipe's values; the others are the recipe's. Returns the exit status: 0, or 2
// when a network failed (the model holds the others; none trained: no model written).
int run_training(const TrainRunOptions& o, const std::set<std::string>& given);

}  // namespace yarnhom
