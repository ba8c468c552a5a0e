#pragma once
// The model file (spec section 7), written by train-all: per term, the network's weights, its
// normalization, its training recipe and history. Everything needed to evaluate
// Psi_hat(s) in physical units without the program is in the file.
//
//   /                             attrs: format="yarnhom-model", version=1, dataset, seed,
//                                 [areal_density (kg/m^2, copied from the dataset)]
//   /networks/<name>              attrs: indices, lower, upper, activation, hidden,
//                                 in_center[d], in_halfwidth[d], out_mean, out_std,
//                                 w_Z w_F w_C w_S w_X, epochs, backend, status
//   /networks/<name>/layer<k>/W   float32 [out, in]   (y = W x + b)
//   /networks/<name>/layer<k>/b   float32 [out]
//   /networks/<name>/history/{train_loss, val_loss, lr, L_Z, L_F, L_C, L_S}  per epoch
//   /networks/<name>/history/{polish_train_loss, polish_val_loss}   per L-BFGS iteration
//                                 of the full-batch polish (absent when there was none)
//   /networks/<name>/val_index    int32 [n_val]: the dataset rows held out for validation
//                                 (absent in files written before it existed)
//   /networks/<name>              attr recipe (optional): "paper" or "default"
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/network.hpp"
#include "core/terms.hpp"

namespace yarnhom {

// x = (s - center) / halfwidth per input; Psi = out_mean + out_std * y.
struct Normalization {
  std::vector<double> center, halfwidth;
  double out_mean = 0.0, out_std = 1.0;
};

struct History {
  std::vector<double> train_loss, val_loss, lr, loss_z, loss_f, loss_c, loss_s;
  std::vector<double> polish_train, polish_val;  // per polish iteration (may be empty)
  size_t size() const { return train_loss.size(); }
};

struct ModelNetwork {
  Term term;
  std::vector<double> lower, upper;
  NetworkDesc desc;
  std::vector<float> params;  // flat layout of core/network.hpp
  Normalization norm;
  LossWeights weights;
  int epochs = 0;             // epochs actually run
  std::string backend = "cpu";
  std::string status = "ok";  // "ok", or why training stopped (e.g. non-finite loss)
  std::string recipe;         // "paper", "default" (empty when the file does not say)
  History history;
  std::vector<int> val_index; // dataset rows of the term held out for validation (may be empty)
};

struct Model {
  std::string dataset;  // the dataset file it was trained on
  uint64_t seed = 0;
  double areal_density = NAN;  // kg/m^2, from the dataset; NaN: unknown (absent in the file)
  std::vector<ModelNetwork> networks;
  const ModelNetwork* find(const std::string& name) const;
};

inline constexpr const char* kModelFormat = "yarnhom-model";
inline constexpr int kModelVersion = 1;

Model read_model(const std::string& path);
void write_model(const std::string& path, const Model& model);  // atomic

}  // namespace yarnhom
