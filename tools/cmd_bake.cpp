// yarnhom bake: trained networks -> Hermite tables with the safeguard (spec section 8).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "bake/bake_accuracy.hpp"
#include "bake/bake_table.hpp"
#include "bake/rest_check.hpp"
#include "core/baked.hpp"
#include "core/dataset.hpp"
#include "core/error.hpp"
#include "core/model.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"

namespace yarnhom::tools {

namespace {

// The model's dataset, as given or relative to the model's folder; empty if neither exists.
std::string find_dataset(const std::string& model_path, const std::string& dataset) {
  namespace fs = std::filesystem;
  if (dataset.empty()) return "";
  const fs::path beside = fs::path(model_path).parent_path() / fs::path(dataset).filename();
  const std::string found = fs::exists(dataset) ? dataset : fs::exists(beside) ? beside.string() : "";
  // A FIFO or device named by the attribute would block the reader: refuse it, naming both.
  if (!found.empty() && !fs::is_regular_file(found))
    throw FileError(model_path, "attribute dataset",
                    "names " + found + ", which is not a regular file; give the dataset with --data");
  return found;
}

}  // namespace

void register_bake(CLI::App& app) {
  struct Opts {
    std::string model, out, data;
    int res1d = 200, res2d = 100;
    bool no_check = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "bake",
      "Bake every network of a model into Hermite tables (1D: cubic, (f, f') at res1d knots; 2D: "
      "bicubic, (f, f_x, f_y, f_xy) on res2d x res2d knots; exact network derivatives) with the "
      "safeguard outside the trained box: a 1D term (energy along one strain axis) continues with "
      "the paper's C2 quadratic, its curvature clamped >= 0, and where its end slope points inward "
      "or curves down the table's outer 5% is repaired so that it rises; a 2D term (a residual, "
      "which may fall outward) is the network's everywhere and continues to first order across "
      "its edges and corners (C1), so that outside the box the total energy's outward curvature "
      "is the 1D terms'. Baked as one material: where a pair's TOTAL energy falls outward at "
      "the box, the 1D end's curvature is raised (C2, in the table's outer 5%) so that it turns "
      "up within half the box width; where a corner's twist would bend the total down without "
      "bound, that corner knot's f_xy is raised (one cell changes). So outside the box the "
      "total is bounded below and rises far out. The table says per term where this departs "
      "from the paper's quadratic and what it changed, and per term pair where the total still "
      "falls outward at the box (data). The baked file is what a cloth simulator loads "
      "(docs/bake.md).");
  cmd->add_option("MODEL", o->model, "Model file (HDF5) written by train-all")->required()->check(existing_regular_file());
  cmd->add_option("-o,--output", o->out, "Baked file to write (HDF5, written atomically)")->required();
  cmd->add_option("--res1d", o->res1d, "Knots of a 1D table (the paper: 200)")->check(CLI::Range(2, 1000000))->capture_default_str();
  cmd->add_option("--res2d", o->res2d, "Knots per axis of a 2D table (the paper: 100)")->check(CLI::Range(2, 10000))->capture_default_str();
  cmd->add_option("--data", o->data,
                  "Dataset whose Psi0 (rest energy) to store for the full material; default: the "
                  "model's own dataset when it can be found")
      ->check(existing_regular_file());
  cmd->add_flag("--no-check", o->no_check, "Skip measuring each table against its network");
  cmd->callback([o] {
    const auto t0 = std::chrono::steady_clock::now();
    prepare_output(o->out, {o->model, o->data});
    Model model = read_model(o->model);
    double psi0 = 0;
    bool known = false;
    const std::string data = o->data.empty() ? find_dataset(o->model, model.dataset) : o->data;
    double areal_density = model.areal_density;
    std::string rve_rest;
    if (!data.empty()) {
      check_output_file(o->out, {data});
      const Dataset ds = read_dataset(data);
      rve_rest = rve_rest_note(ds.rest_hessian);
      psi0 = ds.psi0;
      known = true;
      if (std::isnan(areal_density)) areal_density = ds.areal_density;  // a model trained before it was copied
    } else {
      std::fprintf(stderr,
                   "yarnhom bake: note: the model's dataset '%s' was not found, so Psi0 is stored "
                   "as 0 (psi0_known = 0); give --data to store it\n",
                   model.dataset.c_str());
    }
    std::vector<BakeReport> reports;
    BakedModel baked = bake_model(model, o->model, o->res1d, o->res2d, psi0, known, &reports);
    baked.areal_density = areal_density;
    const double bake_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    write_baked(o->out, baked);
    std::printf("term  knots      max|baked-net|/range  grad max rel   safeguard (where it departs from the paper's quadratic continuation)\n");
    for (size_t k = 0; k < baked.tables.size(); ++k) {
      const BakedTable& t = baked.tables[k];
      const ModelNetwork& net = model.networks[k];
      std::string knots = std::to_string(t.knots[0]) + (t.dim() == 2 ? "x" + std::to_string(t.knots[1]) : "");
      std::string dev = "-", gdev = "-";
      if (!o->no_check) {
        BakeDeviation d = bake_deviation(material_function(net), baked_function(make_baked_term(t)), t.dim(),
                                         t.lower, t.upper, t.dim() == 1 ? 2003 : 101);
        char b1[32], b2[32];
        std::snprintf(b1, sizeof b1, "%.3e", d.max_rel);
        std::snprintf(b2, sizeof b2, "%.3e", d.grad_max_rel);
        dev = b1;
        gdev = b2;
      }
      std::string note = reports[k].summary(t);
      if (net.status != "ok") note = "NETWORK NOT TRAINED (" + net.status + "); " + note;
      std::printf("%-5s %-10s %-21s %-14s %s\n", t.term.name.c_str(), knots.c_str(), dev.c_str(), gdev.c_str(),
                  note.c_str());
    }
    {
      // The rest: stress free and stable? (bake/rest_check.hpp)
      std::string missing;
      const BakedMaterial mat = make_baked_material(baked, o->out, &missing);
      const RestCheck rc = check_rest(mat);
      std::printf("%s%s%s\n", rc.summary().c_str(), missing.empty() ? "" : (" (terms absent: " + missing + ")").c_str(),
                  rve_rest.c_str());
    }
    std::printf("baked %zu terms (1D %d knots, 2D %dx%d) in %.2fs -> %s%s\n", baked.tables.size(), o->res1d, o->res2d,
                o->res2d, bake_s, o->out.c_str(), known ? "" : " (Psi0 unknown)");
  });
}

}  // namespace yarnhom::tools
