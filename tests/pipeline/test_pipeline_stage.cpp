// The pipeline's skip-and-resume logic: a completed stage is not rerun; a stage whose input
// changed, whose output vanished or whose settings changed is.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "pipeline/pipeline_stage.hpp"

using namespace yarnhom;
namespace fs = std::filesystem;

namespace {

void touch(const fs::path& p, fs::file_time_type t) {
  std::ofstream(p) << "x";
  fs::last_write_time(p, t);
}

}  // namespace

TEST(PipelineStage, SkipAndResume) {
  const fs::path dir = fs::temp_directory_path() / ("yarnhom_stage_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto t0 = fs::file_time_type::clock::now() - std::chrono::hours(1);
  const std::string in = (dir / "model.h5").string(), out = (dir / "baked.h5").string(), stamp = (dir / "bake.done").string();
  touch(in, t0);
  // Never run: runs.
  EXPECT_TRUE(stage_decision({in}, {out}, stamp, "res 200 100").run);
  // Completed: output newer than input, stamp with the same settings -> skipped.
  touch(out, t0 + std::chrono::minutes(1));
  write_stage_stamp(stamp, "res 200 100");
  StageDecision d = stage_decision({in}, {out}, stamp, "res 200 100");
  EXPECT_FALSE(d.run) << d.reason;
  // Interrupted before the stamp (output present from an older run, no record): runs.
  fs::remove(stamp);
  EXPECT_TRUE(stage_decision({in}, {out}, stamp, "res 200 100").run);
  write_stage_stamp(stamp, "res 200 100");
  // Other settings: runs.
  d = stage_decision({in}, {out}, stamp, "res 150 50");
  EXPECT_TRUE(d.run);
  EXPECT_NE(d.reason.find("settings"), std::string::npos);
  // The input changed after the output was made: runs.
  touch(in, t0 + std::chrono::minutes(2));
  d = stage_decision({in}, {out}, stamp, "res 200 100");
  EXPECT_TRUE(d.run);
  EXPECT_NE(d.reason.find("newer"), std::string::npos);
  // Rerun done: skipped again.
  touch(out, t0 + std::chrono::minutes(3));
  EXPECT_FALSE(stage_decision({in}, {out}, stamp, "res 200 100").run);
  // An output vanished: runs.
  fs::remove(out);
  d = stage_decision({in}, {out}, stamp, "res 200 100");
  EXPECT_TRUE(d.run);
  EXPECT_NE(d.reason.find("missing"), std::string::npos);
  fs::remove_all(dir);
}
