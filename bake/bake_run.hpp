#pragma once
// `yarnhom bake`: trained networks -> Hermite tables with the safeguard (spec section 8), and
// the table of each term's deviation from its network and what the safeguard changed.
#include <string>

namespace yarnhom {

struct BakeRunOptions {
  std::string model, out, data;
  int res1d = 200, res2d = 100;
  bool no_check = false;
};

// Writes the baked file and prints the table and the rest check on stdout.
void run_bake(const BakeRunOptions& o);

// The model's dataset, as given or relative to the model's folder; empty if neither exists.
// FileError when what it names is not a regular file.
std::string find_model_dataset(const std::string& model_path, const std::string& dataset);

}  // namespace yarnhom
