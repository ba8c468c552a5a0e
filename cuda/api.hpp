#pragma once
// The CUDA twins of the cpu/ kernels, callable from plain C++ (no CUDA headers needed).
//
// Same names, argument order and math as their CPU twins (cpu/mlp_jet.hpp, cpu/losses.hpp,
// cpu/loss_step.hpp, cpu/adam.hpp); the pointers they take are *device* pointers (DeviceVec
// below allocates and copies). float only. All of them run on the block-level building blocks
// of cuda/jet_block.cuh, the same code the fused training kernel (train/cuda_backend.cu) runs, so
// that testing a twin against its CPU twin tests the trainer's arithmetic; mlp_loss_grad of
// the paper's Net-3 runs on the tensor-core warp path of cuda/mma_jet.cuh (same math, the
// hidden-to-hidden products as 3xTF32 MMAs), and is tested on both paths.
//
// Errors (no GPU, out of memory, a failed launch) throw yarnhom::cuda::CudaError, whose
// message names the CUDA call and the CUDA error string.
//
// Included by every .cu file, so it includes no Eigen (cpu/loss_types.hpp, not
// cpu/loss_step.hpp): docs/layout.md, "Compiler flags".
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/network.hpp"
#include "cpu/adam.hpp"
#include "cpu/loss_types.hpp"
#include "cpu/losses.hpp"

namespace yarnhom::cuda {

class CudaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Number of CUDA devices this process can use (0 when there is no driver or no GPU).
int device_count();
// "NVIDIA H100 80GB HBM3 (sm_90, 132 SMs)", or the reason there is none.
std::string device_description();
// Throws CudaError with a clear message when no GPU can be used.
void require_device();
// YARNHOM_HOST_ISA (core/host_isa.hpp) as nvcc's host pass saw it: the target ISA the .cu
// files' host code was compiled for, which must be the .cpp files' (tests/cuda/test_host_isa.cpp).
// Host code only; needs no GPU.
std::string host_isa();

// A device array of T (float or int), owned.
template <class T>
class DeviceVec {
 public:
  DeviceVec() = default;
  explicit DeviceVec(size_t n) { resize(n); }
  explicit DeviceVec(const std::vector<T>& h) { upload(h); }
  ~DeviceVec() { release(); }
  DeviceVec(const DeviceVec&) = delete;
  DeviceVec& operator=(const DeviceVec&) = delete;
  DeviceVec(DeviceVec&& o) noexcept : p_(o.p_), n_(o.n_) { o.p_ = nullptr, o.n_ = 0; }
  DeviceVec& operator=(DeviceVec&& o) noexcept {
    if (this != &o) {
      release();
      p_ = o.p_, n_ = o.n_;
      o.p_ = nullptr, o.n_ = 0;
    }
    return *this;
  }
  void resize(size_t n);  // contents undefined after a resize that reallocates
  void upload(const std::vector<T>& h);
  std::vector<T> download() const;
  void fill_zero();
  T* data() { return p_; }
  const T* data() const { return p_; }
  size_t size() const { return n_; }

 private:
  void release();
  T* p_ = nullptr;
  size_t n_ = 0;
};

// Scratch of the twins: per-block partial gradients and loss sums, reused across calls.
struct JetWorkspace {
  DeviceVec<float> partial;  // [blocks, P] or per-point loss terms
  DeviceVec<float> sums;     // [blocks, 5]
};

// Launch shape of the multi-block twins: threads per block and the column stride of a chunk
// in shared memory (cuda/jet_block.cuh). 0 = the defaults. mlp_loss_grad of the paper's Net-3
// runs on the tensor-core warp path (cuda/mma_jet.cuh; threads and blocks apply, the stride
// does not) unless block_path is set (or the environment variable YARNHOM_CUDA_PATH=block).
struct LaunchShape {
  int threads = 0, stride = 0, blocks = 0;
  bool block_path = false;
};
void set_launch_shape(const LaunchShape& s);  // for benchmarks

// Twin of cpu::mlp_jet_forward: x [B, d], out [C, B] channel-major (device pointers).
void mlp_jet_forward(const NetworkDesc& desc, const float* params, const float* x, int batch,
                     int order, float* out, JetWorkspace& ws);

// Twin of cpu::mlp_jet_backward: adds dL/dparams into dparams (device). Unlike the CPU twin it
// does not keep the forward pass's per-layer jets (the device would have to hold them for the
// whole batch): every block recomputes the forward pass of its chunk of points in shared
// memory, then runs the reverse pass. Per-block partial gradients are summed in block order.
void mlp_jet_backward(const NetworkDesc& desc, const float* params, const float* x, int batch,
                      int order, const float* dout, float* dparams, JetWorkspace& ws);

// Twins of cpu::data_losses and cpu::strain_concentration_loss: one thread per point on the
// device; the per-point terms are summed in point order (as on the CPU).
cpu::LossSums<float> data_losses(int d, int B, int order, const float* jet, const float* y,
                                 const float* g, const float* wt, const LossWeights& w, bool exact_c,
                                 float scale, float* djet);
float strain_concentration_loss(int d, int K, int order, const float* jet, const float* normals,
                                float weight_scale, float* djet);

// Twin of cpu::adam_update (PyTorch Adam), one thread per parameter; bias corrections in
// double on the host, as on the CPU.
void adam_update(float* p, const float* g, float* m, float* v, int n, const cpu::AdamParams& a,
                 int64_t step);

// Twin of cpu::mlp_loss_grad: the fused forward jets, losses and reverse pass of one batch
// (device pointers in `batch`), spread over blocks by chunks of points (the block path) or
// over warps by tiles of 8 points (the tensor-core path, Net-3); the gradient and the loss
// sums are reduced in a fixed order (per block in chunk or warp order, then in block order).
// grad (device) is overwritten when non-null. The stencil L_C is not implemented on the GPU.
cpu::LossValues mlp_loss_grad(const NetworkDesc& desc, const float* params,
                              const cpu::LossBatch<float>& batch, const cpu::LossOptions& opt,
                              float* grad, JetWorkspace& ws);

// For benchmarks: only the launches of mlp_loss_grad (no copy of the loss sums to the host).
void mlp_loss_grad_launch(const NetworkDesc& desc, const float* params, const cpu::LossBatch<float>& batch,
                          const cpu::LossOptions& opt, float* grad, JetWorkspace& ws);

// For tests: D = A B of one warp-level m16n8k8 TF32 MMA (A 16x8, B 8x8, D 16x8, row-major),
// its fragments loaded and stored by the layout cuda/mma_jet.cuh relies on; three = true runs
// the 3xTF32 split (big and small parts) instead of one TF32 MMA.
std::vector<float> mma_tf32_probe(const std::vector<float>& a, const std::vector<float>& b, bool three);

// The GPU's FP32 rate in FLOP/s (an FMA counts 2), measured with long independent FMA chains
// in every thread of a full grid (cuda/peak.cu).
double measure_fp32_peak();

// Event timer on the default stream (milliseconds between start() and stop()).
class EventTimer {
 public:
  EventTimer();
  ~EventTimer();
  EventTimer(const EventTimer&) = delete;
  EventTimer& operator=(const EventTimer&) = delete;
  void start();
  double stop_ms();  // synchronizes on the stop event

 private:
  void *a_ = nullptr, *b_ = nullptr;
};

// Blocks until the device is idle; rethrows any pending asynchronous error as CudaError.
void synchronize();

}  // namespace yarnhom::cuda
