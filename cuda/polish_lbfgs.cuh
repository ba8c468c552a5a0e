#pragma once
// The L-BFGS of the polish on the device (twin of train/lbfgs.hpp's lbfgs_minimize and of
// train/polish.cpp's polish_in), run by one thread-block cluster per network: the kernel and
// its host driver are train/cuda_polish.cu, which explains the scheme; the loss is
// cuda/polish_jet.cuh's. Device code only (and the plain structs the host fills).
#include <cooperative_groups.h>

#include <cmath>
#include <cstddef>

#include "cuda/polish_jet.cuh"

namespace yarnhom::cuda::polish {

using namespace detail;
namespace cg = cooperative_groups;

constexpr int kMaxMemory = 32;
constexpr int kThreads = 256;
constexpr int kMaxCluster = 8;
constexpr int kPenSlot = 60;  // red[60 + parity]: the rest penalty; red[0..47]: block_sum's scratch

enum Stop : int { kNone = 0, kNonFiniteStart, kZeroGradient, kNoProgress, kConverged, kLimit };

struct PolOut {
  int iterations, evaluations, best_iteration, stop;
  double f0, val_start, val_best;
  long long cycles[4];  // SM clock cycles of block 0 in: the direction, the line search's
                        // evaluations, the validation loss, the rest (YARNHOM_CUDA_POLISH_PROFILE)
};

// One network's problem and buffers (device pointers; x etc. hold T).
struct PolNet {
  NetShape s;
  int dbl;  // T = double
  int n_train, n_val, max_iter, memory, keep_best, rest;
  double wz, wf, rest_w, rest_k, x_rest;
  double c1, c2, rel_tol;
  int max_search;
  const void *x, *y, *g, *wt, *xv, *yv, *gv, *wtv;
  const float* p0;
  double* vec;  // per block: the history pairs S, Y [memory][P]
  float* best;  // [P]
  double *train_loss, *val_loss;  // [max_iter]
  PolOut* out;
};

// Sum of v over the block, the same value in every thread (fixed order: lane-strided, a
// shuffle-down tree per warp, the warps in order). N <= 3 values at once. One barrier: the
// scratch alternates between two halves (rp counts the reductions, the same in every thread), so
// a fast thread writing the next reduction's partials never meets a slow one still reading.
template <int N>
__device__ void block_sum(double (&v)[N], double* red, unsigned& rp) {
  const int lane = threadIdx.x & 31, wid = threadIdx.x >> 5, nw = blockDim.x >> 5;
  double* buf = red + (rp & 1) * 24;
  ++rp;
#pragma unroll
  for (int q = 0; q < N; ++q) {
    for (int o = 16; o > 0; o >>= 1) v[q] += __shfl_down_sync(0xffffffffu, v[q], o);
    if (lane == 0) buf[wid * N + q] = v[q];
  }
  __syncthreads();
#pragma unroll
  for (int q = 0; q < N; ++q) {
    double t = 0;
    for (int w = 0; w < nw; ++w) t += buf[w * N + q];
    v[q] = t;
  }
}

__device__ double block_dot(const double* a, const double* b, int n, double* red, unsigned& rp) {
  double v[1] = {0};
  for (int i = threadIdx.x; i < n; i += blockDim.x) v[0] += a[i] * b[i];
  block_sum<1>(v, red, rp);
  return v[0];
}

// The two-loop recursion p = -H g with each thread's entries (i = tid + k blockDim.x, k < K) in
// registers: a pass loads its K entries of a history vector at once (one memory latency per pass
// rather than one per entry: with a plain strided loop over global memory the recursion's 41
// passes were most of an iteration's time), then one block reduction. The sums are those of the
// strided loops (entry order within a thread, then the block tree), for any K.
template <int K>
__device__ void two_loop_regs(double* p, const double* g, const double* Sb, const double* Yb, const double* rho,
                              int head, int count, int M, int P, double* red, unsigned& rp) {
  const int tid = threadIdx.x, bd = blockDim.x;
  double q[K], a[K], b[K], alpha[kMaxMemory];
#pragma unroll
  for (int k = 0; k < K; ++k) {
    const int i = tid + k * bd;
    q[k] = i < P ? -g[i] : 0.0;
  }
  auto load = [&](const double* s, const double* y) {
#pragma unroll
    for (int k = 0; k < K; ++k) {
      const int i = tid + k * bd;
      a[k] = i < P ? s[i] : 0.0;
      b[k] = i < P ? y[i] : 0.0;
    }
  };
  for (int ii = count - 1; ii >= 0; --ii) {
    const int sl = (head + ii) % M;
    load(Sb + size_t(sl) * P, Yb + size_t(sl) * P);
    double v[1] = {0};
#pragma unroll
    for (int k = 0; k < K; ++k) v[0] += a[k] * q[k];
    block_sum<1>(v, red, rp);
    alpha[ii] = rho[sl] * v[0];
#pragma unroll
    for (int k = 0; k < K; ++k) q[k] -= alpha[ii] * b[k];
  }
  if (count > 0) {
    const int sl = (head + count - 1) % M;
    load(Sb + size_t(sl) * P, Yb + size_t(sl) * P);
    double sy2[2] = {0, 0};
#pragma unroll
    for (int k = 0; k < K; ++k) sy2[0] += a[k] * b[k], sy2[1] += b[k] * b[k];
    block_sum<2>(sy2, red, rp);
    const double scale = sy2[0] / sy2[1];
#pragma unroll
    for (int k = 0; k < K; ++k) q[k] *= scale;
  }
  for (int ii = 0; ii < count; ++ii) {
    const int sl = (head + ii) % M;
    load(Sb + size_t(sl) * P, Yb + size_t(sl) * P);
    double v[1] = {0};
#pragma unroll
    for (int k = 0; k < K; ++k) v[0] += b[k] * q[k];
    block_sum<1>(v, red, rp);
    const double beta = rho[sl] * v[0];
#pragma unroll
    for (int k = 0; k < K; ++k) q[k] += (alpha[ii] - beta) * a[k];
  }
#pragma unroll
  for (int k = 0; k < K; ++k) {
    const int i = tid + k * bd;
    if (i < P) p[i] = q[k];
  }
}

// The per-block state of one polish.
template <class T>
struct Ctx {
  const PolNet* n;
  int rank, CB, P;
  T* W;
  T* G[2];
  T* sums;  // [2][4]
  PolishChunk<T> ch;
  double* red;
  unsigned q;  // collectives done (parity of the buffers)
  unsigned rp;  // block reductions done (block_sum)
};

// The polish's loss at xs (double, cast to T as the CPU's to_float does) over the training or
// the validation split, collective over the cluster; with gout, its gradient (double).
template <class T, int D>
__device__ double cluster_loss(Ctx<T>& c, const double* xs, bool train, double* gout) {
  constexpr int NP = polish_np<T>();
  cg::cluster_group cl = cg::this_cluster();
  const PolNet& n = *c.n;
  const int par = c.q & 1;
  T* G = c.G[par];
  T* sum = c.sums + 4 * par;
  const bool grad = gout != nullptr;
  for (int i = threadIdx.x; i < c.P; i += blockDim.x) {
    c.W[i] = T(xs[i]);
    G[i] = T(0);
  }
  if (threadIdx.x < 4) sum[threadIdx.x] = T(0);
  const int m = train ? n.n_train : n.n_val;
  const T* x = static_cast<const T*>(train ? n.x : n.xv);
  const T* y = static_cast<const T*>(train ? n.y : n.yv);
  const T* g = static_cast<const T*>(train ? n.g : n.gv);
  const T* wt = static_cast<const T*>(train ? n.wt : n.wtv);
  const T inv_m = m > 0 ? T(1) / T(m) : T(0);
  const T wz = T(n.wz) * inv_m, wf = T(n.wf) * inv_m;
  __syncthreads();
  const int chunks = (m + NP - 1) / NP;
  for (int t = c.rank; t < chunks; t += c.CB) {
    const int begin = t * NP, np = min(NP, m - begin);
    for (int p = threadIdx.x; p < np; p += blockDim.x) {
      c.ch.y[p] = y[begin + p];
      c.ch.wt[p] = wt ? wt[begin + p] : T(1);
#pragma unroll
      for (int i = 0; i < D; ++i) {
        c.ch.x[p * D + i] = x[size_t(begin + p) * D + i];
        c.ch.g[p * D + i] = g[size_t(begin + p) * D + i];
      }
    }
    __syncthreads();
    polish_chunk_forward<T, D>(n.s, c.W, np, c.ch);
    polish_chunk_losses<T, D>(np, c.ch, wz, wf, n.wz != 0, n.wf != 0, grad, sum);
    __syncthreads();
    if (grad) polish_chunk_backward<T, D>(n.s, c.W, np, c.ch, G);
  }
  // The rest penalty on the last block, which holds no chunk when the chunks are fewer than the
  // blocks (the 1D terms: 3 chunks of 32 points, 8 blocks).
  if (D == 1 && n.rest && c.rank == c.CB - 1) {
    const double pen = polish_rest_penalty_1d<T>(n.s, c.W, T(n.x_rest), n.rest_k, n.rest_w, grad ? G : nullptr,
                                                 c.ch.rest);
    if (threadIdx.x == 0) c.red[kPenSlot + par] = pen;  // in double, parity-buffered as the sums
  }
  cl.sync();  // every block's partial gradient and sums are complete
  T tz = T(0), tf = T(0);
  for (int r = 0; r < c.CB; ++r) {
    const T* q = cl.map_shared_rank(c.sums + 4 * par, r);
    tz += q[0];
    tf += q[1];
  }
  double pen = 0;
  if (D == 1 && n.rest) {
    // The penalty in double, from the last block (written before the barrier).
    pen = *cl.map_shared_rank(c.red + kPenSlot + par, c.CB - 1);
  }
  if (grad)
    for (int i = threadIdx.x; i < c.P; i += blockDim.x) {
      T s = T(0);
      for (int r = 0; r < c.CB; ++r) s = r == 0 ? cl.map_shared_rank(G, r)[i] : s + cl.map_shared_rank(G, r)[i];
      gout[i] = double(s);
    }
  ++c.q;
  __syncthreads();
  const double vz = double(tz) * double(inv_m), vf = double(tf) * double(inv_m);
  return n.wz * vz + n.wf * vf + pen;
}

template <class T, int D>
__device__ void polish_body(const PolNet& n, double* smd, double* red) {
  cg::cluster_group cl = cg::this_cluster();
  const PolishLayout L = polish_layout<T>(n.s);
  const int P4 = (n.s.P + 3) & ~3;
  T* sm = reinterpret_cast<T*>(smd + 5 * P4);  // after the optimizer's vectors
  Ctx<T> c;
  c.n = &n;
  c.rank = int(cl.block_rank());
  c.CB = int(cl.num_blocks());
  c.P = n.s.P;
  c.W = sm + L.w;
  c.G[0] = sm + L.g0;
  c.G[1] = sm + L.g1;
  c.sums = sm + L.sums;
  c.ch = make_polish_chunk<T>(sm, L);
  c.red = red;
  c.q = 0;
  c.rp = 0;
  unsigned& rp = c.rp;
  const int P = c.P, M = n.memory, tid = threadIdx.x, bd = blockDim.x;
  // x, g, the direction and the trial point in shared memory; the history pairs in global memory.
  double *x = smd, *g = x + P4, *p = g + P4, *xt = p + P4, *gt = xt + P4;
  double* Sb = n.vec + size_t(c.rank) * size_t(2 * M) * P;
  double* Yb = Sb + size_t(M) * P;
  __shared__ double rho[kMaxMemory];
  const bool lead = c.rank == 0 && tid == 0;

  for (int i = tid; i < P; i += bd) {
    x[i] = double(n.p0[i]);
    if (c.rank == 0) n.best[i] = n.p0[i];
  }
  __syncthreads();
  double best_val = cluster_loss<T, D>(c, x, false, nullptr);
  const double val_start = best_val;
  int best_iter = 0, evaluations = 0, iterations = 0, stop = kNone;
  double f = cluster_loss<T, D>(c, x, true, g);
  ++evaluations;
  const double f0 = f;
  {
    double bad[1] = {0};
    for (int i = tid; i < P; i += bd) bad[0] += isfinite(g[i]) ? 0.0 : 1.0;
    block_sum<1>(bad, red, rp);
    if (!isfinite(f) || bad[0] > 0) stop = kNonFiniteStart;
  }
  int head = 0, count = 0;  // the history ring: pair i (0 = oldest) in slot (head + i) % M
  auto slot = [&](int i) { return (head + i) % M; };

  long long cyc[4] = {0, 0, 0, 0}, t_mark = clock64();
  auto lap = [&](int phase) {  // time since the last mark goes to `phase` (thread 0 of block 0)
    const long long now = clock64();
    cyc[phase] += now - t_mark;
    t_mark = now;
  };
  for (int k = 0; k < n.max_iter && stop == kNone; ++k) {
    lap(3);
    // p = -H g: the two-loop recursion, every thread on its own entries (no barrier but those
    // of the dot products); in registers up to 8 entries a thread.
    if (P <= 4 * bd) two_loop_regs<4>(p, g, Sb, Yb, rho, head, count, M, P, red, rp);
    else if (P <= 5 * bd) two_loop_regs<5>(p, g, Sb, Yb, rho, head, count, M, P, red, rp);
    else if (P <= 8 * bd) two_loop_regs<8>(p, g, Sb, Yb, rho, head, count, M, P, red, rp);
    else {
      double alpha[kMaxMemory];
      for (int i = tid; i < P; i += bd) p[i] = -g[i];
      for (int i = count - 1; i >= 0; --i) {
        const double* s = Sb + size_t(slot(i)) * P;
        const double* y = Yb + size_t(slot(i)) * P;
        alpha[i] = rho[slot(i)] * block_dot(s, p, P, red, rp);
        for (int j = tid; j < P; j += bd) p[j] -= alpha[i] * y[j];
      }
      if (count > 0) {
        const double* s = Sb + size_t(slot(count - 1)) * P;
        const double* y = Yb + size_t(slot(count - 1)) * P;
        double sy2[2] = {0, 0};
        for (int j = tid; j < P; j += bd) sy2[0] += s[j] * y[j], sy2[1] += y[j] * y[j];
        block_sum<2>(sy2, red, rp);
        const double scale = sy2[0] / sy2[1];
        for (int j = tid; j < P; j += bd) p[j] *= scale;
      }
      for (int i = 0; i < count; ++i) {
        const double* s = Sb + size_t(slot(i)) * P;
        const double* y = Yb + size_t(slot(i)) * P;
        const double beta = rho[slot(i)] * block_dot(y, p, P, red, rp);
        for (int j = tid; j < P; j += bd) p[j] += (alpha[i] - beta) * s[j];
      }
    }
    __syncthreads();
    lap(0);
    double dg0 = block_dot(g, p, P, red, rp);
    if (!(dg0 < 0)) {  // not a descent direction (rounding): restart from steepest descent
      count = 0;
      head = 0;
      for (int i = tid; i < P; i += bd) p[i] = -g[i];
      __syncthreads();
      dg0 = -block_dot(g, g, P, red, rp);
      if (!(dg0 < 0)) {
        stop = kZeroGradient;
        break;
      }
    }
    double a = 1.0;
    if (k == 0 && count == 0) {
      double l1[1] = {0};
      for (int i = tid; i < P; i += bd) l1[0] += fabs(g[i]);
      block_sum<1>(l1, red, rp);
      a = fmin(1.0, 1.0 / l1[0]);
    }
    auto eval = [&](double step, double& fv, double& dv) {
      lap(3);
      for (int i = tid; i < P; i += bd) xt[i] = x[i] + step * p[i];
      __syncthreads();
      fv = cluster_loss<T, D>(c, xt, true, gt);
      ++evaluations;
      dv = block_dot(gt, p, P, red, rp);
      lap(1);
      return isfinite(fv) && isfinite(dv);
    };
    // Strong-Wolfe line search: bracket, then zoom (train/lbfgs.hpp, line for line).
    double a_prev = 0, f_prev = f, d_prev = dg0;
    double a_lo = 0, f_lo = f, d_lo = dg0, a_hi = 0, f_hi = 0, d_hi = 0;
    bool found = false, zoom = false;
    int evals = 0;
    double fa = 0, da = 0;
    while (evals < n.max_search) {
      ++evals;
      const bool finite = eval(a, fa, da);
      if (!finite || fa > f + n.c1 * a * dg0 || (evals > 1 && fa >= f_prev)) {
        if (!finite) {
          fa = INFINITY;
          da = INFINITY;
        }
        a_lo = a_prev, f_lo = f_prev, d_lo = d_prev;
        a_hi = a, f_hi = fa, d_hi = da;
        zoom = true;
        break;
      }
      if (fabs(da) <= -n.c2 * dg0) {
        found = true;
        break;
      }
      if (da >= 0) {
        a_lo = a, f_lo = fa, d_lo = da;
        a_hi = a_prev, f_hi = f_prev, d_hi = d_prev;
        zoom = true;
        break;
      }
      a_prev = a, f_prev = fa, d_prev = da;
      a *= 2;
    }
    while (zoom && !found && evals < n.max_search) {
      ++evals;
      const double lo = fmin(a_lo, a_hi), hi = fmax(a_lo, a_hi), w = hi - lo;
      // cubic_step of train/lbfgs.hpp
      double trial = 0.5 * (a_lo + a_hi);
      if (isfinite(f_hi) && isfinite(d_hi)) {
        const double d1 = d_lo + d_hi - 3 * (f_lo - f_hi) / (a_lo - a_hi);
        const double disc = d1 * d1 - d_lo * d_hi;
        if (disc >= 0) {
          const double d2 = copysign(sqrt(disc), a_hi - a_lo);
          const double cc = a_hi - (a_hi - a_lo) * (d_hi + d2 - d1) / (d_hi - d_lo + 2 * d2);
          if (isfinite(cc)) trial = cc;
        }
      }
      a = fmin(fmax(trial, lo + 0.1 * w), hi - 0.1 * w);
      const bool finite = eval(a, fa, da);
      if (!finite || fa > f + n.c1 * a * dg0 || fa >= f_lo) {
        a_hi = a, f_hi = finite ? fa : INFINITY, d_hi = finite ? da : INFINITY;
      } else {
        if (fabs(da) <= -n.c2 * dg0) {
          found = true;
          break;
        }
        if (da * (a_hi - a_lo) >= 0) a_hi = a_lo, f_hi = f_lo, d_hi = d_lo;
        a_lo = a, f_lo = fa, d_lo = da;
      }
      if (w < 1e-14 * fmax(1.0, hi)) break;
    }
    if (!found) {
      if (a_lo > 0 && f_lo < f) {
        a = a_lo;
        eval(a, fa, da);
      } else {
        stop = kNoProgress;
        break;
      }
    }
    // Accept: the pair (s, y) = (xt - x, gt - g) joins the history when s.y > 1e-12 |s| |y|.
    double sy3[3] = {0, 0, 0};
    for (int i = tid; i < P; i += bd) {
      const double si = xt[i] - x[i], yi = gt[i] - g[i];
      sy3[0] += si * yi, sy3[1] += si * si, sy3[2] += yi * yi;
    }
    block_sum<3>(sy3, red, rp);
    const bool keep = sy3[0] > 1e-12 * sqrt(sy3[1]) * sqrt(sy3[2]);
    int sl = -1;
    if (keep) {
      if (count == M) {
        sl = head;
        head = (head + 1) % M;
      } else {
        sl = slot(count);
        ++count;
      }
      if (tid == 0) rho[sl] = 1.0 / sy3[0];
    }
    for (int i = tid; i < P; i += bd) {
      if (keep) {
        Sb[size_t(sl) * P + i] = xt[i] - x[i];
        Yb[size_t(sl) * P + i] = gt[i] - g[i];
      }
      x[i] = xt[i];
      g[i] = gt[i];
    }
    __syncthreads();
    const double f_old = f;
    f = fa;
    iterations = k + 1;
    // The observer of polish_in: the validation data loss of the iterate, the best one kept.
    lap(3);
    const double v = cluster_loss<T, D>(c, x, false, nullptr);
    lap(2);
    if (lead) {
      n.train_loss[k] = f;
      n.val_loss[k] = v;
    }
    if (!n.keep_best || v < best_val || !isfinite(best_val)) {
      best_val = v;
      best_iter = k + 1;
      if (c.rank == 0)
        for (int i = tid; i < P; i += bd) n.best[i] = float(T(x[i]));
    }
    if (f_old - f <= n.rel_tol * fabs(f)) stop = kConverged;
  }
  if (stop == kNone) stop = kLimit;
  lap(3);
  if (lead) *n.out = PolOut{iterations, evaluations, best_iter, stop, f0, val_start, best_val, {cyc[0], cyc[1], cyc[2], cyc[3]}};
  cl.sync();  // no block leaves while another may still read its shared memory
}


}  // namespace yarnhom::cuda::polish
