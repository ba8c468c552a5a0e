#pragma once
// One fused loss evaluation of one network on one batch, on the CPU: the jet forward pass on
// the data points (to the order the losses need), on the off-domain points (order 1) and, if
// asked, on the finite-difference stencil points of L_C; the losses; and, when a gradient
// buffer is given, the reverse pass of all of it into dL/dparams. This is the unit of work
// the CPU backend runs per step and per validation, and what the CUDA backend fuses on the
// device. Its plain types are in cpu/loss_types.hpp, which the CUDA sources include instead.
#include <vector>

#include "core/network.hpp"
#include "cpu/loss_types.hpp"  // LossBatch, LossOptions, LossValues, kLossChunk, data_jet_order
#include "cpu/mlp_jet.hpp"

namespace yarnhom::cpu {

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

}  // namespace yarnhom::cpu
