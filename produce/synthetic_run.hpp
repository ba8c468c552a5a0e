#pragma once
// `yarnhom synth`: a dataset in the spec's format from the analytic energy of docs/synthetic.md.
#include <string>

namespace yarnhom {

// Writes the dataset ("quick" or "paper" sampling) and one line on stdout.
void run_synth(const std::string& out, const std::string& preset);

}  // namespace yarnhom
