// Twins of cpu::data_losses and cpu::strain_concentration_loss (cpu/losses.cpp): one thread
// per point on the device writes the point's loss terms and adds its adjoint into djet; the
// terms are summed on the host in point order (as on the CPU).
#include <cuda_runtime.h>

#include <cmath>
#include <cstddef>
#include <vector>

#include "core/jet_layout.hpp"
#include "cpu/losses.hpp"
#include "cuda/api.hpp"
#include "cuda/check.cuh"
#include "cuda/jet_shape.cuh"
#include "cuda/launch.cuh"

namespace yarnhom::cuda {

using namespace detail;

namespace {

// Per-point loss terms: 4 values per point (z, f, c, x) for data, 1 (s) for off-domain.
template <int D>
__global__ void data_loss_kernel(int B, int order, const float* jet, const float* y, const float* g,
                                 const float* wt, LossCfg cfg, int exact_c, float scale, float* djet,
                                 float* terms) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= B) return;
  const int C = jet_channels(D, order);
  const float wz = float(cfg.wz) * scale, wf = float(cfg.wf) * scale, wc = float(cfg.wc) * scale,
              wx = float(cfg.wx) * scale;
  auto ch = [&](int c) { return jet[size_t(c) * B + p]; };
  float lz = 0, lf = 0, lc = 0, lx = 0;
  const float k = wt ? wt[p] : 1.f;  // the point's weight on its L_Z and L_F residuals
  if (cfg.wz != 0) {
    const float r = ch(0) - y[p];
    lz = k * r * r;
    if (djet) djet[p] += wz * 2.f * k * r;
  }
  if (cfg.wf != 0)
    for (int i = 0; i < D; ++i) {
      const float r = ch(1 + i) - g[p * D + i];
      lf += k * r * r;
      if (djet) djet[size_t(1 + i) * B + p] += wf * 2.f * k * r;
    }
  if (cfg.wc != 0 && exact_c && order >= 3)
    for (int t = 0; t < jet_num_triples(D); ++t) {
      const int c = jet_first(D, 3) + t;
      const float v = ch(c);
      lc += fabsf(v);
      if (djet) djet[size_t(c) * B + p] += wc * float((v > 0) - (v < 0));
    }
  if (cfg.wx != 0 && order >= 2) {
    const int c0 = jet_first(D, 2);
    float lam, da = 1, db = 0, dc = 0;
    if (D == 1) {
      lam = ch(c0);
    } else {
      lam = cpu::min_eigenvalue_2x2<float>(ch(c0), ch(c0 + 1), ch(c0 + 2), &da, &db, &dc);
    }
    if (lam < 0) {
      lx = lam * lam;
      if (djet) {
        const float gl = wx * 2.f * lam;
        djet[size_t(c0) * B + p] += gl * da;
        if (D == 2) {
          djet[size_t(c0 + 1) * B + p] += gl * db;
          djet[size_t(c0 + 2) * B + p] += gl * dc;
        }
      }
    }
  }
  (void)C;
  terms[4 * size_t(p) + 0] = lz;
  terms[4 * size_t(p) + 1] = lf;
  terms[4 * size_t(p) + 2] = lc;
  terms[4 * size_t(p) + 3] = lx;
}

template <int D>
__global__ void strain_loss_kernel(int K, const float* jet, const float* normals, float weight_scale, float* djet,
                                   float* terms) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= K) return;
  float dot = 0;
  for (int i = 0; i < D; ++i) dot += jet[size_t(1 + i) * K + p] * normals[p * D + i];
  float l = 0;
  if (dot < 0) {
    l = dot * dot;
    if (djet)
      for (int i = 0; i < D; ++i) djet[size_t(1 + i) * K + p] += weight_scale * 2.f * dot * normals[p * D + i];
  }
  terms[p] = l;
}

}  // namespace

cpu::LossSums<float> data_losses(int d, int B, int order, const float* jet, const float* y, const float* g,
                                 const float* wt, const LossWeights& w, bool exact_c, float scale,
                                 float* djet) {
  cpu::LossSums<float> sum;
  if (B <= 0) return sum;
  DeviceVec<float> terms(size_t(B) * 4);
  cpu::LossOptions o;
  o.w = w;
  const LossCfg cfg = make_cfg(o, order);
  const int T = 128, G = (B + T - 1) / T;
  if (d == 1)
    data_loss_kernel<1><<<G, T>>>(B, order, jet, y, g, wt, cfg, exact_c, scale, djet, terms.data());
  else
    data_loss_kernel<2><<<G, T>>>(B, order, jet, y, g, wt, cfg, exact_c, scale, djet, terms.data());
  check(cudaGetLastError(), "launch of the data loss kernel");
  const std::vector<float> h = terms.download();
  for (int p = 0; p < B; ++p) {
    sum.z += h[4 * p + 0];
    sum.f += h[4 * p + 1];
    sum.c += h[4 * p + 2];
    sum.x += h[4 * p + 3];
  }
  return sum;
}

float strain_concentration_loss(int d, int K, int order, const float* jet, const float* normals,
                                float weight_scale, float* djet) {
  (void)order;
  if (K <= 0) return 0.f;
  DeviceVec<float> terms(K);
  const int T = 128, G = (K + T - 1) / T;
  if (d == 1)
    strain_loss_kernel<1><<<G, T>>>(K, jet, normals, weight_scale, djet, terms.data());
  else
    strain_loss_kernel<2><<<G, T>>>(K, jet, normals, weight_scale, djet, terms.data());
  check(cudaGetLastError(), "launch of the strain-concentration loss kernel");
  const std::vector<float> h = terms.download();
  float sum = 0;
  for (int p = 0; p < K; ++p) sum += h[p];
  return sum;
}

}  // namespace yarnhom::cuda
