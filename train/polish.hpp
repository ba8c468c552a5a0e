#pragma once
// The full-batch polish after Adam: L-BFGS (train/lbfgs.hpp) on the same loss L as the
// epochs, over the whole training split at once, with a fixed set of off-domain points for
// L_S (a regular grid of the band) instead of fresh ones per batch, so that the objective is
// a deterministic function of the weights, which a quasi-Newton method needs. The networks
// are small (about 1,100 weights) and the datasets too (at most a few thousand points), so a
// full-batch step costs about one epoch, and curvature information is what stochastic Adam
// lacks once the loss is small: on the yarn data it lowers the validation loss by orders of
// magnitude where hundreds more epochs do not (docs/training.md, "The default recipe").
//
// Runs on the CPU whatever backend trained the epochs (the CUDA backend hands its weights
// over; the polish is a few seconds per network at most).
#include <string>
#include <vector>

#include "train/backend.hpp"

namespace yarnhom {

struct PolishOptions {
  int iterations = 0;     // L-BFGS iterations; 0: no polish (the paper's recipe)
  int memory = 10;        // L-BFGS history pairs
  int off_domain_layers = 8;  // L_S on a midpoint grid of the band, spacing 0.5 / layers
                              // (8: 1280 points in 2D, 16 in 1D)
  bool keep_best = true;  // end on the iterate with the lowest validation data loss
  double w_c = -1;        // weight of L_C in the polish (< 0: the epochs' weight)
  double w_s = -1;        // weight of L_S in the polish (< 0: the epochs' weight)
};

struct PolishResult {
  int iterations = 0, evaluations = 0, best_iteration = 0;
  double train_start = 0, train_end = 0;  // full-batch training loss
  double val_start = 0, val_end = 0;      // validation data loss (w_Z L_Z + w_F L_F) of the
                                          // start and of the result
  std::string stop;
  std::vector<double> train_loss, val_loss;  // per iteration
  double seconds = 0;
};

// Polishes params (the job's network) in place.
PolishResult polish_network(const NetworkJob& job, const TrainConfig& cfg, const PolishOptions& opt,
                            std::vector<float>& params);

}  // namespace yarnhom
