#pragma once
// One fused loss evaluation of one network on one batch, on the CPU: the jet forward pass on
// the data points (to the order the losses need), on the off-domain points (order 1) and, if
// asked, on the finite-difference stencil points of L_C; the losses; and, when a gradient
// buffer is given, the reverse pass of all of it into dL/dparams. This is the unit of work
// the CPU backend runs per step and per validation, and what the CUDA backend fuses on the
// device.
#include <vector>

#include "core/network.hpp"
#include "cpu/mlp_jet.hpp"

namespace yarnhom::cpu {

// Everything one loss evaluation reads, in normalized units; pointers are not owned.
template <class T>
struct LossBatch {
  int m = 0;                  // data points
  const T* x = nullptr;       // [m, d]
  const T* y = nullptr;       // [m]
  const T* g = nullptr;       // [m, d]
  int k = 0;                  // off-domain points
  const T* xo = nullptr;      // [k, d]
  const T* no = nullptr;      // [k, d] outward normals
  const T* wt = nullptr;      // [m] per-point weights of L_Z and L_F, or nullptr (all 1): the
                              // polish's relative fit (train/polish.hpp); the CPU loss only
};

struct LossOptions {
  LossWeights w;
  bool stencil_c = false;      // L_C by the paper's finite-difference stencil instead of exactly
  double stencil_eps = 1e-2;   // stencil step, normalized units
};

// Means of each loss term over its points, and the weighted total.
struct LossValues {
  double total = 0, z = 0, f = 0, c = 0, s = 0, x = 0;
};

// Data points are processed in chunks of this many: each chunk's gradient is summed in chunk
// order, so results do not depend on the number of threads.
inline constexpr int kLossChunk = 64;

template <class T>
struct LossWorkspace {
  std::vector<JetWorkspace<T>> jw;        // per worker thread
  std::vector<std::vector<T>> jet, djet;  // per worker thread
  std::vector<std::vector<T>> grad;       // per chunk parameter gradients (summed in order)
  std::vector<std::vector<T>> pts;        // per worker thread: stencil points, values, adjoints
};

// Returns the losses; if grad is non-null it is overwritten with dL_total/dparams.
// threads > 1 spreads the chunks over OpenMP threads (same result for any thread count).
template <class T>
LossValues mlp_loss_grad(const NetworkDesc& desc, const T* params, const LossBatch<T>& batch,
                         const LossOptions& opt, T* grad, LossWorkspace<T>& ws, int threads = 1);

// The jet order the data points need for these options.
inline int data_jet_order(const LossOptions& opt) {
  if (opt.w.c != 0 && !opt.stencil_c) return 3;
  if (opt.w.x != 0) return 2;
  return 1;
}

}  // namespace yarnhom::cpu
