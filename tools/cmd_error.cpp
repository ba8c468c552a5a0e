// yarnhom error: the metrics of spec section 9 for a model or a baked file.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>

#include "bake/bake_accuracy.hpp"
#include "bake/bake_table.hpp"
#include "bake/fit_error.hpp"
#include "bake/quadratic_error.hpp"
#include "core/baked.hpp"
#include "core/dataset.hpp"
#include "core/fit_metrics.hpp"
#include "core/atomic_file.hpp"
#include "core/model.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"

namespace yarnhom::tools {

namespace {

// A file named inside another one: as given, or beside the file that names it.
std::string resolve_beside(const std::string& owner, const std::string& named) {
  namespace fs = std::filesystem;
  if (named.empty()) return "";
  if (fs::exists(named)) return named;
  const fs::path beside = fs::path(owner).parent_path() / fs::path(named).filename();
  return fs::exists(beside) ? beside.string() : "";
}

// The points of Eq. 5 when no data set is at hand: a regular grid over the box (labelled so).
std::vector<double> grid_points(const std::vector<double>& lo, const std::vector<double>& hi, int d) {
  std::vector<double> s;
  const int n = d == 1 ? 100 : 31;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < (d == 1 ? 1 : n); ++j) {
      s.push_back(lo[0] + (hi[0] - lo[0]) * i / (n - 1));
      if (d == 2) s.push_back(lo[1] + (hi[1] - lo[1]) * j / (n - 1));
    }
  return s;
}

struct Row {
  std::string term;
  int n = 0;
  double E = 0, E_rel = 0;
  bool has_fit = false;
  FitError fit;
  FitQuality val_q, all_q;  // core/fit_metrics.hpp: on the validation points, on all points
  bool has_val = false;     // the model recorded its validation points
  bool has_net = false;     // a baked file's network, measured the same way
  FitQuality net_q, net_all;
  bool has_dev = false;
  BakeDeviation dev;
};

void print_compare(const Model& model, const std::vector<Term>& wanted) {
  // Supplement Table 4's resolutions: Bake-1..3.
  const int r1[3] = {100, 150, 200}, r2[3] = {25, 50, 100};
  std::printf("\nBake resolution against the network (supplement Table 4 analogue): max |baked - network| "
              "over the term's range, on a fine grid offset from the knots (in brackets: max gradient "
              "deviation relative to the largest gradient)\n");
  std::printf("%-5s  %-28s %-28s %-28s\n", "term", "Bake-1 (100 | 25x25)", "Bake-2 (150 | 50x50)", "Bake-3 (200 | 100x100)");
  double worst[3] = {0, 0, 0};
  for (const Term& term : wanted) {
    const ModelNetwork* found = model.find(term.name);
    if (!found) continue;
    const ModelNetwork& net = *found;
    std::printf("%-5s ", net.term.name.c_str());
    const auto ref = material_function(net);  // what bake bakes (2D: the axis projection)
    for (int k = 0; k < 3; ++k) {
      // The interpolation alone: without the 1D end repair, whose change does not depend on
      // the resolution (bake reports it; 2D tables are never changed).
      BakedTerm t = make_baked_term(bake_network(net, r1[k], r2[k], nullptr, false));
      BakeDeviation d = bake_deviation(ref, baked_function(t), net.term.dim(), net.lower, net.upper);
      worst[k] = std::max(worst[k], d.max_rel);
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.3e [%.2e]", d.max_rel, d.grad_max_rel);
      std::printf(" %-28s", buf);
    }
    std::printf("\n");
  }
  std::printf("%-5s  %-28.3e %-28.3e %-28.3e\n", "max", worst[0], worst[1], worst[2]);
}

}  // namespace

void register_error(CLI::App& app) {
  struct Opts {
    std::string file, data, model, terms = "all", csv;
    int samples = 1024;
    bool compare = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "error",
      "Metrics of a model or baked file (spec section 9): the quadratic expansion error E_I of "
      "supplement Eq. 5 per term and E of Eq. 4; the fit error against the data (energy and "
      "gradient, absolute and relative); for a baked file its deviation from the network. "
      "--compare adds the supplement Table 4 analogue (bake resolutions against the network).");
  cmd->add_option("FILE", o->file, "Model file (train-all) or baked file (bake)")->required()->check(existing_regular_file());
  cmd->add_option("--data", o->data, "Dataset (default: the one the file names, if found)")->check(existing_regular_file());
  cmd->add_option("--model", o->model,
                  "For a baked file: the model to measure its deviation against (default: the one "
                  "it was baked from, if found)")
      ->check(existing_regular_file());
  cmd->add_option("--terms", o->terms, "Terms to measure, e.g. 0,02 (default all)")
      ->check(term_list_validator())
      ->capture_default_str();
  cmd->add_option("--samples", o->samples, "Samples per neighbourhood in Eq. 5 (a square in 2D)")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  cmd->add_flag("--compare", o->compare, "Also print the bake-resolution table (needs the model)");
  cmd->add_option("--csv", o->csv, "Also write the per-term rows to this CSV file (written atomically)");
  cmd->callback([o] {
    const auto t0 = std::chrono::steady_clock::now();
    if (!o->csv.empty()) prepare_output(o->csv, {o->file, o->data, o->model}, "--csv");
    const bool baked = is_baked_file(o->file);
    std::optional<Model> model;
    std::optional<BakedModel> bm;
    std::string model_path, dataset_name;
    if (baked) {
      bm = read_baked(o->file);
      model_path = o->model.empty() ? resolve_beside(o->file, bm->model) : o->model;
      if (!model_path.empty()) model = read_model(model_path);
      dataset_name = bm->dataset;
    } else {
      model = read_model(o->file);
      model_path = o->file;
      dataset_name = model->dataset;
    }
    const std::string data_path = o->data.empty() ? resolve_beside(model_path.empty() ? o->file : model_path, dataset_name) : o->data;
    std::optional<Dataset> ds;
    if (!o->csv.empty()) check_output_file(o->csv, {model_path, data_path}, "--csv");
    if (!data_path.empty()) ds = read_dataset(data_path);
    const auto wanted = parse_term_list(o->terms);

    std::printf("%s: %s file", o->file.c_str(), baked ? "baked" : "model");
    std::printf("; data: %s", ds ? data_path.c_str() : "none (Eq. 5 at a regular grid over each box instead)");
    if (baked) std::printf("; network: %s", model ? model_path.c_str() : "not found (no bake deviation)");
    std::printf("\n\n");

    std::vector<Row> rows;
    std::map<std::string, double> per_term;
    for (const Term& term : wanted) {
      TermFunction f;
      std::vector<double> lo, hi;
      if (baked) {
        const BakedTable* t = bm->find(term.name);
        if (!t) continue;
        f = baked_function(make_baked_term(*t, o->file));
        lo = t->lower;
        hi = t->upper;
      } else {
        const ModelNetwork* n = model->find(term.name);
        if (!n) continue;
        f = network_function(*n);
        lo = n->lower;
        hi = n->upper;
      }
      const int d = term.dim();
      Row r;
      r.term = term.name;
      const TermData* td = ds ? ds->find(term.name) : nullptr;
      std::vector<double> pts = td ? td->strain : grid_points(lo, hi, d);
      std::vector<double> width(d);
      double erange = 0;
      for (int i = 0; i < d; ++i) {
        double a = pts[i], b = pts[i];
        for (size_t p = i; p < pts.size(); p += d) { a = std::min(a, pts[p]); b = std::max(b, pts[p]); }
        width[i] = (b - a) / 100.0;
        if (!(width[i] > 0)) width[i] = (hi[i] - lo[i]) / 100.0;
      }
      r.n = static_cast<int>(pts.size()) / d;
      r.E = quadratic_expansion_error(f, d, pts, width, o->samples);
      per_term[term.name] = r.E;
      if (td) {
        r.has_fit = true;
        r.fit = fit_error(f, *td);
        const std::vector<double> jet = f(td->strain.data(), td->n, 1);
        r.all_q = fit_quality(*td, jet);
        const ModelNetwork* mn = model ? model->find(term.name) : nullptr;
        r.has_val = mn && !mn->val_index.empty() && mn->val_index.back() < td->n;
        r.val_q = r.has_val ? fit_quality(*td, jet, mn->val_index) : r.all_q;
        if (baked && mn) {
          const std::vector<double> nj = network_function(*mn)(td->strain.data(), td->n, 1);
          r.has_net = true;
          r.net_all = fit_quality(*td, nj);
          r.net_q = r.has_val ? fit_quality(*td, nj, mn->val_index) : r.net_all;
        }
        double a = td->energy[0], b = td->energy[0];
        for (double e : td->energy) { a = std::min(a, e); b = std::max(b, e); }
        erange = b - a;
      } else {
        auto v = f(pts.data(), r.n, 0);
        double a = v[0], b = v[0];
        for (double e : v) { a = std::min(a, e); b = std::max(b, e); }
        erange = b - a;
      }
      r.E_rel = erange > 0 ? r.E / erange : 0.0;
      if (baked && model) {
        if (const ModelNetwork* n = model->find(term.name)) {
          r.has_dev = true;
          r.dev = bake_deviation(material_function(*n), f, d, lo, hi);
        }
      }
      rows.push_back(r);
    }
    if (rows.empty()) throw std::invalid_argument(o->file + ": none of the requested terms is in the file");

    // The fit first: what the model is for.
    bool any_fit = false, any_val = false;
    for (const Row& r : rows) {
      any_fit = any_fit || r.has_fit;
      any_val = any_val || r.has_val;
    }
    int failed = 0;
    if (any_fit) {
      std::printf("Fit to the data, in physical units (docs/training.md, \"Fit quality\"): energy RMSE relative to the "
                  "term's data range, RMS gradient error relative to its mean gradient (box coordinates), and for 1D terms "
                  "'S', the RMS relative error of the small stresses (|dPsi| at 1-20%% of the term's largest); limits %g%%, "
                  "%g%% and %g%% on the validation points%s. 'data G' is the data's own inconsistency (its gradients against "
                  "the slopes of its energies, same unit): where it is above the limit no smooth fit can pass\n",
                  100 * kFitEnergyThreshold, 100 * kFitGradThreshold, 100 * kFitSmallStressThreshold,
                  any_val ? "" : " (this model records no validation split: measured on all points)");
      if (baked)
        std::printf("The verdict is the network's (what training achieved); the baked columns are the tables a "
                    "simulator evaluates: a 2D table is the network everywhere in the box (to the bake's interpolation "
                    "accuracy), a 1D table too except where bake's end repair made a 1D term rise outward "
                    "(docs/bake.md).\n");
      std::printf("%-5s %6s  %-10s %-10s %-9s | %-10s %-10s %-9s %-7s |%s %s\n", "term", "N val", "val E/rng",
                  "val G/avg", "val S", "all E/rng", "all G/avg", "all S", "data G",
                  baked ? " baked E    baked G    |" : "", "verdict");
      for (const Row& r : rows) {
        if (!r.has_fit) continue;
        const FitQuality& q = r.has_net ? r.net_q : r.val_q;
        const FitQuality& qa = r.has_net ? r.net_all : r.all_q;
        std::string verdict = fit_verdict(q);
        failed += !q.ok();
        if (r.has_net && !r.val_q.ok() && q.ok())
          verdict += std::string("; the BAKED table fails (") + baked_table_cause(int(r.term.size())) + ")";
        char dg[32] = "-", vs[32] = "-", as[32] = "-";
        if (qa.data_inconsistency >= 0) std::snprintf(dg, sizeof dg, "%.3g", 100 * qa.data_inconsistency);
        if (q.small_stress_rel >= 0) std::snprintf(vs, sizeof vs, "%.3g", 100 * q.small_stress_rel);
        if (qa.small_stress_rel >= 0) std::snprintf(as, sizeof as, "%.3g", 100 * qa.small_stress_rel);
        std::printf("%-5s %6d  %-10.3g %-10.3g %-9s | %-10.3g %-10.3g %-9s %-7s |", r.term.c_str(), q.n,
                    100 * q.energy_rel, 100 * q.grad_rel, vs, 100 * qa.energy_rel, 100 * qa.grad_rel, as, dg);
        if (baked) std::printf(" %-10.3g %-10.3g |", 100 * r.val_q.energy_rel, 100 * r.val_q.grad_rel);
        std::printf(" %s\n", verdict.c_str());
      }
      std::printf("(percentages)  %d of %zu term(s) fail the limits%s\n\n", failed, rows.size(),
                  failed ? ": their networks do not represent the data there (see the verdicts)" : "");
    }
    std::printf("%-5s %6s  %-11s %-10s | %-11s %-11s %-9s %-11s %-9s", "term", "N", "E_I", "E_I/range",
                "energy MAE", "energy RMSE", "rel std", "grad MAE", "rel");
    if (baked) std::printf(" | %-12s %-12s", "bake max/rng", "bake mean/rng");
    std::printf("\n");
    for (const Row& r : rows) {
      std::printf("%-5s %6d  %-11.3e %-10.3e |", r.term.c_str(), r.n, r.E, r.E_rel);
      if (r.has_fit)
        std::printf(" %-11.3e %-11.3e %-9.2e %-11.3e %-9.2e", r.fit.energy_mae, r.fit.energy_rmse, r.fit.energy_rel,
                    r.fit.grad_mae, r.fit.grad_rel);
      else
        std::printf(" %-11s %-11s %-9s %-11s %-9s", "-", "-", "-", "-", "-");
      if (baked) {
        if (r.has_dev) std::printf(" | %-12.3e %-12.3e", r.dev.max_rel, r.dev.mean_rel);
        else std::printf(" | %-12s %-12s", "-", "-");
      }
      std::printf("\n");
    }
    const double E = combine_expansion_errors(per_term);
    std::printf("\nE (supplement Eq. 4: mean of the 1D E_I + mean of the 2D E_I) = %.4e J/m^2\n", E);
    std::printf("  paper, same metric: basket 6.28e-4, stockinette 4.05e-4 (HYLC's fits 1.31e-3, 2.67e-3); "
                "only comparable for the same pattern and data\n");
    std::printf("  E_I: mean |Psi - T2| over %d midpoints of a neighbourhood 1/100 of the data range wide "
                "(our reading of Eq. 5: integral over measure)\n", o->samples);
    std::printf("  note: E measures smoothness (how far the function is from its local quadratic), not fit: a flat "
                "network that predicts the mean has a tiny E. Read the fit table above for the fit.\n");

    if (!o->csv.empty()) {
      AtomicOutput file(o->csv);
      std::ofstream out(file.temp_path());
      if (!out) throw std::invalid_argument(o->csv + ": cannot write");
      out << "term,n,E_I,E_I_rel,energy_mae,energy_rmse,energy_rel,grad_mae,grad_rel,bake_max_rel,bake_mean_rel,"
             "val_n,val_energy_rel_range,val_grad_rel_mean,all_energy_rel_range,all_grad_rel_mean,fit_ok,verdict,"
             "baked_val_energy_rel_range,baked_val_grad_rel_mean,baked_ok,val_small_stress_rel,all_small_stress_rel\n";
      for (const Row& r : rows) {
        out << r.term << ',' << r.n << ',' << r.E << ',' << r.E_rel << ',';
        if (r.has_fit) out << r.fit.energy_mae << ',' << r.fit.energy_rmse << ',' << r.fit.energy_rel << ',' << r.fit.grad_mae << ',' << r.fit.grad_rel << ',';
        else out << ",,,,,";
        if (r.has_dev) out << r.dev.max_rel << ',' << r.dev.mean_rel << ',';
        else out << ",,";
        if (r.has_fit) {
          const FitQuality& q = r.has_net ? r.net_q : r.val_q;
          const FitQuality& qa = r.has_net ? r.net_all : r.all_q;
          out << q.n << ',' << q.energy_rel << ',' << q.grad_rel << ',' << qa.energy_rel << ',' << qa.grad_rel
              << ',' << (q.ok() ? 1 : 0) << ",\"" << fit_verdict(q) << "\",";
          if (baked) out << r.val_q.energy_rel << ',' << r.val_q.grad_rel << ',' << (r.val_q.ok() ? 1 : 0) << ',';
          else out << ",,,";
          auto ss = [](const FitQuality& f) { return f.small_stress_rel >= 0 ? std::to_string(f.small_stress_rel) : std::string(); };
          out << ss(q) << ',' << ss(qa) << '\n';
        } else {
          out << ",,,,,,,,,,,\n";
        }
      }
      out << "E,," << E << ",,,,,,,,,,,,,,,,,,,,\n";
      out.close();
      if (!out) throw std::invalid_argument(o->csv + ": write failed");
      file.commit();
    }
    if (o->compare) {
      if (!model) throw std::invalid_argument("--compare needs the network: give --model MODEL.h5");
      print_compare(*model, wanted);
    }
    std::printf("\n(%.1fs)\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  });
}

}  // namespace yarnhom::tools
