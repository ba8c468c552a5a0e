#include "accuracy/fit_splines_run.hpp"

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "core/baked.hpp"
#include "core/console.hpp"
#include "core/dataset.hpp"

namespace yarnhom {

void run_fit_splines(const FitSplinesOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  SplineFitOptions fit = o.fit;
  fit.monotone = !o.no_monotone;
  prepare_output(o.out, {o.data});
  const Dataset ds = read_dataset(o.data);
  std::vector<SplineFitReport> reports;
  BakedModel m;
  try {
    m = fit_splines(ds, o.data, fit, &reports);
  } catch (const std::runtime_error& e) {  // a term without a fit: name the file and the weights that led there
    char buf[200];
    std::snprintf(buf, sizeof buf, " (--smoothing %g, --gradient-weight %g%s)", fit.smoothing, fit.gradient_weight,
                  fit.monotone ? "; --no-monotone drops the monotone constraint" : "");
    throw std::runtime_error(o.data + ": " + e.what() + buf);
  }
  write_baked(o.out, m);
  std::printf("term  knots   energy RMSE/range  grad err/mean  monotone (minimum knot, active constraints)\n");
  for (const SplineFitReport& r : reports) {
    std::string knots = std::to_string(r.knots[0]) + (r.knots[1] ? "x" + std::to_string(r.knots[1]) : "");
    std::string mono = r.minimum_knot >= 0 ? "knot " + std::to_string(r.minimum_knot) + ", " +
                                                 std::to_string(r.constraints_active) + " active"
                                           : "-";
    std::printf("%-5s %-7s %-18.3e %-14.3e %s\n", r.term.c_str(), knots.c_str(), r.energy_rmse_rel, r.gradient_err_rel,
                mono.c_str());
  }
  std::printf("fitted %zu terms in %.2fs -> %s\n", m.tables.size(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), o.out.c_str());
}

}  // namespace yarnhom
