#pragma once
// The named training recipes (docs/training.md):
//   "default"   the paper's 500 Adam epochs, then the full-batch L-BFGS polish (train/polish.hpp)
//               of up to 16000 iterations (8000 for the 1D terms) on the data losses L_Z + w_F L_F,
//               with Net-2 [32,32] for the 2D terms and Net-3 [16,32,16] for the 1D terms,
//               the 1D terms' in double, their points weighted for a relative fit (floor 0.1)
//               and their curvature at rest held to the data's (weight 0.1), ending on the
//               iterate with the lowest validation data loss;
//   "paper"     the paper's recipe exactly (spec section 6): the epochs alone;
//   "improved"  the paper's epochs with lr 3e-3 and 2D batch 32, no polish (kept for comparison).
#include <string>
#include <vector>

#include "train/trainer.hpp"

namespace yarnhom {

// Throws std::invalid_argument naming the known recipes.
TrainerOptions recipe_options(const std::string& recipe);
std::vector<std::string> recipe_names();

}  // namespace yarnhom
