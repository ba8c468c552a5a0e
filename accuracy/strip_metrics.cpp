#include "accuracy/strip_metrics.hpp"

#include <algorithm>
#include <cmath>

#include "accuracy/middle_width.hpp"

namespace yarnhom {

AccuracySummary summarize(const std::vector<StepMetrics>& steps, double rel_floor) {
  AccuracySummary s;
  s.tests = int(steps.size());
  if (steps.empty()) return s;
  double nmax = 0, sum_diff = 0, sum_yarn = 0;
  for (const StepMetrics& m : steps) nmax = std::max(nmax, std::abs(m.n_yarn));
  for (const StepMetrics& m : steps) {
    s.mean_stress_diff += m.stress_diff;
    s.mean_hausdorff += m.hausdorff.symmetric;
    s.mean_hausdorff_fabric += m.hausdorff_fabric.symmetric;
    sum_diff += m.stress_diff;
    sum_yarn += std::abs(m.n_yarn);
    if (nmax > 0 && std::abs(m.n_yarn) >= rel_floor * nmax) {
      s.mean_rel_error += m.stress_diff / std::abs(m.n_yarn);
      ++s.rel_tests;
    }
  }
  s.mean_stress_diff /= s.tests;
  s.mean_hausdorff /= s.tests;
  s.mean_hausdorff_fabric /= s.tests;
  if (s.rel_tests) s.mean_rel_error /= s.rel_tests;
  s.ratio_of_means = sum_yarn > 0 ? sum_diff / sum_yarn : 0;
  return s;
}

Eigen::Matrix3Xd align_surface_to_points(const Eigen::Matrix3Xd& V, const Eigen::Matrix3Xd& P) {
  if (V.cols() == 0 || P.cols() == 0) return V;
  auto centre = [](const Eigen::Matrix3Xd& A) {
    Eigen::Vector3d c = 0.5 * (A.rowwise().minCoeff() + A.rowwise().maxCoeff());
    c[2] = A.row(2).mean();
    return c;
  };
  return V.colwise() + (centre(P) - centre(V));
}

}  // namespace yarnhom

#include "io/obj_read.hpp"
#include "core/error.hpp"

namespace yarnhom {

StepMetrics compare_step(const std::string& yarn_obj, const std::string& surface_obj, double stretch, double n_yarn,
                         double n_cont, double spacing) {
  const ObjGeometry y = read_obj_geometry(yarn_obj), c = read_obj_geometry(surface_obj);
  if (y.V.cols() == 0) throw FileError(yarn_obj, "", "no vertices");
  if (c.F.cols() == 0) throw FileError(surface_obj, "", "no triangles");
  StepMetrics m;
  m.stretch = stretch;
  m.n_yarn = n_yarn;
  m.n_cont = n_cont;
  m.stress_diff = std::abs(n_yarn - n_cont);
  m.hausdorff = hausdorff(y.V, align_surface_to_points(c.V, y.V), c.F, spacing);
  const Eigen::Matrix3Xd fabric = points_outside_group(y, "boundary");
  m.hausdorff_fabric = hausdorff(fabric, align_surface_to_points(c.V, fabric), c.F, spacing);
  m.width_yarn = middle_width(y.V).width;
  m.width_yarn_fabric = middle_width(fabric).width;
  m.width_cont = middle_width(c.V).width;
  return m;
}

}  // namespace yarnhom
