#include "train/recipe.hpp"

#include <stdexcept>

namespace yarnhom {

std::vector<std::string> recipe_names() { return {"default", "paper", "improved"}; }

TrainerOptions recipe_options(const std::string& recipe) {
  TrainerOptions opt;  // the paper's recipe: Adam 1e-3, batch 4 / 128, 500 epochs, plateau, weights
  opt.recipe = recipe;
  if (recipe == "paper") return opt;
  if (recipe == "improved") {
    opt.config.adam.lr = 3e-3;
    opt.batch_2d = 32;
    return opt;
  }
  if (recipe == "default") {
    opt.polish.iterations = 16000;       // the 2D terms' cap (they stop earlier where they converge)
    opt.hidden_2d = {32, 32};            // Net-2 for the 2D terms (docs/training.md, "The default recipe")
    opt.polish.w_c = 0;
    opt.polish.w_s = 0;
    opt.polish.keep_best = true;
    opt.polish.relative_floor[0] = 0.1;  // the 1D terms' small stresses (docs/training.md, "Relative fit")
    opt.polish.rest_weight = 0.1;        // and their curvature at rest
    opt.polish.iterations_1d = 8000;
    opt.polish.memory_2d = 30;           // (docs/training.md, "The polish's memory and stops")
    return opt;
  }
  std::string names;
  for (const std::string& n : recipe_names()) names += (names.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown recipe '" + recipe + "' (known: " + names + ")");
}

}  // namespace yarnhom
