#pragma once
// Forward and reverse mode over third-order jets of a small MLP, on the CPU.
//
// mlp_jet_forward propagates, for a batch of B points, the value of the network and all its
// input derivatives up to `order` (<= 3). A jet of a layer's pre-activations z is a set of C
// channels (core/jet_layout.hpp): z, z_i, z_ij, z_ijk. A linear layer maps every channel by
// the same W (the bias only enters channel 0), so one matrix product per layer carries the
// whole jet: Z = W A with A of shape [n_in, C*B], channel c of point p in column c*B + p.
// The sigmoid maps a jet to a jet by the chain rule (Faa di Bruno to third order):
//
//   a     = s0
//   a_i   = s1 z_i
//   a_ij  = s2 z_i z_j + s1 z_ij
//   a_ijk = s3 z_i z_j z_k + s2 (z_ij z_k + z_ik z_j + z_jk z_i) + s1 z_ijk
//
// with s_n the n-th derivative of the sigmoid at z:  s1 = s0(1-s0), s2 = s1(1-2 s0),
// s3 = s1(1 - 6 s0 + 6 s0^2), s4 = s1(1-2 s0)(1 - 12 s0 + 12 s0^2).
//
// mlp_jet_backward is the reverse mode of that computation: given dL/d(output jet), it adds
// dL/d(every weight and bias) into dparams, differentiating through all jet channels (which is
// why it needs s4). The CUDA twins in cuda/ have the same names, arguments and math.
#if defined(__CUDACC__)
#error "cpu/mlp_jet.hpp (Eigen) in a translation unit nvcc compiles: include cpu/loss_types.hpp instead (docs/layout.md, Compiler flags)"
#endif
#include <Eigen/Dense>
#include <vector>

#include "core/jet_layout.hpp"
#include "core/network.hpp"

namespace yarnhom::cpu {

template <class T>
using Mat = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;  // column-major

// Per-layer buffers of one forward pass, kept for the backward pass. Reused across calls
// (resized only when the batch grows), so a training step allocates nothing.
//
// The weights and inputs are copied into the workspace's own (aligned) matrices, and weight
// gradients are formed there before being added to the caller's buffer: Eigen's vectorized
// reductions split their sums by the alignment of the memory they read, so computing on
// caller-owned memory would make the last bits of the result depend on where the caller's
// allocator put it, and training would not be reproducible.
template <class T>
struct JetWorkspace {
  using RowMat = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  std::vector<RowMat> W;    // weights per layer, [out, in]
  std::vector<Eigen::Matrix<T, Eigen::Dynamic, 1>> b;
  RowMat X;                 // inputs [B, d]
  RowMat dW;                // one layer's weight gradient
  Eigen::Matrix<T, Eigen::Dynamic, 1> db;  // one layer's bias gradient (or channel sum)
  std::vector<Mat<T>> z;    // pre-activation jets per layer, [n_k, C*B]
  std::vector<Mat<T>> a;    // activation jets per hidden layer, [n_k, C*B]
  Mat<T> zbar, abar;        // adjoints, reused layer by layer
  int batch = 0, order = 0;
};

// x: [B, d] row-major inputs (normalized units). out: [C, B] output jet, channel-major
// (channel c of point p at out[c*B + p]), C = jet_channels(d, order).
template <class T>
void mlp_jet_forward(const NetworkDesc& desc, const T* params, const T* x, int batch, int order,
                     T* out, JetWorkspace<T>& ws);

// dout: [C, B] adjoint of the output jet. Adds the parameter gradient into dparams (same flat
// layout as params). Uses the workspace of the last mlp_jet_forward on the same inputs.
template <class T>
void mlp_jet_backward(const NetworkDesc& desc, const T* params, const T* x, int batch, int order,
                      const T* dout, T* dparams, JetWorkspace<T>& ws);

}  // namespace yarnhom::cpu
