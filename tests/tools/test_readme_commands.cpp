// Every command line of the README's command table, read from README.md itself (issue 37: every
// README example runs as written): each option it names is one its command's --help lists, and
// the quick ones run, in the table's order, on small files (synth's dataset, one epoch of
// training, a 3 x 3 drape of 2 frames): rve, synth, train-all, train, eval, bake, error, sim, the
// Python example (when the module is built), export-hylc, fit-splines.
//
// The slow ones run in a second test (TheSlowOnesRunAtReducedSizes, so that ctest runs it beside
// the first), each README line as written with options appended that only shrink the work, on the
// built-in stockinette (PATTERN; needs nothing from ../shared; plain is no cheaper: its quick
// dataset took 38 s of CPU here against the stockinette's 24 s): pipeline --preset tiny
// (produce's 5 / 3 x 3 points; the preset was added to pipeline for this) --epochs 1 --no-plot;
// produce --preset tiny --terms 0,02; plot on the pipeline's RUN; accuracy, study strip-width and
// study architectures (1 epoch) on the pipeline's dataset and baked file; study table5 on one
// pattern and direction, study rve-size with one patch size (--tiles 1) and study
// bake-resolution with its reference row baked at 150 / 50x50 (--reference-res1d/-res2d, added
// for this: the fixed 2000 / 400x400 bake alone took 55 s of a 173 s run here), at the tiny
// preset and 1 epoch; every strip 1 x 1 cm stretched in one step (a 2 mm clamp band: the default
// 5 mm covers it), against a 4 x 4 continuum strip. The strip line's own --size and --stretch
// values are replaced (0.01,0.01 and 1.0:1.05:0.05): an option given twice is an error. Each must
// exit 0 and write its main output file. Measured (2-core machine at load 0.5-1.4): 85.4 s wall,
// 76.5 s user + 21.6 s system; bake-resolution 19.2 s, table5 18.0, plot 14.1, rve-size 13.1,
// pipeline 11.4, accuracy 5.0, strip-width 2.9, produce 1.1, strip 0.5, architectures 0.1.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/common/run_cli.hpp"

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The first cell of each command-table row: "yarnhom ..." or "python3 ...", "\|" unescaped.
std::vector<std::string> readme_commands() {
  std::vector<std::string> out;
  std::istringstream in(slurp(fs::path(YARNHOM_SOURCE_DIR) / "README.md"));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("| `yarnhom ", 0) != 0 && line.rfind("| `python3 ", 0) != 0) continue;
    std::string cmd = line.substr(3, line.find('`', 3) - 3);
    for (size_t k; (k = cmd.find("\\|")) != std::string::npos;) cmd.replace(k, 2, "|");
    out.push_back(cmd);
  }
  return out;
}

// Optional parts "[...]" dropped, alternatives "a|b" reduced to the first, "..." dropped.
std::string runnable(std::string c) {
  c = std::regex_replace(c, std::regex(R"( \[[^\]]*\])"), "");
  c = std::regex_replace(c, std::regex(R"(([^ |]+)(\|[^ ]+)+)"), "$1");
  c = std::regex_replace(c, std::regex(R"( \.\.\.)"), "");
  return c;
}

}  // namespace

TEST(ReadmeCommands, EveryOptionIsKnownAndTheQuickOnesRun) {
  const std::vector<std::string> cmds = readme_commands();
  ASSERT_GE(cmds.size(), 15u) << "the README's command table was not found";
  const fs::path dir = fs::temp_directory_path() / ("yarnhom_readme_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string d = dir.string() + "/";
  // The placeholders of the table, as files of this run.
  const std::map<std::string, std::string> files = {{"D.h5", d + "D.h5"},     {"M.h5", d + "M.h5"},
                                                    {"B.h5", d + "B.h5"},     {"OUT", d + "OUT"},
                                                    {"MATERIAL.json", d + "MATERIAL.json"},
                                                    {"PATTERN", "stockinette"},  // the built-in one
                                                    {"sx,sa,sy,IIx,IIa,IIy", "0.1,0,0,0,0,0"}};
  // What makes a quick command small here (appended to the README's line).
  const std::map<std::string, std::string> small = {
      {"rve", ""},  // one RVE solve of the built-in stockinette (about a second)
      {"synth", " --preset quick"},
      {"train-all", " --recipe paper --epochs 1 --threads 1 -q"},
      {"train", " --recipe paper --epochs 1"},
      {"sim", " --density 0.3 --frames 2 --resolution 3 --render none --threads 1 -q"},
      {"export-hylc", " --density 0.3"},  // synth's data carry no areal density, produce's do
      {"eval", ""}, {"bake", ""}, {"error", ""}, {"fit-splines", ""}};
  int ran = 0;
  for (const std::string& full : cmds) {
    SCOPED_TRACE(full);
    std::string c = runnable(full);
    std::istringstream ws(c);
    std::vector<std::string> w;
    for (std::string t; ws >> t;) w.push_back(t);
    if (w[0] == "python3") {  // the module's example: where the module is built
      const fs::path mod = fs::path(YARNHOM_BINARY).parent_path().parent_path() / "python";
      bool built = false;
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(mod, ec))
        built |= e.path().filename().string().rfind("yarnhom.", 0) == 0;
      const std::string py = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
      if (!built || yarnhom::test::run_shell(py + " -c 'import numpy, matplotlib'").status != 0) continue;
      std::string line = py + " " + std::string(YARNHOM_SOURCE_DIR) + "/" + w[1] + " " + files.at(w[2]) + " -o " + d +
                         "ss.png --module-dir " + mod.string();
      const auto r = yarnhom::test::run_shell(line);
      EXPECT_EQ(r.status, 0) << line << "\n" << r.out;
      ++ran;
      continue;
    }
    ASSERT_EQ(w[0], "yarnhom");
    // Every option the line names is one the command takes.
    std::string sub = w[1];
    if (sub == "study" && w.size() > 2 && w[2][0] != '-' && w[2] == w[2].substr(0, w[2].find('.'))) sub += " " + w[2];
    const auto help = yarnhom::test::run_cli(sub + " --help");
    EXPECT_EQ(help.status, 0) << sub << " --help:\n" << help.out;
    static const std::regex option_re(R"(--[a-z0-9-]+)");
    for (auto m = std::sregex_iterator(full.begin(), full.end(), option_re); m != std::sregex_iterator(); ++m) {
      const std::string opt = m->str();
      EXPECT_NE(help.out.find(opt), std::string::npos) << "`yarnhom " << sub << " --help` does not list " << opt;
    }
    const auto it = small.find(w[1]);
    if (it == small.end()) continue;  // slow: --help only
    std::string line;
    for (size_t k = 1; k < w.size(); ++k) {
      std::string t = w[k];
      if (w[1] == "train" && t == "M.h5") t = "M_one.h5";  // not over train-all's model
      line += " " + (files.count(t) ? files.at(t) : (t == "M_one.h5" ? d + t : t));
    }
    line += it->second;
    const auto r = yarnhom::test::run_cli(line);
    EXPECT_EQ(r.status, 0) << "yarnhom" << line << "\n" << r.out;
    ++ran;
  }
  EXPECT_GE(ran, 10);
  fs::remove_all(dir);
}

// The command table's slow lines (pipeline, produce, plot, accuracy, study, strip), each run as
// written with options that only shrink the work appended (header of this file).
TEST(ReadmeCommands, TheSlowOnesRunAtReducedSizes) {
  const std::vector<std::string> cmds = readme_commands();
  ASSERT_GE(cmds.size(), 15u) << "the README's command table was not found";
  const fs::path dir = fs::temp_directory_path() / ("yarnhom_readme_slow_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string d = dir.string() + "/";
  // A 1 x 1 cm stockinette strip (a 2 mm clamp band), stretched once, against a 4 x 4 continuum strip.
  const std::string strip_args = " --strip-args '--clamp 0.002 --threads 1 --no-plots' --sim-args '--resolution 4'";
  const std::string tiny_test = " --preset tiny --size 0.01,0.01 --stretch 1.0:1.05:0.05 --epochs 1 --threads 1" + strip_args;
  const std::string reuse = " --dataset " + d + "RUN/dataset.h5 --baked " + d + "RUN/baked.h5";
  struct Small {
    std::string append;                           // options appended to the README's line
    std::map<std::string, std::string> replace;   // values of the line's own options replaced
    std::vector<std::string> outputs;             // the main output files, relative to the run's folder
  };
  // The key: the command, or "study NAME"; the placeholders: PATTERN the built-in stockinette,
  // RUN, D.h5 and DIR files of this run (DIR one per command), D a direction.
  const std::map<std::string, Small> small = {
      {"pipeline", {" --preset tiny --epochs 1 --threads 1 --no-plot", {}, {"RUN/dataset.h5", "RUN/baked.h5", "RUN/errors.txt"}}},
      {"produce", {" --preset tiny --terms 0,02 --threads 1", {}, {"D.h5"}}},
      {"plot", {"", {}, {"RUN/plots/plotdata.h5"}}},
      {"accuracy", {reuse + " --size 0.01,0.01 --stretch 1.0:1.05:0.05 --threads 1" + strip_args, {},
                    {"DIR_accuracy/accuracy.md", "DIR_accuracy/accuracy.csv"}}},
      {"study table5", {" stockinette --directions course -o " + d + "DIR_table5" + tiny_test, {}, {"DIR_table5/table5.md"}}},
      {"study bake-resolution", {" stockinette --direction course -o " + d + "DIR_bake" + tiny_test +
                                     " --reference-res1d 150 --reference-res2d 50", {}, {"DIR_bake/table4.md"}}},
      {"study rve-size",
       {" stockinette --tiles 1 --direction course -o " + d + "DIR_rve" + tiny_test, {}, {"DIR_rve/table2.md"}}},
      {"study architectures",
       {" " + d + "RUN/dataset.h5 --term 0 --epochs 1 --no-plot -o " + d + "DIR_arch", {}, {"DIR_arch/architectures.csv"}}},
      {"study strip-width",
       {reuse + " --widths 0.01 --length 0.01 --stretch 1.0:1.05:0.05 --threads 1 --no-plot" + strip_args, {},
        {"DIR_study_strip-width/width.md"}}},
      {"strip", {" --clamp 0.002 --threads 1 --no-plots", {{"--size", "0.01,0.01"}, {"--stretch", "1.0:1.05:0.05"}},
                 {"DIR_strip/force.csv"}}},
  };
  std::vector<std::string> done;
  for (const std::string& full : cmds) {
    SCOPED_TRACE(full);
    std::istringstream ws(runnable(full));
    std::vector<std::string> w;
    for (std::string t; ws >> t;) w.push_back(t);
    if (w[0] != "yarnhom") continue;  // the Python example: the other test
    // The lines to run: "study a|b|c ..." is one line per study it names.
    std::istringstream rs(full);
    std::vector<std::string> raw;
    for (std::string t; rs >> t;) raw.push_back(t);
    std::vector<std::string> keys;
    if (w[1] == "study" && raw[2].find('|') != std::string::npos) {
      std::istringstream names(raw[2]);
      for (std::string n; std::getline(names, n, '|');) keys.push_back("study " + n);
    } else {
      keys.push_back(w[1] == "study" ? "study " + w[2] : w[1]);
    }
    for (const std::string& key : keys) {
      const auto it = small.find(key);
      if (it == small.end()) {
        // Not a slow command: only the quick ones, which the other test runs, may be missing here.
        EXPECT_TRUE(key.rfind("study", 0) != 0 && key != "strip" && key != "accuracy" && key != "produce" &&
                    key != "pipeline" && key != "plot")
            << key << ": a slow README command with no reduced form in this test";
        continue;
      }
      std::string folder = "DIR_" + key;
      std::replace(folder.begin(), folder.end(), ' ', '_');
      const std::map<std::string, std::string> files = {
          {"PATTERN", "stockinette"}, {"RUN", d + "RUN"}, {"D.h5", d + "D.h5"}, {"DIR", d + folder}, {"D", "course"}};
      std::vector<std::string> words(w.begin() + 1, w.end());
      if (keys.size() > 1) words = {"study", key.substr(6)};  // "study a|b ...": the study's own arguments appended
      std::string line;
      for (size_t k = 0; k < words.size(); ++k) {
        std::string t = words[k];
        if (k > 0 && it->second.replace.count(words[k - 1])) t = it->second.replace.at(words[k - 1]);
        line += " " + (files.count(t) ? files.at(t) : t);
      }
      line += it->second.append;
      const auto t0 = std::chrono::steady_clock::now();
      const auto r = yarnhom::test::run_cli(line);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf("[ README   ] %-22s %6.1f s: yarnhom%s\n", key.c_str(), s, line.c_str());
      EXPECT_EQ(r.status, 0) << "yarnhom" << line << "\n" << r.out;
      for (const std::string& f : it->second.outputs) EXPECT_TRUE(fs::exists(d + f)) << key << ": no " << f << "\n" << r.out;
      done.push_back(key);
    }
  }
  for (const auto& [key, s] : small)
    EXPECT_NE(std::find(done.begin(), done.end(), key), done.end()) << key << " is no longer in the README's table";
  fs::remove_all(dir);
}
