#pragma once
// `yarnhom study`: the supplement's tables as commands (docs/accuracy.md, docs/training.md).
// table5, bake-resolution, rve-size and strip-width run the accuracy test
// (pipeline/accuracy_run.hpp) for several patterns, directions, materials or strips, cached and
// resumable stage by stage, and write a Markdown and a CSV table beside the paper's figures;
// architectures trains the paper's four networks on one term.
#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/accuracy_run.hpp"

namespace yarnhom::pipeline {

// The accuracy test's options as the studies start them: the paper's sampling preset.
inline AccuracyOptions study_accuracy_defaults(const std::string& stretch = "1.0:1.7:0.05") {
  AccuracyOptions a;
  a.preset = "paper";
  a.stretch = stretch;
  return a;
}

// Supplement Table 5: every pattern and direction, neural material and spline baseline;
// OUT/table5.md, OUT/table5.csv and the Fig. 5 pictures.
struct Table5Options {
  std::vector<std::string> patterns;
  std::vector<std::string> directions = {"course", "wale"};
  std::string out;
  AccuracyOptions acc = study_accuracy_defaults();
};
void run_study_table5(const Table5Options& o);

// Supplement Table 4: the same networks baked at Bake-1, -2, -3 and a reference resolution, one
// yarn strip for all; OUT/table4.md and .csv.
struct BakeResolutionOptions {
  std::string pattern, out, direction = "wale";
  int reference_res1d = 2000, reference_res2d = 400;  // the reference bake, standing for the network
  AccuracyOptions acc = study_accuracy_defaults();
};
void run_study_bake_resolution(const BakeResolutionOptions& o);

// The accuracy test on strips of one length and several widths, one neural material for all;
// OUT/width.md, width.csv and width.png.
struct StripWidthOptions {
  std::string pattern, out, direction = "wale", dataset, baked;
  std::vector<double> widths = {0.02, 0.04, 0.06, 0.08};
  double length = 0.04;
  bool no_plot = false;
  AccuracyOptions acc = study_accuracy_defaults("1.0:1.3:0.1");
};
void run_study_strip_width(const StripWidthOptions& o);

// Supplement Table 2: datasets produced on n x n patches of the pattern, each trained, baked and
// tested against the same yarn strip; OUT/table2.md and .csv.
struct RveSizeOptions {
  std::string pattern, out, direction = "wale";
  std::vector<int> tiles = {1, 2, 3};
  AccuracyOptions acc = study_accuracy_defaults();
};
void run_study_rve_size(const RveSizeOptions& o);

// Supplement Table 3: the paper's four networks trained on one term with the same recipe, seed
// and split; OUT/architectures.csv and .png. Returns the exit status: 0, or 2 when the picture
// failed.
struct ArchitecturesOptions {
  std::string dataset, term = "0", out = "study_architectures", recipe = "paper", backend = "cpu";
  int threads = 1, epochs = 0;
  uint64_t seed = 0;
  bool no_plot = false;
};
int run_study_architectures(const ArchitecturesOptions& o);

}  // namespace yarnhom::pipeline
