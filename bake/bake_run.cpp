#include "bake/bake_run.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "bake/bake_accuracy.hpp"
#include "bake/bake_table.hpp"
#include "bake/rest_check.hpp"
#include "core/baked.hpp"
#include "core/console.hpp"
#include "core/dataset.hpp"
#include "core/error.hpp"
#include "core/file_checks.hpp"
#include "core/model.hpp"

namespace yarnhom {

std::string find_model_dataset(const std::string& model_path, const std::string& dataset) {
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

namespace {

void print_tables(const BakeRunOptions& o, const Model& model, const BakedModel& baked,
                  const std::vector<BakeReport>& reports) {
  std::printf("term  knots      max|baked-net|/range  grad max rel   safeguard (where it departs from the paper's quadratic continuation)\n");
  for (size_t k = 0; k < baked.tables.size(); ++k) {
    const BakedTable& t = baked.tables[k];
    const ModelNetwork& net = model.networks[k];
    std::string knots = std::to_string(t.knots[0]) + (t.dim() == 2 ? "x" + std::to_string(t.knots[1]) : "");
    std::string dev = "-", gdev = "-";
    if (!o.no_check) {
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
}

}  // namespace

void run_bake(const BakeRunOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  prepare_output(o.out, {o.model, o.data});
  Model model = read_model(o.model);
  double psi0 = 0;
  bool known = false;
  const std::string data = o.data.empty() ? find_model_dataset(o.model, model.dataset) : o.data;
  double areal_density = model.areal_density;
  std::string rve_rest;
  if (!data.empty()) {
    check_output_file(o.out, {data});
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
  BakedModel baked = bake_model(model, o.model, o.res1d, o.res2d, psi0, known, &reports);
  baked.areal_density = areal_density;
  const double bake_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_baked(o.out, baked);
  print_tables(o, model, baked, reports);
  {
    // The rest: stress free and stable? (bake/rest_check.hpp)
    std::string missing;
    const BakedMaterial mat = make_baked_material(baked, o.out, &missing);
    const RestCheck rc = check_rest(mat);
    std::printf("%s%s%s\n", rc.summary().c_str(), missing.empty() ? "" : (" (terms absent: " + missing + ")").c_str(),
                rve_rest.c_str());
  }
  std::printf("baked %zu terms (1D %d knots, 2D %dx%d) in %.2fs -> %s%s\n", baked.tables.size(), o.res1d, o.res2d,
              o.res2d, bake_s, o.out.c_str(), known ? "" : " (Psi0 unknown)");
}

}  // namespace yarnhom
