// Every command line of the README's command table, read from README.md itself (issue 37: every
// README example runs as written): each option it names is one its command's --help lists, and
// the quick ones run, in the table's order, on small files (synth's dataset, one epoch of
// training, a 3 x 3 drape of 2 frames): rve, synth, train-all, train, eval, bake, error, sim, the
// Python example (when the module is built), export-hylc, fit-splines. The slow ones (pipeline,
// produce, plot, accuracy, study, strip) are checked through --help only; scripts/demo.sh runs
// the pipeline itself.
#include <gtest/gtest.h>
#include <unistd.h>

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
