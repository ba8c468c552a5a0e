#pragma once
// The Adam epochs' minibatch loss and gradient (what cpu::mlp_loss_grad computes for one batch)
// as one fused kernel for the network shapes of the recipes: the data points' jets to third
// order (value, gradient, Hessian, third derivatives, as the exact L_C needs), the off-domain
// points' jets to first order (L_S), the losses L_Z + w_F L_F + w_C L_C + w_S L_S, and, with a
// gradient buffer, dL/dparams by reverse mode through every jet channel.
//
// Why not cpu::mlp_loss_grad: at the recipes' widths (16 and 32 neurons) its Eigen products on
// [n, C x 64] chunks spend as much time packing, dispatching and zeroing as multiplying
// (`perf` of a paper-recipe run: GEMM kernels 27 %, packing 15 %, memset 6 %, of 81 % in the
// loss; docs/benchmarks.md). This kernel is the polish kernel's layout (cpu/polish_kernel.hpp)
// carried to any jet order: widths, input dimension and order are template parameters, points
// sit in SIMD lanes, a group of points goes through the whole network at once, every layer
// product is a register-blocked loop over its inputs with the weights broadcast, the weight
// gradient is accumulated lane by lane in one vector per weight and summed across lanes once per
// call, and nothing is allocated per call (docs/training.md, "The epochs' fused kernel").
// The sums run in a fixed order that does not depend on threads: the result is a deterministic
// function of the inputs, within rounding of mlp_loss_grad's (not bit-equal to it).
#include <vector>

#include "core/network.hpp"
#include "cpu/loss_types.hpp"

namespace yarnhom::cpu {

// Scratch of the epoch kernel: per-weight lane accumulators and one group of
// points' jets, reused from call to call.
template <class T>
struct EpochWorkspace {
  std::vector<T> buf;
};

// Whether fused_loss_grad covers this network and these options: input dimension 1 or 2, hidden
// sizes {16, 32, 16} (Net-3) or {32, 32} (Net-2), sigmoid; L_C exact (not the stencil) or off;
// no L_X (w.x = 0).
bool fused_loss_supported(const NetworkDesc& desc, const LossOptions& opt);

// The losses of mlp_loss_grad on this batch (means over the data and off-domain points, total
// weighted by opt.w), and with grad non-null dL_total/dparams written into it. Only for what
// fused_loss_supported accepts; one thread.
template <class T>
LossValues fused_loss_grad(const NetworkDesc& desc, const T* params, const LossBatch<T>& batch,
                           const LossOptions& opt, T* grad, EpochWorkspace<T>& ws);

}  // namespace yarnhom::cpu
