// yarnhom plot RUN_DIR: the pictures of a run (supplement Fig. 1, 3, 4 and 1D fits). The
// numbers are computed by bake/plot_data.hpp with the project's own evaluators and written to
// RUN_DIR/plots/plotdata.h5; tools/plot/plot_run.py only draws them (matplotlib, h5py), so
// that no formula exists twice.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>

#include "bake/bake_table.hpp"
#include "bake/plot_data.hpp"
#include "core/baked.hpp"
#include "core/dataset.hpp"
#include "core/model.hpp"
#include "tools/child_process.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"
#include "tools/python_env.hpp"

namespace yarnhom::tools {

namespace fs = std::filesystem;

void register_plot(CLI::App& app) {
  struct Opts {
    std::string run, model, baked, data, out;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "plot",
      "Draw a run's pictures as PNG files: loss curves with the learning rate (supplement Fig. 1), "
      "each 2D term's surface with the safeguard coloured by sector and the magnitude of its third "
      "derivatives (Fig. 3), the sign of the Hessian's smallest eigenvalue (Fig. 4), and data "
      "against network along each 1D term. Needs a python3 with matplotlib and h5py "
      "($YARNHOM_PYTHON, /usr/bin/python3 or python3 on PATH).");
  cmd->add_option("RUN_DIR", o->run, "Run folder holding model.h5, baked.h5 and dataset.h5 (any may be missing)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--model", o->model, "Model file (default RUN_DIR/model.h5)")->check(existing_regular_file());
  cmd->add_option("--baked", o->baked, "Baked file (default RUN_DIR/baked.h5; baked in memory from the model if absent)")
      ->check(existing_regular_file());
  cmd->add_option("--data", o->data, "Dataset (default RUN_DIR/dataset.h5)")->check(existing_regular_file());
  cmd->add_option("-o,--output", o->out, "Folder for the PNGs (default RUN_DIR/plots)");
  cmd->callback([o] {
    const fs::path run(o->run);
    const fs::path out = o->out.empty() ? run / "plots" : fs::path(o->out);
    check_output_folder(out.string(), o->out.empty() ? "RUN_DIR/plots" : "-o");
    auto pick = [&](const std::string& given, const char* name) {
      if (!given.empty()) {
        if (!fs::exists(given)) throw std::invalid_argument(given + ": no such file");
        return given;
      }
      const fs::path p = run / name;
      return fs::exists(p) ? p.string() : std::string();
    };
    const std::string mp = pick(o->model, "model.h5"), bp = pick(o->baked, "baked.h5"), dp = pick(o->data, "dataset.h5");
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
    if (!baked) throw std::invalid_argument(o->run + ": neither model.h5 nor baked.h5 found (give --model or --baked)");
    fs::create_directories(out);
    const std::string data = (out / "plotdata.h5").string();
    prepare_output(data, {mp, bp, dp}, o->out.empty() ? "RUN_DIR/plots" : "-o");
    write_plot_data(data, model, *baked, ds);
    const std::string py = find_python();
    if (py.empty()) {
      std::fprintf(stderr,
                   "yarnhom plot: no python3 with matplotlib, h5py and numpy was found (tried "
                   "$YARNHOM_PYTHON, /usr/bin/python3, python3); the numbers are in %s. Install "
                   "python3-matplotlib python3-h5py (Debian) or set YARNHOM_PYTHON.\n",
                   data.c_str());
      throw ExitCode{2};
    }
    const std::string script = (fs::path(scripts_dir()) / "plot" / "plot_run.py").string();
    if (!fs::exists(script)) throw std::invalid_argument(script + ": plot script not found (set YARNHOM_SCRIPTS to the tools folder)");
    // A child that dies with this process (tools/child_process.hpp), so that a killed plot or
    // pipeline leaves no python behind.
    const int rc = run_child({py, script, data, out.string()});
    if (rc != 0) {
      std::fprintf(stderr, "yarnhom plot: the plot script failed (%s %s %s %s)\n", py.c_str(), script.c_str(),
                   data.c_str(), out.string().c_str());
      throw ExitCode{1};
    }
  });
}

}  // namespace yarnhom::tools
