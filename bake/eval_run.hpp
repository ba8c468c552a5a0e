#pragma once
// `yarnhom eval`: a trained term's energy and derivatives at given strains, as CSV on stdout
// (the network's term as bake bakes it, or a baked file's table, safeguard included).
#include <string>
#include <vector>

namespace yarnhom {

struct EvalOptions {
  std::string model, term, points;  // model: a model or a baked file; points: a CSV of strains
  std::vector<std::string> at;      // strain points, "d comma-separated values" each
};

void run_eval(const EvalOptions& o);

}  // namespace yarnhom
