#include "accuracy/error_report.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>
#include <vector>

#include "accuracy/fit_error.hpp"
#include "accuracy/quadratic_error.hpp"
#include "bake/bake_accuracy.hpp"
#include "bake/bake_table.hpp"
#include "core/atomic_file.hpp"
#include "core/baked.hpp"
#include "core/console.hpp"
#include "core/dataset.hpp"
#include "core/file_checks.hpp"
#include "core/fit_metrics.hpp"
#include "core/model.hpp"

namespace yarnhom {
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

double value_range(const std::vector<double>& v) {
  double a = v[0], b = v[0];
  for (double e : v) {
    a = std::min(a, e);
    b = std::max(b, e);
  }
  return b - a;
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
  // The verdict's fit: the network's where there is one (what training achieved).
  const FitQuality& verdict_q() const { return has_net ? net_q : val_q; }
  const FitQuality& verdict_all() const { return has_net ? net_all : all_q; }
};

// What is measured: the file, its network (a baked file's, if found) and the data (if found).
struct Inputs {
  bool baked = false;
  std::optional<Model> model;
  std::optional<BakedModel> bm;
  std::optional<Dataset> ds;
  std::string model_path, data_path;
};

Inputs read_inputs(const ErrorReportOptions& o) {
  Inputs in;
  in.baked = is_baked_file(o.file);
  std::string dataset_name;
  if (in.baked) {
    in.bm = read_baked(o.file);
    in.model_path = o.model.empty() ? resolve_beside(o.file, in.bm->model) : o.model;
    if (!in.model_path.empty()) in.model = read_model(in.model_path);
    dataset_name = in.bm->dataset;
  } else {
    in.model = read_model(o.file);
    in.model_path = o.file;
    dataset_name = in.model->dataset;
  }
  in.data_path = o.data.empty() ? resolve_beside(in.model_path.empty() ? o.file : in.model_path, dataset_name) : o.data;
  if (!o.csv.empty()) check_output_file(o.csv, {in.model_path, in.data_path}, "--csv");
  if (!in.data_path.empty()) in.ds = read_dataset(in.data_path);
  return in;
}

// One term's row; false when the file has no such term.
bool measure_term(const ErrorReportOptions& o, const Inputs& in, const Term& term, Row& r) {
  TermFunction f;
  std::vector<double> lo, hi;
  if (in.baked) {
    const BakedTable* t = in.bm->find(term.name);
    if (!t) return false;
    f = baked_function(make_baked_term(*t, o.file));
    lo = t->lower;
    hi = t->upper;
  } else {
    const ModelNetwork* n = in.model->find(term.name);
    if (!n) return false;
    f = network_function(*n);
    lo = n->lower;
    hi = n->upper;
  }
  const int d = term.dim();
  r.term = term.name;
  const TermData* td = in.ds ? in.ds->find(term.name) : nullptr;
  std::vector<double> pts = td ? td->strain : grid_points(lo, hi, d);
  std::vector<double> width(d);
  for (int i = 0; i < d; ++i) {
    double a = pts[i], b = pts[i];
    for (size_t p = i; p < pts.size(); p += d) { a = std::min(a, pts[p]); b = std::max(b, pts[p]); }
    width[i] = (b - a) / 100.0;
    if (!(width[i] > 0)) width[i] = (hi[i] - lo[i]) / 100.0;
  }
  r.n = static_cast<int>(pts.size()) / d;
  r.E = quadratic_expansion_error(f, d, pts, width, o.samples);
  const ModelNetwork* mn = in.model ? in.model->find(term.name) : nullptr;
  double erange = 0;
  if (td) {
    r.has_fit = true;
    r.fit = fit_error(f, *td);
    const std::vector<double> jet = f(td->strain.data(), td->n, 1);
    r.all_q = fit_quality(*td, jet);
    r.has_val = mn && !mn->val_index.empty() && mn->val_index.back() < td->n;
    r.val_q = r.has_val ? fit_quality(*td, jet, mn->val_index) : r.all_q;
    if (in.baked && mn) {
      const std::vector<double> nj = network_function(*mn)(td->strain.data(), td->n, 1);
      r.has_net = true;
      r.net_all = fit_quality(*td, nj);
      r.net_q = r.has_val ? fit_quality(*td, nj, mn->val_index) : r.net_all;
    }
    erange = value_range(td->energy);
  } else {
    erange = value_range(f(pts.data(), r.n, 0));
  }
  r.E_rel = erange > 0 ? r.E / erange : 0.0;
  if (in.baked && mn) {
    r.has_dev = true;
    r.dev = bake_deviation(material_function(*mn), f, d, lo, hi);
  }
  return true;
}

// The fit first: what the model is for.
void print_fit_table(const std::vector<Row>& rows, bool baked) {
  bool any_fit = false, any_val = false;
  for (const Row& r : rows) {
    any_fit = any_fit || r.has_fit;
    any_val = any_val || r.has_val;
  }
  if (!any_fit) return;
  std::printf("Fit to the data, in physical units (docs/training.md, \"Fit quality\"): energy RMSE relative to the "
              "term's data range, RMS gradient error relative to its mean gradient (box coordinates), and for 1D terms "
              "'S', the RMS relative error of the small stresses (|dPsi| at 1-20%% of the term's largest); limits %g%%, "
              "%g%% and %g%% on the validation points%s. 'data G' is the data's own inconsistency (its gradients against "
              "the slopes of its energies, same unit): where it is above the gradient limit no smooth fit can meet that limit, "
              "and the gradient passes below 1.25 x data G instead (the data rule; the verdict names it)\n",
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
  int failed = 0;
  for (const Row& r : rows) {
    if (!r.has_fit) continue;
    const FitQuality& q = r.verdict_q();
    const FitQuality& qa = r.verdict_all();
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

void print_metrics_table(const std::vector<Row>& rows, bool baked, double E, int samples) {
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
  std::printf("\nE (supplement Eq. 4: mean of the 1D E_I + mean of the 2D E_I) = %.4e J/m^2\n", E);
  std::printf("  paper, same metric: basket 6.28e-4, stockinette 4.05e-4 (HYLC's fits 1.31e-3, 2.67e-3); "
              "only comparable for the same pattern and data\n");
  std::printf("  E_I: mean |Psi - T2| over %d midpoints of a neighbourhood 1/100 of the data range wide "
              "(our reading of Eq. 5: integral over measure)\n", samples);
  std::printf("  note: E measures smoothness (how far the function is from its local quadratic), not fit: a flat "
              "network that predicts the mean has a tiny E. Read the fit table above for the fit.\n");
}

void write_csv(const std::string& path, const std::vector<Row>& rows, bool baked, double E) {
  AtomicOutput file(path);
  std::ofstream out(file.temp_path());
  if (!out) throw std::invalid_argument(path + ": cannot write");
  out << "term,n,E_I,E_I_rel,energy_mae,energy_rmse,energy_rel,grad_mae,grad_rel,bake_max_rel,bake_mean_rel,"
         "val_n,val_energy_rel_range,val_grad_rel_mean,all_energy_rel_range,all_grad_rel_mean,fit_ok,verdict,"
         "baked_val_energy_rel_range,baked_val_grad_rel_mean,baked_ok,val_small_stress_rel,all_small_stress_rel\n";
  auto ss = [](const FitQuality& f) { return f.small_stress_rel >= 0 ? std::to_string(f.small_stress_rel) : std::string(); };
  for (const Row& r : rows) {
    out << r.term << ',' << r.n << ',' << r.E << ',' << r.E_rel << ',';
    if (r.has_fit) out << r.fit.energy_mae << ',' << r.fit.energy_rmse << ',' << r.fit.energy_rel << ',' << r.fit.grad_mae << ',' << r.fit.grad_rel << ',';
    else out << ",,,,,";
    if (r.has_dev) out << r.dev.max_rel << ',' << r.dev.mean_rel << ',';
    else out << ",,";
    if (!r.has_fit) {
      out << ",,,,,,,,,,,\n";
      continue;
    }
    const FitQuality& q = r.verdict_q();
    const FitQuality& qa = r.verdict_all();
    out << q.n << ',' << q.energy_rel << ',' << q.grad_rel << ',' << qa.energy_rel << ',' << qa.grad_rel
        << ',' << (q.ok() ? 1 : 0) << ",\"" << fit_verdict(q) << "\",";
    if (baked) out << r.val_q.energy_rel << ',' << r.val_q.grad_rel << ',' << (r.val_q.ok() ? 1 : 0) << ',';
    else out << ",,,";
    out << ss(q) << ',' << ss(qa) << '\n';
  }
  out << "E,," << E << ",,,,,,,,,,,,,,,,,,,,\n";
  out.close();
  if (!out) throw std::invalid_argument(path + ": write failed");
  file.commit();
}

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

void run_error_report(const ErrorReportOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!o.csv.empty()) prepare_output(o.csv, {o.file, o.data, o.model}, "--csv");
  const Inputs in = read_inputs(o);
  const auto wanted = parse_term_list(o.terms);

  std::printf("%s: %s file", o.file.c_str(), in.baked ? "baked" : "model");
  std::printf("; data: %s", in.ds ? in.data_path.c_str() : "none (Eq. 5 at a regular grid over each box instead)");
  if (in.baked) std::printf("; network: %s", in.model ? in.model_path.c_str() : "not found (no bake deviation)");
  std::printf("\n\n");

  std::vector<Row> rows;
  std::map<std::string, double> per_term;
  for (const Term& term : wanted) {
    Row r;
    if (!measure_term(o, in, term, r)) continue;
    per_term[term.name] = r.E;
    rows.push_back(r);
  }
  if (rows.empty()) throw std::invalid_argument(o.file + ": none of the requested terms is in the file");
  print_fit_table(rows, in.baked);
  const double E = combine_expansion_errors(per_term);
  print_metrics_table(rows, in.baked, E, o.samples);
  if (!o.csv.empty()) write_csv(o.csv, rows, in.baked, E);
  if (o.compare) {
    if (!in.model) throw std::invalid_argument("--compare needs the network: give --model MODEL.h5");
    print_compare(*in.model, wanted);
  }
  std::printf("\n(%.1fs)\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

}  // namespace yarnhom
