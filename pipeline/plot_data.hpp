#pragma once
// The numbers behind a run's pictures (supplement Fig. 1, 3, 4 and the 1D fits), computed with
// the project's own evaluators and written to one HDF5 file that scripts/plot/plot_run.py draws,
// so that no formula exists twice (once here, once in Python).
//
//   /                      attrs: format="yarnhom-plotdata"
//   /history/<term>/{train_loss, val_loss, lr}              per epoch (from the model)
//   /history/<term>/{polish_train_loss, polish_val_loss}    per L-BFGS iteration of the polish
//                          that follows the epochs (absent when the recipe had none)
//   /line/<term>           1D: x, baked, sector, network (if the model is given),
//                          data_x, data_psi (if the dataset is given); attrs lower, upper, symbol
//   /surface/<term>        2D: x [n], y [n], psi [n, n], sector [n, n], d3 [n, n] over the box
//                          widened by half its width on each side; attrs lower, upper, symbol_x/y;
//                          data_x, data_y, data_psi (and data_val: the validation rows) with a dataset
//   line and surface, with model and dataset: attrs fit_ok (1/0) and verdict, the term's fit on
//                          its validation rows as the pipeline's report judges it
//   /convexity/<term>      2D: x, y, lam_min [m, m]: smallest Hessian eigenvalue over the box in
//                          box-normalized units, and lam_min_pair: that of the pair's total
//                          Psi_I + Psi_J + Psi_IJ (baked 1D terms added; when both are baked), in
//                          box-normalized units; attr source = "network" or "baked"
#include <optional>
#include <string>

#include "core/baked.hpp"
#include "core/dataset.hpp"
#include "core/model.hpp"

namespace yarnhom {

void write_plot_data(const std::string& path, const std::optional<Model>& model, const BakedModel& baked,
                     const std::optional<Dataset>& ds);

}  // namespace yarnhom
