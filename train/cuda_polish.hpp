#pragma once
// The default recipe's full-batch L-BFGS polish on the GPU (train/cuda_polish.cu): the whole of
// train/polish.cpp's polish_network (the two-loop recursion, the strong-Wolfe line search with
// cubic zoom, the fused loss and gradient, the validation loss of every accepted iterate and
// the best iterate kept) for all networks at once, in one kernel launch: one thread-block
// cluster per network. Plain C++: no CUDA header needed to call it.
#include <vector>

#include "train/polish.hpp"

namespace yarnhom {

// Whether the GPU polish computes what polish_network would for this job and options: the
// polish's losses L_Z and L_F only (w_C, w_S, w_X zero in the polish), no rest penalty on a 2D
// term, at most 32 history pairs, a network that fits a block's shared memory. The default
// recipe's polish qualifies on every term.
bool cuda_polish_supports(const NetworkJob& job, const TrainConfig& cfg, const PolishOptions& opt);

// Polishes params[j] in place for each j in `which` (all supported) and fills results[j], as
// polish_network does on the CPU (the same iterations, stop reasons and histories up to
// rounding); PolishResult::seconds is the wall time of the one launch, shared by all.
void cuda_polish_networks(const std::vector<NetworkJob>& jobs, const TrainConfig& cfg, const PolishOptions& opt,
                          const std::vector<int>& which, std::vector<std::vector<float>>& params,
                          std::vector<PolishResult>& results);

}  // namespace yarnhom
