#include "pipeline/pipeline_stage.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/text_file.hpp"

namespace yarnhom {

namespace fs = std::filesystem;

StageDecision stage_decision(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs,
                             const std::string& stamp_path, const std::string& settings) {
  for (const std::string& o : outputs)
    if (!fs::exists(o)) return {true, "output " + o + " is missing"};
  {
    std::ifstream in(stamp_path);
    if (!in) return {true, "no record of a completed run"};
    std::stringstream ss;
    ss << in.rdbuf();
    if (ss.str() != settings) return {true, "settings changed since the last run"};
  }
  fs::file_time_type oldest = fs::file_time_type::max();
  for (const std::string& o : outputs) oldest = std::min(oldest, fs::last_write_time(o));
  for (const std::string& i : inputs) {
    if (!fs::exists(i)) return {true, "input " + i + " is missing"};
    if (fs::last_write_time(i) > oldest) return {true, "input " + i + " is newer than the output"};
  }
  return {false, "up to date"};
}

void write_stage_stamp(const std::string& stamp_path, const std::string& settings) {
  write_text_file(stamp_path, settings, "cannot write the stage record");
}

}  // namespace yarnhom
