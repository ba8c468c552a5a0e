#pragma once
// The polish's full-batch loss and gradient (train/polish.hpp) as one fused kernel for the
// network shapes of the default recipe: L_Z + w_F L_F on order-1 jets (value and input
// gradient), per-point weights, and dL/dparams, without Eigen's general matrix products.
//
// Why not cpu::mlp_loss_grad: its layer products are Eigen GEMMs on [n, C*64] chunks; at the
// polish's widths (16 and 32 neurons, 2-3 jet channels) packing, dispatch and the colwise copies
// take more than the arithmetic (docs/benchmarks.md, "The polish"). Here the widths are template
// parameters and the work is laid out with points in SIMD lanes: a group of G vectors of points
// goes through the whole network at once, every layer product is a register-blocked loop over
// its inputs (weights broadcast, OB x C x G accumulators), the weight gradient is accumulated
// lane by lane in a vector per weight and summed across lanes once at the end, and nothing is
// allocated per evaluation. (An earlier kernel with jets as [neuron][channel][64 points] and
// unblocked loops was slower than Eigen and was dropped.) Net-2 with two inputs (the default
// recipe's 2D terms) takes double backpropagation instead of jets: the input gradient by a
// backward pass and dL/dparams by the reverse of both passes, six products of the hidden layer's
// size per point against the jets' nine (0.68x the time per evaluation). The sums run in a fixed
// order: the result is a deterministic function of the inputs, though not bit-equal to
// mlp_loss_grad's.
#include <vector>

#include "core/network.hpp"
#include "cpu/loss_types.hpp"

namespace yarnhom::cpu {

// Scratch of the fused kernel: per-weight lane accumulators and one group's jets, reused.
template <class T>
struct FusedWorkspace {
  std::vector<T> buf;
};

// Whether fused_data_loss_grad covers this network: input dimension 1 or 2 and hidden sizes
// {16, 32, 16} (the paper's Net-3) or {32, 32} (Net-2), sigmoid.
bool fused_order1_supported(const NetworkDesc& desc);

// L_Z and L_F of batch.m data points (batch.x, y, g, and batch.wt as weights when non-null) as
// mlp_loss_grad computes them at jet order 1 (means over the points; total = w.z L_Z + w.f L_F;
// L_C, L_S and L_X are not part of it). With grad non-null it is overwritten with
// d total / d params. Only for networks fused_order1_supported accepts.
template <class T>
LossValues fused_data_loss_grad(const NetworkDesc& desc, const T* params, const LossBatch<T>& batch,
                                const LossWeights& w, T* grad, FusedWorkspace<T>& ws);

}  // namespace yarnhom::cpu
