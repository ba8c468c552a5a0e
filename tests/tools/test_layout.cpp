// The tree's rule (docs/layout.md): one concept per folder, and nothing below includes anything
// above. The folders from the bottom of the pipeline to its top; a source file may include
// headers of its own folder and of folders listed before it, never of one listed after it. And
// no source file grows past 600 lines (a concept that needs more is two concepts).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kRooms = {"core",      "numerics",   "io",      "material", "cpu",      "cuda",
                                         "train",     "bake",       "yarn/rod", "yarn/rve", "yarn/strip", "produce",
                                         "sim",       "accuracy",   "pipeline", "tools",    "python"};

// The room of a path relative to the source root ("yarn/rve/rve.hpp" -> index of "yarn/rve"), -1 if none.
int room_of(const std::string& rel) {
  int best = -1;
  size_t best_len = 0;
  for (size_t i = 0; i < kRooms.size(); ++i)
    if (rel.rfind(kRooms[i] + "/", 0) == 0 && kRooms[i].size() > best_len) best = int(i), best_len = kRooms[i].size();
  return best;
}

bool is_source(const fs::path& p) {
  const std::string e = p.extension().string();
  return e == ".cpp" || e == ".hpp" || e == ".cu" || e == ".cuh" || e == ".h";
}

}  // namespace

TEST(Layout, RoomsIncludeOnlyRoomsBelowThem) {
  const fs::path root = YARNHOM_SOURCE_DIR;
  const std::regex include_re("#include \"([^\"]+)\"");
  int files = 0;
  for (size_t r = 0; r < kRooms.size(); ++r) {
    ASSERT_TRUE(fs::is_directory(root / kRooms[r])) << kRooms[r];
    for (const auto& e : fs::recursive_directory_iterator(root / kRooms[r])) {
      if (!e.is_regular_file() || !is_source(e.path())) continue;
      const std::string rel = fs::relative(e.path(), root).generic_string();
      if (room_of(rel) != int(r)) continue;  // a nested room is checked as itself
      ++files;
      std::ifstream in(e.path());
      std::string line;
      while (std::getline(in, line)) {
        std::smatch m;
        if (!std::regex_search(line, m, include_re)) continue;
        const int inc = room_of(m[1].str());
        if (inc >= 0) EXPECT_LE(inc, int(r)) << rel << " includes " << m[1].str() << ", a room above " << kRooms[r];
      }
    }
  }
  EXPECT_GT(files, 200);
}

TEST(Layout, NoSourceFileOverSixHundredLines) {
  const fs::path root = YARNHOM_SOURCE_DIR;
  std::vector<std::string> dirs = kRooms;
  dirs.push_back("tests");
  for (const std::string& d : dirs)
    for (const auto& e : fs::recursive_directory_iterator(root / d)) {
      if (!e.is_regular_file() || !is_source(e.path())) continue;
      std::ifstream in(e.path());
      const auto lines = std::count(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>(), '\n');
      EXPECT_LE(lines, 600) << fs::relative(e.path(), root).generic_string();
    }
}
