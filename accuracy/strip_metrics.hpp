#pragma once
// The per-step metrics of the accuracy study (supplement section 4.2, Table 5) and their means.
//
//   stress difference  |N_yarn - N_cont|, N the clamp force along the stretch axis per
//                      undeformed clamp width (N/m), as `strip` and `sim stretch` report it;
//   Hausdorff distance accuracy/hausdorff.hpp between the yarn centreline vertices and the
//                      continuum surface, after align_surface_to_points;
//   means              over the tests (the paper: 15, 100 % to 170 % in 5 % steps) of the
//                      stress difference and of the Hausdorff distance, and the mean relative
//                      stress error: the mean of |N_yarn - N_cont| / |N_yarn| over the tests
//                      whose |N_yarn| is at least `rel_floor` of the largest |N_yarn| (at 100 %
//                      the yarn strip carries ~0 N/m and the ratio is undefined: our reading,
//                      the paper does not say); also the ratio of the means,
//                      sum |N_yarn - N_cont| / sum |N_yarn|, which needs no such cut.
#include <vector>

#include "accuracy/hausdorff.hpp"

namespace yarnhom {

struct StepMetrics {
  double stretch = 1;  // clamp separation / rest length
  double n_yarn = 0, n_cont = 0;  // N/m
  double stress_diff = 0;         // |n_yarn - n_cont|
  HausdorffDistance hausdorff;    // metres
  // The same, with the yarn strip's soft boundary yarn (OBJ group "boundary") left out: its
  // connectors run in lanes up to a centimetre outside the fabric (docs/strip.md section 1), so
  // they, not the fabric, set the full distance's floor. Equal to `hausdorff` without groups.
  HausdorffDistance hausdorff_fabric;
  double width_yarn_fabric = 0;  // m, the yarn strip's middle width without its boundary yarn
  double width_yarn = 0, width_cont = 0;  // m, each strip's projected width at its middle
                                          // (accuracy/middle_width.hpp)
};

struct AccuracySummary {
  int tests = 0;
  double mean_stress_diff = 0;  // N/m
  double mean_hausdorff = 0;    // metres
  double mean_hausdorff_fabric = 0;  // metres, StepMetrics::hausdorff_fabric
  double mean_rel_error = 0;    // fraction, over rel_tests tests
  int rel_tests = 0;
  double ratio_of_means = 0;    // fraction
};

AccuracySummary summarize(const std::vector<StepMetrics>& steps, double rel_floor = 0.01);

// The continuum surface translated so that the centre of its bounding box in the plane (x, y)
// and its mean height z match those of the yarn points: the two simulators each choose where
// the strip lies; the metrics compare shapes, not placements.
Eigen::Matrix3Xd align_surface_to_points(const Eigen::Matrix3Xd& V, const Eigen::Matrix3Xd& P);

}  // namespace yarnhom

namespace yarnhom {

// One step: the yarn centreline vertices (all vertices of the OBJ, polylines or not) against
// the continuum surface (its triangles), aligned by align_surface_to_points; and the fabric's
// vertices alone (points_outside_group "boundary") against the surface aligned to them.
StepMetrics compare_step(const std::string& yarn_obj, const std::string& surface_obj, double stretch, double n_yarn,
                         double n_cont, double spacing);

}  // namespace yarnhom
