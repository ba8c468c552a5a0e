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
// With the CUDA backend the polish runs on the GPU (train/cuda_polish.hpp: the same algorithm,
// every network in one launch); polish_network is the CPU's, on the fused kernel of the epochs
// (cpu::mlp_loss_grad).
#include <string>
#include <vector>

#include "train/backend.hpp"

namespace yarnhom {

struct PolishOptions {
  int iterations = 0;     // L-BFGS iterations; 0: no polish (the paper's recipe)
  int iterations_1d = -1; // the 1D terms' cap (< 0: iterations). Held to the data's curvature
                          // at rest (rest_weight), basket's s_a term needs more than 4000 to fit
                          // its steep ends as well (gradient error 10.8 % at 4000, 1.2 % at 8000)
  int memory = 10;        // L-BFGS history pairs
  int memory_2d = -1;     // the 2D terms' (< 1: memory). The default recipe's 30: on the synthetic
                          // paper data the 2D polishes end (float rounding) after 19,070
                          // iterations in all instead of 28,454 with 10, on 32 % fewer
                          // evaluations, as well fitted (docs/training.md, "The polish's memory
                          // and stops")
  int off_domain_layers = 8;  // L_S on a midpoint grid of the band, spacing 0.5 / layers
                              // (8: 1280 points in 2D, 16 in 1D)
  bool keep_best = true;  // end on the iterate with the lowest validation data loss
  double w_c = -1;        // weight of L_C in the polish (< 0: the epochs' weight)
  double w_s = -1;        // weight of L_S in the polish (< 0: the epochs' weight)
  // > 0: the relative fit. Each data point's L_Z and L_F residuals are weighted by
  //   w_p = 1 + 1 / (|g_p|^2 / G^2 + floor^2),   G^2 = mean over the training points of |g|^2,
  // normalized to a mean of 1 over the training points (the validation points take the same
  // constant). Where the gradient (the stress) is small, the second part dominates and the fit
  // is relative to the local gradient, down to floor x its typical size; where it is large the
  // weight tends to 1 and the fit stays the absolute one that the fit limits measure.
  // Unweighted, a term that varies over orders of magnitude in its box (basket s_x: |g| 0.29 at
  // s_x = 0.012, 83 at 1.0) is fitted to an absolute error that is a quarter of its stress at
  // small strain (docs/training.md, "Relative fit"). 0: unweighted. Per input dimension: [0] the
  // 1D terms, [1] the 2D terms.
  double relative_floor[2] = {0, 0};
  // Compute the losses in double, per input dimension ([0] 1D, [1] 2D). In float the loss of a
  // well-fitted 1D network carries rounding of about 1e-5 of itself (residuals of 1e-3 on
  // outputs of order 1), and L-BFGS stops where a step's decrease falls below it: measured on
  // basket term 0, 56 iterations and a slope 34 % too high at s_x = 0.048 in float, 4000 and
  // 3 % in double. The 2D terms' polishes run their (up to 16000) iterations in float and cost 2x in
  // double (docs/training.md, "Relative fit").
  bool in_double[2] = {true, false};
  // > 0: the second derivatives at rest are held to NetworkJob::curvature_rest (the dataset's
  // measured rest Hessian: 1D H_ii, 2D f_xy = H_ij; without one, the 1D terms' grid curvature)
  // by a penalty rest_weight * sum_c (y_c(x_rest) - k_c)^2 over the second-order jet channels,
  // in normalized units, added to the polish's loss and its validation loss.
  double rest_weight = 0;
  // The same for the 2D terms' mixed derivative f_xy at rest (only from a measured rest Hessian).
  // Off by default: measured on the paper datasets, it holds the couplings' f_xy at the origin
  // but costs the shear-bending couplings' fit (basket 13: gradient error 28 -> 54 %), whose
  // data have a ridge at II = 0 (docs/training.md, "Rest Hessian"); their rest was stable
  // without it.
  double rest_weight_2d = 0;
  // > 0: a polish in float whose line search ends ("no progress") with the training loss still
  // above stall_ratio x its starting loss is run again in double from the same start, and the
  // run with the lower validation loss is kept. Such a run sits in a flat region where each
  // step's decrease is below the float loss's rounding (the README demo's term 25 since the
  // fused epoch kernel: 944 iterations to 0.344, 5.2 % of its start, where from other last bits
  // of the epochs it reaches 2.6e-5 of it; in double from the same start 1.2e-5, a fit of
  // 0.41 % of the range); a converged float polish ends at 1e-5 to 3e-4 of its start on the
  // synthetic and the demo data (docs/training.md, "A float polish that stalls high").
  double stall_ratio = 3e-3;
};

// The L-BFGS memory of a term of this input dimension (PolishOptions::memory, memory_2d).
int polish_memory(const PolishOptions& opt, int input_dim);

// The stop reason of a polish whose line search found no lower point (train/lbfgs.hpp).
inline constexpr const char* kPolishNoProgress = "line search made no progress";


// The weights of the relative fit of points with gradients g [n, d] (normalized units), given
// G^2 and the normalization constant (both taken from the training points:
// relative_fit_scale). Exposed for the tests.
struct RelativeFitScale {
  double g2 = 1, norm = 1;
};
RelativeFitScale relative_fit_scale(const std::vector<float>& g_train, int d, double floor);
std::vector<float> relative_fit_weights(const std::vector<float>& g, int d, double floor,
                                        const RelativeFitScale& sc);

struct PolishResult {
  int iterations = 0, evaluations = 0, best_iteration = 0;
  double train_start = 0, train_end = 0;  // full-batch training loss
  double val_start = 0, val_end = 0;      // validation data loss (w_Z L_Z + w_F L_F) of the
                                          // start and of the result
  std::string stop;
  std::vector<double> train_loss, val_loss;  // per iteration
  double seconds = 0;
  bool retried = false;  // stalled high in float and run again in double (stall_ratio)
};

// Whether a float polish's result asks for the run in double (PolishOptions::stall_ratio), and
// the result to keep of the two (the lower validation loss; `params` receives its weights,
// `retry_params` are the double run's; the stop reason says what happened). The CPU and the GPU
// polish share these.
bool polish_stalled_high(const PolishResult& r, const PolishOptions& opt);
PolishResult choose_polish_retry(PolishResult first, PolishResult retry, std::vector<float>& params,
                                 std::vector<float>& retry_params);

// Polishes params (the job's network) in place.
PolishResult polish_network(const NetworkJob& job, const TrainConfig& cfg, const PolishOptions& opt,
                            std::vector<float>& params);

}  // namespace yarnhom
