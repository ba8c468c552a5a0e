#pragma once
// A batch as a sequence of chunk tasks of one block: where its points come from, how it is cut
// into chunks (the CPU's tasks, cpu/loss_step.cpp), and the loop that runs the forward jets,
// losses and reverse pass of each task (the block path of mlp_loss_grad and of the fused epoch
// kernel).
#include <cstddef>
#include <cstdint>

#include "core/jet_layout.hpp"
#include "core/offdomain.hpp"
#include "cuda/chunk_jet.cuh"
#include "cuda/jet_shape.cuh"
#include "cuda/loss_jets.cuh"

namespace yarnhom::cuda::detail {

#ifdef __CUDACC__

// Where a batch's points come from. Data point i of the batch is row idx[i] (or i when idx is
// null) of x [*, D], y, g. Off-domain points are either given (xo, no [k, D]) or drawn on the
// fly from the stream okey with core/offdomain.hpp (the CPU backend's exact points).
struct BatchSrc {
  int m = 0;
  const float *x = nullptr, *y = nullptr, *g = nullptr;
  const int* idx = nullptr;
  int k = 0;  // 0: no off-domain term
  const float *xo = nullptr, *no = nullptr;
  uint64_t okey = 0;
};

// Chunks of a batch: the data points in chunks of S/C, then the off-domain points in chunks of
// S/(1+D) (order-1 jets), numbered in that order (the CPU's tasks, cpu/loss_step.cpp).
struct TaskPlan {
  int cap_d, cap_o, nd, no;
  YH_HD int tasks() const { return nd + no; }
};
template <int D, int ORDER>
YH_HD inline TaskPlan plan_tasks(int S, int m, int k) {
  TaskPlan t;
  t.cap_d = S / jet_channels(D, ORDER);
  t.cap_o = S / jet_channels(D, 1);
  t.nd = (m + t.cap_d - 1) / t.cap_d;
  t.no = k > 0 ? (k + t.cap_o - 1) / t.cap_o : 0;
  return t;
}

// Runs tasks first, first + stride, ... of a batch in this block: forward jets, losses, and
// (when G is non-null) the reverse pass, adding each task's gradient into G in task order.
// The loss sums of the tasks are added into *sum (thread 0). inv_m, inv_k: 1/M and 1/K of the
// whole batch (cpu::mlp_loss_grad's scales).
template <int D, int ORDER>
__device__ void batch_tasks(const NetShape& s, const float* W, const LossCfg& cfg, const BatchSrc& src,
                            float inv_m, float inv_k, Chunk& ch, float* G, Sums5* sum, int first, int stride) {
  const TaskPlan tp = plan_tasks<D, ORDER>(ch.S, src.m, src.k);
  const bool grad = G != nullptr;
  for (int t = first; t < tp.tasks(); t += stride) {
    if (t < tp.nd) {
      const int begin = t * tp.cap_d, np = min(tp.cap_d, src.m - begin);
      for (int p = threadIdx.x; p < np; p += blockDim.x) {
        const int i = src.idx ? src.idx[begin + p] : begin + p;
        ch.y[p] = src.y[i];
#pragma unroll
        for (int q = 0; q < D; ++q) {
          ch.x[p * D + q] = src.x[size_t(i) * D + q];
          ch.g[p * D + q] = src.g[size_t(i) * D + q];
        }
      }
      __syncthreads();
      chunk_forward<D, ORDER>(s, W, np, ch);
      chunk_data_losses<D, ORDER>(cfg, np, inv_m, grad, ch, sum);
      if (grad) chunk_backward<D, ORDER>(s, W, np, ch, G);
    } else {
      const int begin = (t - tp.nd) * tp.cap_o, np = min(tp.cap_o, src.k - begin);
      for (int p = threadIdx.x; p < np; p += blockDim.x) {
        if (src.xo) {
#pragma unroll
          for (int q = 0; q < D; ++q) {
            ch.x[p * D + q] = src.xo[size_t(begin + p) * D + q];
            ch.nrm[p * D + q] = src.no[size_t(begin + p) * D + q];
          }
        } else {
          offdomain_point<float>(D, src.okey, uint64_t(begin + p), &ch.x[p * D], &ch.nrm[p * D]);
        }
      }
      __syncthreads();
      chunk_forward<D, 1>(s, W, np, ch);
      chunk_offdomain_loss<D>(np, float(cfg.ws) * inv_k, grad, ch, sum);
      if (grad) chunk_backward<D, 1>(s, W, np, ch, G);
    }
    __syncthreads();
  }
}

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
