// yarnhom study bake-resolution: supplement Table 4 (pipeline/study.hpp).
#include <array>
#include <cstdio>
#include <filesystem>
#include <map>

#include "core/file_checks.hpp"
#include "core/text_file.hpp"
#include "pipeline/rank_tasks.hpp"
#include "pipeline/stage_runner.hpp"
#include "pipeline/study.hpp"
#include "pipeline/study_util.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

namespace {

// Supplement Table 4 (wale): stress difference / Hausdorff for Bake-1, Bake-2, Bake-3, Neural.
const std::map<std::string, std::array<std::array<double, 2>, 4>>& paper_table4() {
  static const std::map<std::string, std::array<std::array<double, 2>, 4>> t = {
      {"basket", {{{0.93, 0.72}, {0.87, 0.69}, {0.87, 0.69}, {0.87, 0.69}}}},
      {"stockinette", {{{4.26, 0.82}, {3.08, 0.78}, {3.04, 0.75}, {3.04, 0.75}}}},
      {"honeycomb", {{{5.32, 1.42}, {3.63, 1.10}, {3.54, 1.10}, {3.54, 1.10}}}},
      {"cartridge", {{{7.39, 0.93}, {6.12, 0.81}, {6.02, 0.74}, {6.02, 0.74}}}},
  };
  return t;
}

struct Bake {
  const char* label;
  int r1, r2;
};

}  // namespace

void run_study_bake_resolution(const BakeResolutionOptions& o) {
  check_output_folder(o.out);
  const fs::path dir(o.out);
  const std::array<Bake, 4> bakes = {
      {{"Bake-1", 100, 25}, {"Bake-2", 150, 50}, {"Bake-3", 200, 100}, {"network", o.reference_res1d, o.reference_res2d}}};
  const std::string name = paper_name(o.pattern);
  AccuracyOptions base = row_test(o.acc, o.pattern, o.direction, dir.string(), "");
  base.strip_dir = (dir / "strip").string();
  base.spline = false;
  std::string md = "# Supplement Table 4, reproduced (" + name + ", " + o.direction +
                   ")\n\nMean stress difference (N/m) / mean Hausdorff distance (cm) against the yarn strip.\n\n"
                   "| bake | 1D knots | 2D knots | ours dN / H | paper dN / H |\n|---|---|---|---|---|\n";
  std::string csv = "bake,knots1d,knots2d,mean_dN,mean_H_cm,mean_rel_pct,paper_dN,paper_H_cm\n";
  // The dataset and the networks once; every bake of them is tested against one yarn strip.
  const std::string model = (dir / "model.h5").string(), ds = (dir / "dataset.h5").string();
  std::vector<std::string> in;
  if (fs::exists(o.pattern)) in.push_back(o.pattern);
  const StageSpec produce = {"produce", produce_stage_args(o.pattern, ds, o.acc.preset, o.acc.threads), in, {ds}};
  const StageSpec train = {"train-all", train_stage_args(ds, model, o.acc.threads, o.acc.epochs), {ds}, {model}};
  auto bake = [&](const Bake& b) {
    const std::string baked = (dir / (std::string(b.label) + ".h5")).string();
    return StageSpec{std::string("bake-") + b.label,
                     {"bake", model, "-o", baked, "--data", ds, "--res1d", std::to_string(b.r1), "--res2d", std::to_string(b.r2)},
                     {model, ds},
                     {baked}};
  };
  auto test = [&](const Bake& b) {
    AccuracyOptions a = base;
    a.baked = (dir / (std::string(b.label) + ".h5")).string();
    a.dataset = ds;
    a.out = (dir / b.label).string();
    return a;
  };
  // On several ranks (pipeline/rank_tasks.hpp): the stages as tasks first, then rank 0 alone.
  const OnRanks ranks(dir, "study bake-resolution", [&](RankTasks& g) {
    // (The tasks run after this lambda returned: no locals of it in them.)
    auto key = [&](const StageSpec& s) { return (dir / ".stages" / s.name).string(); };
    const int p = g.add(key(produce), "produce (" + o.acc.preset + ")", produce_task_weight(o.acc.preset), {},
                        [&dir, &produce, &o] { run_stage(dir, produce, o.acc.force); });
    const int t = g.add(key(train), "train-all", 10, {p}, [&dir, &train, &o] { run_stage(dir, train, o.acc.force); });
    for (const Bake& b : bakes) {
      // Its cost grows with its 2D tables (2000 / 400x400: about 13x Bake-3's time, measured).
      const int k = g.add(key(bake(b)), bake(b).name, 0.2 + 0.5 * (b.r2 / 100.0) * (b.r2 / 100.0), {t}, [&dir, &bake, &o, b] { run_stage(dir, bake(b), o.acc.force); });
      add_accuracy_tasks(g, test(b), b.label, {k});
    }
  });
  if (!ranks.root()) return;
  run_stage(dir, produce, o.acc.force);
  run_stage(dir, train, o.acc.force);
  const auto it = paper_table4().find(name);
  for (size_t k = 0; k < 4; ++k) {
    const Bake& b = bakes[k];
    run_stage(dir, bake(b), o.acc.force);
    const AccuracySummary s = run_accuracy(test(b)).materials[0].summary;
    const std::string paper = it == paper_table4().end() ? "-" : fmt(it->second[k][0]) + " / " + fmt(it->second[k][1]);
    md += std::string("| ") + b.label + " | " + std::to_string(b.r1) + " | " + std::to_string(b.r2) + "x" + std::to_string(b.r2) +
          " | " + summary_md(s, " / ") + " | " + paper + " |\n";
    csv += std::string(b.label) + "," + std::to_string(b.r1) + "," + std::to_string(b.r2) + "," + summary_csv(s) + "," +
           (it == paper_table4().end() ? "," : fmt(it->second[k][0], "%g") + "," + fmt(it->second[k][1], "%g")) + "\n";
    write_text_file((dir / "table4.md").string(), md);
    write_text_file((dir / "table4.csv").string(), csv);
  }
  std::printf("\n%s\n-> %s/table4.md, table4.csv\n", md.c_str(), o.out.c_str());
}

}  // namespace yarnhom::pipeline
