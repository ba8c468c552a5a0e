#include "pipeline/plot_run.hpp"

#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "bake/bake_table.hpp"
#include "core/baked.hpp"
#include "core/console.hpp"
#include "core/dataset.hpp"
#include "core/file_checks.hpp"
#include "core/model.hpp"
#include "pipeline/child_process.hpp"
#include "pipeline/plot_data.hpp"
#include "pipeline/python_env.hpp"

namespace yarnhom::pipeline {

namespace fs = std::filesystem;

namespace {

// The run's files: as given, else RUN_DIR/name when it exists, else "".
std::string pick(const fs::path& run, const std::string& given, const char* name) {
  if (!given.empty()) {
    if (!fs::exists(given)) throw std::invalid_argument(given + ": no such file");
    return given;
  }
  const fs::path p = run / name;
  return fs::exists(p) ? p.string() : std::string();
}

// plotdata.h5 in `out`: the numbers of every picture.
std::string write_numbers(const PlotOptions& o, const fs::path& out) {
  const fs::path run(o.run);
  const std::string mp = pick(run, o.model, "model.h5"), bp = pick(run, o.baked, "baked.h5"), dp = pick(run, o.data, "dataset.h5");
  std::optional<Model> model;
  std::optional<BakedModel> baked;
  std::optional<Dataset> ds;
  if (!mp.empty()) model = read_model(mp);
  if (!bp.empty()) baked = read_baked(bp);
  if (!dp.empty()) ds = read_dataset(dp);
  if (!baked && model) {
    std::fprintf(stderr, "yarnhom plot: no baked file; baking the model in memory (200 / 100x100)\n");
    baked = bake_model(*model, mp, 200, 100, 0, false);
  }
  if (!baked) throw std::invalid_argument(o.run + ": neither model.h5 nor baked.h5 found (give --model or --baked)");
  fs::create_directories(out);
  const std::string data = (out / "plotdata.h5").string();
  prepare_output(data, {mp, bp, dp}, o.out.empty() ? "RUN_DIR/plots" : "-o");
  write_plot_data(data, model, *baked, ds);
  return data;
}

}  // namespace

int run_plot(const PlotOptions& o) {
  const fs::path out = o.out.empty() ? fs::path(o.run) / "plots" : fs::path(o.out);
  check_output_folder(out.string(), o.out.empty() ? "RUN_DIR/plots" : "-o");
  const std::string data = write_numbers(o, out);
  const std::string py = find_python();
  if (py.empty()) {
    std::fprintf(stderr,
                 "yarnhom plot: no python3 with matplotlib, h5py and numpy was found (tried "
                 "$YARNHOM_PYTHON, /usr/bin/python3, python3); the numbers are in %s. Install "
                 "python3-matplotlib python3-h5py (Debian) or set YARNHOM_PYTHON.\n",
                 data.c_str());
    return 2;
  }
  const std::string script = (fs::path(scripts_dir()) / "plot" / "plot_run.py").string();
  if (!fs::exists(script)) throw std::invalid_argument(script + ": plot script not found (set YARNHOM_SCRIPTS to the scripts folder)");
  // A child that dies with this process (pipeline/child_process.hpp), so that a killed plot or
  // pipeline leaves no python behind.
  const int rc = run_child({py, script, data, out.string()});
  if (rc != 0) {
    std::fprintf(stderr, "yarnhom plot: the plot script failed (%s %s %s %s)\n", py.c_str(), script.c_str(), data.c_str(),
                 out.string().c_str());
    return 1;
  }
  return 0;
}

}  // namespace yarnhom::pipeline
