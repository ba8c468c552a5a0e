// The plot data: every group the script draws, sectors 0..8 all present around a 2D box, finite
// numbers; and, where a python3 with matplotlib and h5py exists, the script's PNGs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "bake/bake_table.hpp"
#include "pipeline/plot_data.hpp"
#include "core/h5.hpp"
#include "tests/common/bake_test_util.hpp"

using namespace yarnhom;
namespace fs = std::filesystem;

namespace {

std::string python_with_matplotlib() {
  for (const char* c : {"/usr/bin/python3", "python3"}) {
    const std::string cmd = std::string(c) + " -c 'import matplotlib, h5py, numpy' >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) return c;
  }
  return "";
}

}  // namespace

TEST(PlotData, WritesWhatTheScriptDrawsAndTheScriptRuns) {
  const fs::path dir = fs::temp_directory_path() / ("yarnhom_plot_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Model model;
  model.networks.push_back(test::random_model_network("0", {-0.2}, {1.0}, 81));
  model.networks.push_back(test::random_model_network("03", {-0.2, -200.0}, {1.0, 200.0}, 82));
  for (ModelNetwork& n : model.networks)
    for (int e = 0; e < 20; ++e) {
      n.history.train_loss.push_back(1.0 / (e + 1));
      n.history.val_loss.push_back(1.2 / (e + 1));
      n.history.lr.push_back(e < 10 ? 1e-3 : 5e-4);
    }
  // The L-BFGS polish after the epochs: drawn on its own x-axis segment.
  model.networks[1].history.polish_train = {0.05, 0.01, 0.002};
  model.networks[1].history.polish_val = {0.06, 0.02, 0.004};
  model.networks[1].val_index = {1, 3};
  Dataset ds;
  TermData td;
  td.term = term_by_name("0");
  td.n = 3;
  td.strain = {-0.1, 0.4, 0.9};
  td.energy = {0.0, 0.1, 0.5};
  td.gradient = {0.5, 0.6, 1.0};
  ds.terms.push_back(td);
  TermData t2;  // the 2D term's data: drawn on its surface
  t2.term = term_by_name("03");
  t2.n = 4;
  t2.strain = {-0.1, -100.0, 0.5, -100.0, -0.1, 100.0, 0.5, 100.0};
  t2.energy = {0.01, -0.02, 0.0, 0.03};
  t2.gradient = {0.1, 1e-4, 0.2, 1e-4, 0.1, 2e-4, 0.3, 1e-4};
  ds.terms.push_back(t2);
  const BakedModel baked = bake_model(model, "model.h5", 50, 20, 0, false);
  const std::string path = (dir / "plotdata.h5").string();
  write_plot_data(path, model, baked, ds);

  h5::Node root = h5::open_file(path);
  EXPECT_EQ(root.attr_string("format"), "yarnhom-plotdata");
  EXPECT_EQ(root.group("history").group("03").read_double("lr").data.size(), 20u);
  auto sec = root.group("surface").group("03").read_double("sector");
  int seen[9] = {};
  for (double s : sec.data) {
    ASSERT_GE(s, 0);
    ASSERT_LE(s, 8);
    seen[int(s)]++;
  }
  for (int k = 0; k < 9; ++k) EXPECT_GT(seen[k], 0) << "sector " << k;
  for (double v : root.group("surface").group("03").read_double("d3").data) ASSERT_TRUE(std::isfinite(v));
  for (double v : root.group("convexity").group("03").read_double("lam_min").data) ASSERT_TRUE(std::isfinite(v));
  EXPECT_EQ(root.group("line").group("0").read_double("data_psi").data.size(), 3u);
  EXPECT_EQ(root.group("history").group("03").read_double("polish_val_loss").data.size(), 3u);
  EXPECT_FALSE(root.group("history").group("0").has("polish_train_loss"));
  EXPECT_EQ(root.group("surface").group("03").read_double("data_y").data.size(), 4u);
  EXPECT_EQ(root.group("surface").group("03").read_double("data_val").data.size(), 2u);
  EXPECT_TRUE(root.group("surface").group("03").has_attr("verdict"));  // a random network fails
  EXPECT_TRUE(root.group("line").group("0").has_attr("fit_ok"));
  EXPECT_EQ(root.group("convexity").group("03").attr_string("source"), "network");

  const std::string py = python_with_matplotlib();
  if (py.empty()) {
    fs::remove_all(dir);
    GTEST_SKIP() << "no python3 with matplotlib and h5py: the script was not run";
  }
  const std::string script = std::string(YARNHOM_SOURCE_DIR) + "/scripts/plot/plot_run.py";
  const std::string cmd = py + " '" + script + "' '" + path + "' '" + dir.string() + "' >/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  for (const char* png : {"loss_curves.png", "surface_03.png", "convexity.png", "lines_1d.png"}) {
    std::ifstream f(dir / png, std::ios::binary);
    ASSERT_TRUE(f) << png;
    char magic[8] = {};
    f.read(magic, 8);
    EXPECT_EQ(std::string(magic + 1, 3), "PNG") << png;
  }
  fs::remove_all(dir);
}
