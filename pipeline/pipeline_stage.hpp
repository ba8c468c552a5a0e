#pragma once
// Skip-and-resume for `yarnhom pipeline`: a stage runs only when its result is missing or out of
// date, so that a rerun after an interruption continues where it stopped. A stage is out of
// date when
//   - one of its outputs is missing, or
//   - one of its inputs is newer than its oldest output (the input changed), or
//   - it was last run with other settings (its stamp file holds the settings of the last
//     successful run; none means never completed).
// Outputs are written atomically by the stages themselves, so an interrupted stage leaves no
// output and reruns. The stamp is written only after the stage succeeded.
#include <string>
#include <vector>

namespace yarnhom {

struct StageDecision {
  bool run = true;
  std::string reason;  // why it runs, or "up to date"
};

StageDecision stage_decision(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs,
                             const std::string& stamp_path, const std::string& settings);

// Records a successful run with these settings (atomically).
void write_stage_stamp(const std::string& stamp_path, const std::string& settings);

}  // namespace yarnhom
