// Parts F and G of the hardening campaign (issue 32). F: output rules of the new commands (-o
// naming a file, a FIFO, /dev/null or a place under /proc; inputs as outputs; a failed run keeps
// the previous output; a rerun removes what an earlier, longer run wrote). G: sim, strip and
// accuracy killed (SIGKILL to the whole process group) at random moments and rerun: the rerun
// must restart (sim) or resume (strip, accuracy) cleanly to the uninterrupted run's result.
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "tools/campaign/campaign_parts.hpp"
#include "tools/campaign/campaign_util.hpp"

namespace campaign {

namespace {

// A CSV text without the columns whose header ends in "seconds" (timings).
std::string without_timings(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, out;
  std::vector<bool> keep;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    if (keep.empty())
      for (const auto& c : cells) keep.push_back(!(c.size() >= 7 && c.compare(c.size() - 7, 7, "seconds") == 0));
    for (size_t i = 0; i < cells.size(); ++i)
      if (i >= keep.size() || keep[i]) out += cells[i] + ",";
    out += "\n";
  }
  return out;
}

int count_files(const fs::path& dir) {
  int n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    n += it->is_regular_file();
  return n;
}

}  // namespace

void part_f_outputs(const fs::path& work, const NewPartsOptions& opt) {
  const fs::path dir = fresh_model_dir(work / "new_outputs");
  auto p = [&](const std::string& f) { return (dir / f).string(); };
  run(cmd({"bake", p("m.h5"), "-o", p("b.h5"), "--res1d", "20", "--res2d", "8"}));
  const std::string B = p("b.h5"), D = p("d.h5"), pat = opt.check_pattern, tiny = opt.strip_pattern;
  Tally t;
  std::printf("F. outputs of the new commands\n");
  // F1. Output folders that are a file, a FIFO, /dev/null, under /proc, under a file.
  std::ofstream(p("file")) << "x";
  ::mkfifo(p("fifo").c_str(), 0644);
  const std::vector<std::string> targets = {p("file"), p("fifo"), "/dev/null", "/proc/yarnhom_campaign", "/proc/self/yarnhom",
                                            p("file/out")};
  const std::vector<std::vector<std::string>> folder_cmds = {
      {"sim", "hang", "-q", "--frames", "1", "--resolution", "2", "--render", "none", "--density", "0.3", "--material", B},
      {"sim", "stretch", "-q", "--resolution", "2", "--stretch", "1.0:1.05:0.05", "--density", "0.3", "--material", B},
      {"strip", pat, "--no-plots"},
      {"accuracy", pat, "--direction", "wale"},
      {"study", "table5", pat},
      {"study", "strip-width", pat},
      {"study", "bake-resolution", pat},
      {"study", "rve-size", pat},
      {"study", "architectures", D},
      {"pipeline", "synthetic", "--epochs", "1"}};
  auto state = [&](const std::string& target) {
    if (target == p("file")) return std::string(file_type(target) == S_IFREG ? "reg:" : "other:") + slurp(target);
    if (target == p("fifo")) return std::string(file_type(target) == S_IFIFO ? "fifo" : "changed");
    if (target == "/dev/null") return std::string(file_type(target) == S_IFCHR ? "chr" : "changed");
    return std::string(fs::exists(target) ? "exists" : "absent");
  };
  auto outcome = [&](const std::vector<std::string>& args, const std::string& target, const std::string& before) {
    const Run r = run(args, 120);
    const std::string v = judge(args, r, true, {target, "-o"}, t);
    if (state(target) != before) {
      ++t.clobbered;
      std::printf("            CLOBBERED: %s\n", target.c_str());
    }
    (void)v;
  };
  for (const auto& c : folder_cmds)
    for (const std::string& target : targets) {
      std::vector<std::string> args = {g_bin};
      args.insert(args.end(), c.begin(), c.end());
      args.insert(args.end(), {"-o", target});
      outcome(args, target, state(target));
    }
  // F2. File outputs: export-hylc and fit-splines to a FIFO, /dev/null, a folder, their own input.
  fs::create_directories(p("folder"));
  fs::create_hard_link(B, p("b_hard.h5"));
  fs::create_symlink(B, p("b_soft.h5"));
  fs::create_hard_link(D, p("d_hard.h5"));
  fs::create_symlink(D, p("d_soft.h5"));
  const std::string b0 = slurp(B), d0 = slurp(D);
  for (const std::string& target : {p("fifo"), std::string("/dev/null"), p("folder"), std::string("/proc/yarnhom_campaign.json")}) {
    outcome(cmd({"export-hylc", B, "--density", "0.3", "-o", target}), target, state(target));
    outcome(cmd({"fit-splines", D, "-o", target}), target, state(target));
  }
  for (const std::string& target : {B, p("b_hard.h5"), p("b_soft.h5")}) {
    const auto args = cmd({"export-hylc", B, "--density", "0.3", "-o", target});
    judge(args, run(args, 60), true, {target, B}, t);
    if (slurp(B) != b0) ++t.clobbered, std::printf("            CLOBBERED: %s\n", B.c_str());
  }
  for (const std::string& target : {D, p("d_hard.h5"), p("d_soft.h5")}) {
    const auto args = cmd({"fit-splines", D, "-o", target});
    judge(args, run(args, 120), true, {target, D}, t);
    if (slurp(D) != d0) ++t.clobbered, std::printf("            CLOBBERED: %s\n", D.c_str());
  }
  // F3. A failed run keeps the previous output.
  run(cmd({"export-hylc", B, "--density", "0.3", "-o", p("prev.json")}));
  run(cmd({"fit-splines", D, "-o", p("prev_s.h5")}), 120);
  run(cmd({"train-all", D, "-o", p("prev_m.h5"), "--epochs", "2", "--terms", "0,02", "-q"}), 120);
  {
    std::string bad = b0;
    for (size_t i = bad.size() / 2; i < bad.size() / 2 + 64 && i < bad.size(); ++i) bad[i] = char(0xff);
    std::ofstream(p("b_bad.h5"), std::ios::binary) << bad.substr(0, bad.size() * 3 / 4);
    std::string badd = d0;
    std::ofstream(p("d_bad.h5"), std::ios::binary) << badd.substr(0, badd.size() / 2);
  }
  struct Keep {
    std::vector<std::string> args;
    std::string file;
  };
  for (const Keep& k : std::vector<Keep>{
           {cmd({"export-hylc", p("b_bad.h5"), "--density", "0.3", "-o", p("prev.json")}), p("prev.json")},
           {cmd({"export-hylc", B, "--density", "nan", "-o", p("prev.json")}), p("prev.json")},
           {cmd({"fit-splines", p("d_bad.h5"), "-o", p("prev_s.h5")}), p("prev_s.h5")},
           {cmd({"train-all", D, "-o", p("prev_m.h5"), "--epochs", "5", "--polish", "0", "--terms", "0", "--lr", "1e30", "-q"}), p("prev_m.h5")}}) {
    const std::string before = slurp(k.file);
    const Run r = run(k.args, 120);
    judge(k.args, r, true, {}, t);
    if (slurp(k.file) != before) ++t.clobbered, std::printf("            CLOBBERED: %s\n", k.file.c_str());
  }
  // F4. Stale outputs: a shorter sim rerun, a refused rerun, a shorter strip rerun.
  const std::string S = p("simrun");
  auto hang = [&](const std::string& frames, const std::string& dt) {
    return cmd({"sim", "hang", "-q", "--resolution", "3", "--render", "none", "--density", "0.3", "--threads", "1",
                "--material", B, "--frames", frames, "--dt", dt, "-o", S});
  };
  auto stale = [&](const std::string& what, bool ok) {
    ++t.cases;
    if (!ok) ++t.clobbered;
    std::printf("   %-70s %s\n", what.c_str(), ok ? "clean" : "STALE OR CLOBBERED");
  };
  run(hang("12", "0.0333"), 120);
  const int frames12 = count_files(S + "/frames");
  Run r = run(hang("4", "0.0333"), 120);
  stale("sim hang --frames 12, then --frames 4 into its folder: 5 frames left (had " + std::to_string(frames12) + ")",
        r.status == 0 && count_files(S + "/frames") == 5 && !fs::exists(S + "/frames/frame_0005.obj"));
  const std::string f4 = slurp(S + "/frames/frame_0004.obj");
  r = run(hang("4", "-1"), 60);
  stale("a refused rerun (--dt -1) leaves the earlier run's frames", r.status != 0 && slurp(S + "/frames/frame_0004.obj") == f4);
  std::ofstream(S + "/frames/frame_0002.obj.partial-999999") << "x";
  r = run(hang("4", "0.0333"), 120);
  stale("a rerun removes a dead process's frame temporary", r.status == 0 && count_partials(S) == 0);
  const std::string R = p("striprun");
  const std::string sargs = " --direction wale --size 0.0035,0.0027 --clamp 0.0009 --no-plots --threads 1 -o " + R;
  r = run(split_cmd("strip " + tiny + sargs + " --stretch 1.0:1.15:0.05"), 300);
  const bool had = fs::exists(R + "/centrelines/step_003.obj");
  r = run(split_cmd("strip " + tiny + sargs + " --stretch 1.0:1.05:0.05"), 300);
  stale("strip 1.0:1.15, then 1.0:1.05 into its folder: later steps removed",
        had && r.status == 0 && !fs::exists(R + "/centrelines/step_002.obj") && !fs::exists(R + "/steps/step_003.h5"));
  r = run(split_cmd("strip " + tiny + sargs + " --stretch 1.0:1.05:0.05 --clamp 0.001"), 60);
  stale("strip rerun with other settings refused, folder kept", r.status != 0 && fs::exists(R + "/centrelines/step_001.obj"));
  t.print("F. result");
  std::printf("\n");
}

void part_g_kills(const fs::path& work, const NewPartsOptions& opt, std::mt19937_64& rng) {
  const fs::path dir = fresh_model_dir(work / "new_kills");
  auto p = [&](const std::string& f) { return (dir / f).string(); };
  run(cmd({"bake", p("m.h5"), "-o", p("b.h5"), "--res1d", "20", "--res2d", "8"}));
  const std::string B = p("b.h5"), pat = opt.strip_pattern;
  run(cmd({"produce", pat, "--preset", "tiny", "--threads", "2", "-o", p("ds.h5")}), 600);
  struct Target {
    std::string name;
    std::function<std::vector<std::string>(const std::string&)> args;
    std::function<std::string(const std::string&)> result;  // what must equal the uninterrupted run's
    int kills;
  };
  const std::vector<Target> targets = {
      {"sim hang (restarts)",
       [&](const std::string& o) {
         return cmd({"sim", "hang", "-q", "--resolution", "20", "--frames", "60", "--render", "none", "--threads", "1",
                     "--density", "0.3", "--material", B, "-o", o});
       },
       [](const std::string& o) {
         return slurp(o + "/frames/frame_0060.obj") + std::to_string(count_files(o + "/frames")) + " frames";
       },
       opt.sim_kills},
      {"strip (resumes)",
       [&](const std::string& o) {
         return split_cmd("strip " + pat + " --direction wale --size 0.0035,0.0027 --clamp 0.0009 --no-plots --threads 1 "
                          "--stretch 1.0:1.15:0.05 -o " + o);
       },
       [](const std::string& o) {
         return without_timings(slurp(o + "/force.csv")) + std::to_string(count_files(o + "/centrelines")) + " centrelines";
       },
       opt.strip_kills},
      {"accuracy (resumes its stages)",
       [&](const std::string& o) {
         return split_cmd("accuracy " + pat + " --direction wale --dataset " + p("ds.h5") +
                          " --size 0.0035,0.0027 --epochs 20 --threads 2 --strip-args '--clamp 0.0009 --threads 1 "
                          "--no-plots' --sim-args '--resolution 4 --threads 1' -o " + o);
       },
       [](const std::string& o) { return slurp(o + "/accuracy.csv"); },
       opt.accuracy_kills}};
  int wrong = 0, failed = 0, total = 0, left_partials = 0;
  std::printf("G. kills of sim, strip and accuracy, each rerun to completion\n");
  for (const Target& tg : targets) {
    const std::string ref = p("ref");
    fs::remove_all(ref);
    Run r = run(tg.args(ref), 900);
    if (r.status != 0) {
      std::printf("   %s: the uninterrupted run failed (status %d): %s\n", tg.name.c_str(), r.status, r.out.substr(0, 400).c_str());
      ++failed;
      continue;
    }
    const double T = r.seconds;
    const std::string expect = tg.result(ref);
    std::printf("   %s: uninterrupted run %.1f s; %d kills at uniform random moments of it\n", tg.name.c_str(), T, tg.kills);
    std::uniform_real_distribution<double> when(0.03, 1.0);
    for (int k = 0; k < tg.kills; ++k, ++total) {
      const std::string o = p("run");
      fs::remove_all(o);
      const double at = when(rng) * T;
      const pid_t pid = spawn(tg.args(o), p("kill.log"));
      const auto t0 = Clock::now();
      int st = 0;
      bool exited = false;
      while (since(t0) < at) {
        if (::waitpid(pid, &st, WNOHANG) == pid) {
          exited = true;
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
      if (!exited) ::kill(-pid, SIGKILL), ::waitpid(pid, &st, 0);
      const int partials = count_partials(o);
      r = run(tg.args(o), 900);
      const int after = count_partials(o);
      left_partials += after;
      std::string verdict;
      if (r.timed_out || r.status >= 128) verdict = "RERUN HUNG OR CRASHED", ++failed;
      else if (r.status != 0) verdict = "RERUN FAILED: " + r.out.substr(0, 300), ++failed;
      else if (tg.result(o) != expect) verdict = "DIFFERENT from the uninterrupted run", ++wrong;
      else verdict = "identical";
      if (after) verdict += ", " + std::to_string(after) + " temporaries left";
      const bool resumed = r.out.find("kept") != std::string::npos || r.out.find("resum") != std::string::npos ||
                           r.out.find("cached") != std::string::npos || r.out.find("skip") != std::string::npos;
      std::printf("   kill %d at %5.1f s%s (%d temporaries)%s: %s\n", k, at, exited ? " (had finished)" : "", partials,
                  resumed ? ", rerun resumed" : "", verdict.c_str());
      std::fflush(stdout);
    }
  }
  std::printf("G. result: %d wrong results and %d failed reruns of %d kills; %d temporaries left after the reruns\n\n", wrong,
              failed, total, left_partials);
}

}  // namespace campaign
