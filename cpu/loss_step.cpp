#include "cpu/loss_step.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "core/jet_layout.hpp"
#include "cpu/flush_denormals.hpp"
#include "cpu/loss_stencil.hpp"
#include "cpu/losses.hpp"

namespace yarnhom::cpu {

namespace {

constexpr int kParallelMinPoints = 512;

// L_C by the stencil for the data points x[0..m): forward of the value at every tap, the
// stencil sums, |.|, and (with grad) the reverse pass through the value jets.
template <class T>
T stencil_c(const NetworkDesc& desc, const T* params, int m, const T* x, const LossOptions& opt,
            T adj_scale, T* grad, JetWorkspace<T>& jw, std::vector<T>& pts, std::vector<T>& val,
            std::vector<T>& dval) {
  const int d = desc.input_dim;
  const int triples = jet_num_triples(d);
  const int taps = d == 1 ? 4 : 20;
  const T eps = T(opt.stencil_eps);
  const int n = m * taps;
  pts.resize(size_t(n) * d);
  for (int p = 0; p < m; ++p) {
    int q = 0;
    for (int t = 0; t < triples; ++t) {
      const int nt = d == 1 ? 4 : kStencil2DTaps[t];
      for (int a = 0; a < nt; ++a, ++q) {
        const StencilTap tap = d == 1 ? kStencil1D[a] : kStencil2D[t][a];
        T* o = &pts[(size_t(p) * taps + q) * d];
        o[0] = x[p * d] + eps * T(tap.dx);
        if (d == 2) o[1] = x[p * d + 1] + eps * T(tap.dy);
      }
    }
  }
  val.resize(n);
  mlp_jet_forward<T>(desc, params, pts.data(), n, 0, val.data(), jw);
  const T inv = T(1) / (T(2) * eps * eps * eps);
  T sum = 0;
  if (grad) dval.assign(n, T(0));
  for (int p = 0; p < m; ++p) {
    int q = 0;
    for (int t = 0; t < triples; ++t) {
      const int nt = d == 1 ? 4 : kStencil2DTaps[t];
      T v = 0;
      for (int a = 0; a < nt; ++a) {
        const StencilTap tap = d == 1 ? kStencil1D[a] : kStencil2D[t][a];
        v += T(tap.coef) * val[size_t(p) * taps + q + a];
      }
      v *= inv;
      sum += std::abs(v);
      if (grad) {
        const T sg = T((v > 0) - (v < 0)) * adj_scale * inv;
        for (int a = 0; a < nt; ++a) {
          const StencilTap tap = d == 1 ? kStencil1D[a] : kStencil2D[t][a];
          dval[size_t(p) * taps + q + a] += sg * T(tap.coef);
        }
      }
      q += nt;
    }
  }
  if (grad) mlp_jet_backward<T>(desc, params, pts.data(), n, 0, dval.data(), grad, jw);
  return sum;
}

}  // namespace

template <class T>
LossValues mlp_loss_grad(const NetworkDesc& desc, const T* params, const LossBatch<T>& batch,
                         const LossOptions& opt, T* grad, LossWorkspace<T>& ws, int threads) {
  const int d = desc.input_dim;
  const int P = desc.num_params();
  const int order = data_jet_order(opt);
  const int C = jet_channels(d, order), C1 = jet_channels(d, 1);
  const int data_tasks = (batch.m + kLossChunk - 1) / kLossChunk;
  const bool off = batch.k > 0 && opt.w.s != 0;
  const int tasks = data_tasks + (off ? 1 : 0);
  const T inv_m = batch.m > 0 ? T(1) / T(batch.m) : T(0);
  const T inv_k = batch.k > 0 ? T(1) / T(batch.k) : T(0);
  const bool stencil = opt.stencil_c && opt.w.c != 0;

  // Per task: jet workspace, jets, adjoints, gradient, stencil buffers (3 vectors).
  const bool parallel = threads > 1 && tasks > 1 && batch.m + batch.k >= kParallelMinPoints;
  const int workers = parallel ? std::min(threads, tasks) : 1;
  // Jet buffers per worker thread (reused chunk after chunk); only the gradient is kept per
  // chunk, for the fixed-order sum.
  ws.jw.resize(workers);
  ws.jet.resize(workers);
  ws.djet.resize(workers);
  ws.pts.resize(3 * workers);
  ws.grad.resize(tasks);
  std::vector<LossSums<T>> sums(tasks);

  auto run_task = [&](int t, int w) {
    flush_denormals();
    T* g = nullptr;
    if (grad) {
      ws.grad[t].assign(P, T(0));
      g = ws.grad[t].data();
    }
    if (t < data_tasks) {
      const int begin = t * kLossChunk, n = std::min(kLossChunk, batch.m - begin);
      const T* x = batch.x + size_t(begin) * d;
      ws.jet[w].resize(size_t(C) * n);
      mlp_jet_forward<T>(desc, params, x, n, order, ws.jet[w].data(), ws.jw[w]);
      if (g) ws.djet[w].assign(size_t(C) * n, T(0));
      sums[t] = data_losses<T>(d, n, order, ws.jet[w].data(), batch.y + begin,
                               batch.g + size_t(begin) * d, batch.wt ? batch.wt + begin : nullptr,
                               opt.w, !stencil, inv_m,
                               g ? ws.djet[w].data() : nullptr);
      if (g) mlp_jet_backward<T>(desc, params, x, n, order, ws.djet[w].data(), g, ws.jw[w]);
      if (stencil)
        sums[t].c = stencil_c<T>(desc, params, n, x, opt, T(opt.w.c) * inv_m, g, ws.jw[w],
                                 ws.pts[3 * w], ws.pts[3 * w + 1], ws.pts[3 * w + 2]);
    } else {
      const int K = batch.k;
      ws.jet[w].resize(size_t(C1) * K);
      mlp_jet_forward<T>(desc, params, batch.xo, K, 1, ws.jet[w].data(), ws.jw[w]);
      if (g) ws.djet[w].assign(size_t(C1) * K, T(0));
      sums[t].s = strain_concentration_loss<T>(d, K, 1, ws.jet[w].data(), batch.no,
                                               T(opt.w.s) * inv_k, g ? ws.djet[w].data() : nullptr);
      if (g) mlp_jet_backward<T>(desc, params, batch.xo, K, 1, ws.djet[w].data(), g, ws.jw[w]);
    }
  };

  // A parallel region costs microseconds (far more when the cores are shared), as much as a
  // whole small batch: spread only batches large enough to pay for it.
  if (parallel) {
#pragma omp parallel for num_threads(workers) schedule(dynamic, 1)
    for (int t = 0; t < tasks; ++t) run_task(t, omp_get_thread_num());
  } else {
    for (int t = 0; t < tasks; ++t) run_task(t, 0);
  }

  // Reduce in task order: the result is the same for any thread count.
  LossSums<T> tot;
  for (int t = 0; t < tasks; ++t) {
    tot.z += sums[t].z;
    tot.f += sums[t].f;
    tot.c += sums[t].c;
    tot.s += sums[t].s;
    tot.x += sums[t].x;
  }
  if (grad && tasks == 0) std::fill(grad, grad + P, T(0));
  if (grad && tasks > 0) {
    std::copy(ws.grad[0].begin(), ws.grad[0].end(), grad);
    for (int t = 1; t < tasks; ++t)
      for (int i = 0; i < P; ++i) grad[i] += ws.grad[t][i];
  }
  LossValues v;
  v.z = double(tot.z) * double(inv_m);
  v.f = double(tot.f) * double(inv_m);
  v.c = double(tot.c) * double(inv_m);
  v.x = double(tot.x) * double(inv_m);
  v.s = double(tot.s) * double(inv_k);
  v.total = opt.w.z * v.z + opt.w.f * v.f + opt.w.c * v.c + opt.w.s * v.s + opt.w.x * v.x;
  return v;
}

template LossValues mlp_loss_grad<float>(const NetworkDesc&, const float*, const LossBatch<float>&,
                                         const LossOptions&, float*, LossWorkspace<float>&, int);
template LossValues mlp_loss_grad<double>(const NetworkDesc&, const double*,
                                          const LossBatch<double>&, const LossOptions&, double*,
                                          LossWorkspace<double>&, int);

}  // namespace yarnhom::cpu
