#pragma once
// The plain types of one loss evaluation (cpu/loss_step.hpp): its batch, options and values.
// No Eigen here: the CUDA sources (cuda/api.hpp, train/backend.hpp) include this header and not
// cpu/loss_step.hpp, so that no translation unit nvcc compiles instantiates Eigen's host code
// (docs/layout.md, "Compiler flags").
#include "core/network.hpp"

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

// The jet order the data points need for these options.
inline int data_jet_order(const LossOptions& opt) {
  if (opt.w.c != 0 && !opt.stencil_c) return 3;
  if (opt.w.x != 0) return 2;
  return 1;
}

}  // namespace yarnhom::cpu
