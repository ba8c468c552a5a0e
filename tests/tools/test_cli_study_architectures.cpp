// `yarnhom study architectures` (supplement Table 3): each row trains the architecture it names,
// whatever the recipe gives the 2D terms (the default recipe's Net-2 must not replace them).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "tests/common/run_cli.hpp"

namespace fs = std::filesystem;

TEST(CliStudyArchitectures, EveryRowTrainsItsOwnNetworkOnA2DTermUnderTheDefaultRecipe) {
  const fs::path d = fs::temp_directory_path() / ("yarnhom_sa_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  ASSERT_EQ(yarnhom::test::run_cli("synth --preset quick -o " + (d / "ds.h5").string()).status, 0);
  auto r = yarnhom::test::run_cli("study architectures " + (d / "ds.h5").string() +
                                  " --term 01 --epochs 2 --recipe default --no-plot -o " + (d / "out").string());
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in(d / "out" / "architectures.csv");
  ASSERT_TRUE(in) << r.out;
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("net,hidden,weights,val_loss,", 0), 0u) << line;
  // Same seed, split and recipe: four different networks give four different losses; had every
  // row trained the recipe's [32,32], all four would be equal.
  std::set<std::string> losses;
  int rows = 0;
  while (std::getline(in, line)) {
    ++rows;
    std::stringstream ss(line);
    std::string net, hidden, weights, val;
    std::getline(ss, net, ',');
    std::getline(ss, hidden, '"');  // the opening quote
    std::getline(ss, hidden, '"');
    std::getline(ss, weights, ',');  // the comma after the quote
    std::getline(ss, weights, ',');
    std::getline(ss, val, ',');
    losses.insert(val);
    EXPECT_EQ(line.substr(line.size() - 2), "ok") << line;
  }
  EXPECT_EQ(rows, 4);
  EXPECT_EQ(losses.size(), 4u);
  fs::remove_all(d);
}
