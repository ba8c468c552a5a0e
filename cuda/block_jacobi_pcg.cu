// The GPU twin of numerics/block_jacobi_pcg.cpp. One iteration is five launches:
//   spmv_dot    q = A p (a warp per row) and the blocks' partial sums of p.q
//   finish_pq   alpha = (r.z) / (p.q), or stop on p.q <= 0 (breakdown)
//   update      x += alpha p, r -= alpha q, z = M^-1 r (a thread per vertex), partial r.z, r.r
//   finish_rz   stop when |r| <= tol |b|, else beta = (r.z)_new / (r.z)_old
//   update_p    p = z + beta p
// The scalars live on the device, so the host launches a batch of iterations without waiting and
// reads the stop flag once per batch; every kernel returns at once after the stop. A batch is a
// CUDA graph (captured once per pattern, the buffers it names fixed until the next), launched
// as one: the 40 kernels run without a host launch between them. The reductions
// have a fixed shape (the same sums in the same order every run): bit-identical reruns.
#include <cuda_runtime.h>

#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "cuda/block_jacobi_pcg.hpp"
#include "cuda/check.cuh"
#include "numerics/spd3_inverse.hpp"

namespace yarnhom::cuda {

namespace {

constexpr int kThreads = 256;
constexpr int kBatch = 8;  // iterations launched between two reads of the stop flag

struct Scalars {
  double rz, rr, bn2, tol2, alpha, beta;
  int done, breakdown, iterations;
};

// Sum of v over the block, in thread 0 (fixed order).
__device__ double block_sum(double v, double* sh) {
  for (int o = 16; o > 0; o >>= 1) v += __shfl_down_sync(0xffffffffu, v, o);
  const int warp = threadIdx.x / 32, lane = threadIdx.x % 32;
  if (lane == 0) sh[warp] = v;
  __syncthreads();
  double s = 0;
  if (threadIdx.x == 0)
    for (int w = 0; w < blockDim.x / 32; ++w) s += sh[w];
  __syncthreads();
  return s;
}

__global__ void spmv_dot(int n, const int* __restrict__ rp, const int* __restrict__ ci, const double* __restrict__ v,
                         const double* __restrict__ p, double* __restrict__ q, double* __restrict__ part,
                         const Scalars* s) {
  __shared__ double sh[kThreads / 32];
  if (s->done) return;
  const int row = blockIdx.x * (kThreads / 32) + threadIdx.x / 32, lane = threadIdx.x % 32;
  double pq = 0;
  if (row < n) {
    double acc = 0;
    for (int k = rp[row] + lane; k < rp[row + 1]; k += 32) acc += v[k] * p[ci[k]];
    for (int o = 16; o > 0; o >>= 1) acc += __shfl_down_sync(0xffffffffu, acc, o);
    if (lane == 0) {
      q[row] = acc;
      pq = acc * p[row];
    }
  }
  const double t = block_sum(pq, sh);
  if (threadIdx.x == 0) part[blockIdx.x] = t;
}

__global__ void finish_pq(const double* __restrict__ part, int parts, Scalars* s) {
  __shared__ double sh[kThreads / 32];
  if (s->done) return;
  double v = 0;
  for (int i = threadIdx.x; i < parts; i += blockDim.x) v += part[i];
  const double pq = block_sum(v, sh);
  if (threadIdx.x == 0) {
    if (!(pq > 0)) {
      s->breakdown = 1;
      s->done = 1;
    } else {
      s->alpha = s->rz / pq;
    }
  }
}

// z = M^-1 r for vertex k; returns r.z and r.r of its three rows.
__device__ void precondition(int k, const double* __restrict__ bi, const double* r, double* z, double& rz, double& rr) {
  const double* B = bi + 9 * k;
  const double r0 = r[3 * k], r1 = r[3 * k + 1], r2 = r[3 * k + 2];
  const double z0 = B[0] * r0 + B[1] * r1 + B[2] * r2;
  const double z1 = B[3] * r0 + B[4] * r1 + B[5] * r2;
  const double z2 = B[6] * r0 + B[7] * r1 + B[8] * r2;
  z[3 * k] = z0, z[3 * k + 1] = z1, z[3 * k + 2] = z2;
  rz = r0 * z0 + r1 * z1 + r2 * z2;
  rr = r0 * r0 + r1 * r1 + r2 * r2;
}

__global__ void start(int nb, const double* __restrict__ bi, const double* __restrict__ r, double* __restrict__ z,
                      double* __restrict__ p, double* __restrict__ x, double* __restrict__ part_rz,
                      double* __restrict__ part_rr) {
  __shared__ double sh[kThreads / 32];
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  double rz = 0, rr = 0;
  if (k < nb) {
    precondition(k, bi, r, z, rz, rr);
    for (int i = 0; i < 3; ++i) p[3 * k + i] = z[3 * k + i], x[3 * k + i] = 0;
  }
  const double a = block_sum(rz, sh);
  const double b = block_sum(rr, sh);
  if (threadIdx.x == 0) part_rz[blockIdx.x] = a, part_rr[blockIdx.x] = b;
}

__global__ void finish_start(const double* part_rz, const double* part_rr, int parts, double tol, Scalars* s) {
  __shared__ double sh[kThreads / 32];
  double a = 0, b = 0;
  for (int i = threadIdx.x; i < parts; i += blockDim.x) a += part_rz[i], b += part_rr[i];
  a = block_sum(a, sh);
  b = block_sum(b, sh);
  if (threadIdx.x == 0) {
    s->rz = a, s->rr = b, s->bn2 = b, s->tol2 = tol * tol;
    s->done = b > 0 ? 0 : 1;
    s->breakdown = 0, s->iterations = 0;
  }
}

__global__ void update(int nb, const double* __restrict__ bi, const double* __restrict__ p,
                       const double* __restrict__ q, double* __restrict__ x, double* __restrict__ r,
                       double* __restrict__ z, double* __restrict__ part_rz, double* __restrict__ part_rr,
                       const Scalars* s) {
  __shared__ double sh[kThreads / 32];
  if (s->done) return;
  const double alpha = s->alpha;
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  double rz = 0, rr = 0;
  if (k < nb) {
    for (int i = 3 * k; i < 3 * k + 3; ++i) x[i] += alpha * p[i], r[i] -= alpha * q[i];
    precondition(k, bi, r, z, rz, rr);
  }
  const double a = block_sum(rz, sh);
  const double b = block_sum(rr, sh);
  if (threadIdx.x == 0) part_rz[blockIdx.x] = a, part_rr[blockIdx.x] = b;
}

__global__ void finish_rz(const double* part_rz, const double* part_rr, int parts, Scalars* s) {
  __shared__ double sh[kThreads / 32];
  if (s->done) return;
  double a = 0, b = 0;
  for (int i = threadIdx.x; i < parts; i += blockDim.x) a += part_rz[i], b += part_rr[i];
  a = block_sum(a, sh);
  b = block_sum(b, sh);
  if (threadIdx.x == 0) {
    ++s->iterations;
    s->rr = b;
    if (b <= s->tol2 * s->bn2) {
      s->done = 1;
    } else {
      s->beta = a / s->rz;
      s->rz = a;
    }
  }
}

__global__ void update_p(int n, const double* __restrict__ z, double* __restrict__ p, const Scalars* s) {
  if (s->done) return;
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) p[i] = z[i] + s->beta * p[i];
}

// The system from one triangle's values (PcgDevice::upload_triangle): entry k to its row's slot
// and its mirror's, and to both places of its diagonal block (blocks zeroed before).
__global__ void scatter_triangle(int nnz, const double* __restrict__ t, const int* __restrict__ pos,
                                 const int* __restrict__ mirror, const int* __restrict__ diag, double* __restrict__ v,
                                 double* __restrict__ blocks) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= nnz) return;
  const double x = t[k];
  v[pos[k]] = x;
  if (mirror[k] >= 0) v[mirror[k]] = x;
  const int d = diag[k];
  if (d >= 0) {
    const int b = d / 9, i = (d % 9) / 3, j = d % 3;
    blocks[9 * b + 3 * i + j] = x;
    blocks[9 * b + 3 * j + i] = x;
  }
}

// Each diagonal block inverted in place (numerics/spd3_inverse.hpp, as on the CPU); *failed = 1
// where one is not positive definite.
__global__ void invert_blocks(int nb, double* __restrict__ blocks, int* failed) {
  const int b = blockIdx.x * blockDim.x + threadIdx.x;
  if (b >= nb) return;
  if (!numerics::spd3_inverse(blocks + 9 * b, blocks + 9 * b)) *failed = 1;
}


class DevicePcg final : public numerics::PcgDevice {
 public:
  DevicePcg() {
    int count = 0;
    if (cudaGetDeviceCount(&count) != cudaSuccess || count == 0)
      throw CudaError("--solver pcg-cuda: no CUDA GPU can be used (cudaGetDeviceCount)");
    cudaDeviceProp prop{};
    check(cudaGetDeviceProperties(&prop, 0), "cudaGetDeviceProperties");
    name_ = std::string("pcg-cuda (block Jacobi, ") + prop.name + ")";
    check(cudaMalloc(&s_, sizeof(Scalars)), "cudaMalloc (PCG scalars)");
    // Everything of the solver on its own stream (uploads included: a copy from pageable memory
    // may return before its DMA ends, so the kernels must be ordered after it on one stream).
    check(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), "cudaStreamCreate (PCG)");
  }
  ~DevicePcg() override {
    if (graph_) cudaGraphExecDestroy(graph_);
    if (stream_) cudaStreamDestroy(stream_);
    for (void* p : {(void*)rp_, (void*)ci_, (void*)v_, (void*)bi_, (void*)x_, (void*)r_, (void*)z_, (void*)p_,
                    (void*)q_, (void*)pa_, (void*)pb_, (void*)s_, (void*)tri_, (void*)pos_, (void*)mir_, (void*)dg_,
                    (void*)failed_})
      if (p) cudaFree(p);
  }

  void upload(const numerics::BlockCsr& A) override {
    pattern(A);
    check(cudaMemcpyAsync(v_, A.val.data(), sizeof(double) * A.val.size(), cudaMemcpyHostToDevice, stream_),
          "cudaMemcpy (PCG values)");
    check(cudaMemcpyAsync(bi_, A.block_inv.data(), sizeof(double) * A.block_inv.size(), cudaMemcpyHostToDevice, stream_),
          "cudaMemcpy (PCG block inverses)");
  }

  bool upload_triangle(const numerics::BlockCsr& A, const numerics::TriangleMap& map, const double* values,
                       int nnz) override {
    pattern(A);
    if (map_id_ != A.pattern_id || tri_n_ != nnz) {
      map_id_ = A.pattern_id;
      tri_n_ = nnz;
      alloc(tri_, nnz, "cudaMalloc (PCG triangle)");
      alloc(pos_, nnz, "cudaMalloc (PCG map)");
      alloc(mir_, nnz, "cudaMalloc (PCG map)");
      alloc(dg_, nnz, "cudaMalloc (PCG map)");
      check(cudaMemcpyAsync(pos_, map.pos.data(), sizeof(int) * nnz, cudaMemcpyHostToDevice, stream_), "cudaMemcpy (PCG map)");
      check(cudaMemcpyAsync(mir_, map.mirror.data(), sizeof(int) * nnz, cudaMemcpyHostToDevice, stream_),
            "cudaMemcpy (PCG map)");
      check(cudaMemcpyAsync(dg_, map.diag.data(), sizeof(int) * nnz, cudaMemcpyHostToDevice, stream_), "cudaMemcpy (PCG map)");
    }
    if (!failed_) check(cudaMalloc(&failed_, sizeof(int)), "cudaMalloc (PCG flag)");
    check(cudaMemcpyAsync(tri_, values, sizeof(double) * nnz, cudaMemcpyHostToDevice, stream_), "cudaMemcpy (PCG values)");
    check(cudaMemsetAsync(bi_, 0, sizeof(double) * 3 * size_t(n_), stream_), "cudaMemset (PCG blocks)");
    check(cudaMemsetAsync(failed_, 0, sizeof(int), stream_), "cudaMemset (PCG flag)");
    scatter_triangle<<<(nnz + kThreads - 1) / kThreads, kThreads, 0, stream_>>>(nnz, tri_, pos_, mir_, dg_, v_, bi_);
    invert_blocks<<<(n_ / 3 + kThreads - 1) / kThreads, kThreads, 0, stream_>>>(n_ / 3, bi_, failed_);
    check(cudaGetLastError(), "the PCG system's kernels");
    int failed = 0;
    check(cudaMemcpyAsync(&failed, failed_, sizeof(int), cudaMemcpyDeviceToHost, stream_), "cudaMemcpy (PCG flag)");
    check(cudaStreamSynchronize(stream_), "cudaStreamSynchronize (PCG)");
    return failed == 0;
  }

  numerics::BlockPcgResult solve(const double* b, double* x, double tol, int max_iterations) override {
    numerics::BlockPcgResult res;
    if (n_ == 0) return res;
    const int nb = n_ / 3;
    const int gv = (nb + kThreads - 1) / kThreads, gr = (n_ + kThreads / 32 - 1) / (kThreads / 32),
              gn = (n_ + kThreads - 1) / kThreads;
    cudaStream_t st = stream_;
    check(cudaMemcpyAsync(r_, b, sizeof(double) * n_, cudaMemcpyHostToDevice, st), "cudaMemcpy (PCG right-hand side)");
    start<<<gv, kThreads, 0, st>>>(nb, bi_, r_, z_, p_, x_, pa_, pb_);
    finish_start<<<1, kThreads, 0, st>>>(pa_, pb_, gv, tol, s_);
    auto iterations = [&](int count) {
      for (int k = 0; k < count; ++k) {
        spmv_dot<<<gr, kThreads, 0, st>>>(n_, rp_, ci_, v_, p_, q_, pa_, s_);
        finish_pq<<<1, kThreads, 0, st>>>(pa_, gr, s_);
        update<<<gv, kThreads, 0, st>>>(nb, bi_, p_, q_, x_, r_, z_, pa_, pb_, s_);
        finish_rz<<<1, kThreads, 0, st>>>(pa_, pb_, gv, s_);
        update_p<<<gn, kThreads, 0, st>>>(n_, z_, p_, s_);
      }
    };
    if (!graph_) {
      cudaGraph_t g = nullptr;
      check(cudaStreamBeginCapture(st, cudaStreamCaptureModeThreadLocal), "cudaStreamBeginCapture (PCG)");
      iterations(kBatch);
      check(cudaStreamEndCapture(st, &g), "cudaStreamEndCapture (PCG)");
      const cudaError_t e = cudaGraphInstantiate(&graph_, g, 0);
      cudaGraphDestroy(g);
      check(e, "cudaGraphInstantiate (PCG)");
    }
    Scalars h{};
    for (int it = 0; it < max_iterations; it += kBatch) {
      if (it + kBatch <= max_iterations) check(cudaGraphLaunch(graph_, st), "cudaGraphLaunch (PCG)");
      else iterations(max_iterations - it);
      check(cudaGetLastError(), "the PCG kernels' launch");
      check(cudaMemcpyAsync(&h, s_, sizeof(Scalars), cudaMemcpyDeviceToHost, st), "cudaMemcpy (PCG scalars)");
      check(cudaStreamSynchronize(st), "cudaStreamSynchronize (PCG)");
      if (h.done) break;
    }
    if (!h.done) {
      check(cudaMemcpyAsync(&h, s_, sizeof(Scalars), cudaMemcpyDeviceToHost, st), "cudaMemcpy (PCG scalars)");
      check(cudaStreamSynchronize(st), "cudaStreamSynchronize (PCG)");
    }
    check(cudaMemcpyAsync(x, x_, sizeof(double) * n_, cudaMemcpyDeviceToHost, st), "cudaMemcpy (PCG solution)");
    check(cudaStreamSynchronize(st), "cudaStreamSynchronize (PCG)");
    res.iterations = h.iterations;
    res.breakdown = h.breakdown != 0;
    res.relative_residual = h.bn2 > 0 ? std::sqrt(h.rr / h.bn2) : 0.0;
    res.converged = !res.breakdown && res.relative_residual <= tol;
    return res;
  }

  const char* name() const override { return name_.c_str(); }

  // p with room for n elements; a buffer that has it already is kept (a T-shirt's pattern
  // changes every few steps, by a few hundred entries: cudaFree waits for the device, and each
  // of the 15 buffers cost one).
  template <class T>
  void alloc(T*& p, size_t n, const char* what) {
    size_t& cap = capacity_[(void*)&p];
    if (p && n <= cap) return;
    if (p) cudaFree(p);
    p = nullptr;
    cap = std::max<size_t>(n, 1) + n / 8;  // (an eighth to spare: patterns grow by a little)
    check(cudaMalloc(&p, cap * sizeof(T)), what);
  }

  // The pattern's buffers (and the vectors sized by it), again only when the pattern_id changes.
  void pattern(const numerics::BlockCsr& A) {
    const bool same = A.n == n_ && A.pattern_id != 0 && A.pattern_id == pattern_id_;
    if (!same) {
      n_ = A.n;
      pattern_id_ = A.pattern_id;
      nnz_ = A.col.size();
      alloc(rp_, n_ + 1, "cudaMalloc (PCG rows)");
      alloc(ci_, nnz_, "cudaMalloc (PCG columns)");
      alloc(v_, nnz_, "cudaMalloc (PCG values)");
      alloc(bi_, 3 * size_t(n_), "cudaMalloc (PCG block inverses)");
      for (double** p : {&x_, &r_, &z_, &p_, &q_}) alloc(*p, n_, "cudaMalloc (PCG vectors)");
      if (graph_) cudaGraphExecDestroy(graph_);  // it names the buffers just replaced
      graph_ = nullptr;
      parts_ = std::max((n_ + kThreads / 32 - 1) / (kThreads / 32), (n_ / 3 + kThreads - 1) / kThreads);
      alloc(pa_, parts_, "cudaMalloc (PCG partial sums)");
      alloc(pb_, parts_, "cudaMalloc (PCG partial sums)");
      check(cudaMemcpyAsync(rp_, A.row_ptr.data(), sizeof(int) * (n_ + 1), cudaMemcpyHostToDevice, stream_),
            "cudaMemcpy (PCG rows)");
      check(cudaMemcpyAsync(ci_, A.col.data(), sizeof(int) * nnz_, cudaMemcpyHostToDevice, stream_),
            "cudaMemcpy (PCG columns)");
    }
  }

 private:
  std::string name_;
  std::map<void*, size_t> capacity_;  // alloc's buffers: elements room
  int n_ = 0, parts_ = 0;
  uint64_t pattern_id_ = 0;
  size_t nnz_ = 0;
  int *rp_ = nullptr, *ci_ = nullptr;
  double *v_ = nullptr, *bi_ = nullptr, *x_ = nullptr, *r_ = nullptr, *z_ = nullptr, *p_ = nullptr, *q_ = nullptr,
         *pa_ = nullptr, *pb_ = nullptr;
  Scalars* s_ = nullptr;
  cudaStream_t stream_ = nullptr;
  cudaGraphExec_t graph_ = nullptr;  // kBatch iterations on this pattern's buffers
  // upload_triangle's: the triangle's values, its map (for pattern map_id_), the failure flag
  double* tri_ = nullptr;
  int *pos_ = nullptr, *mir_ = nullptr, *dg_ = nullptr, *failed_ = nullptr;
  uint64_t map_id_ = 0;
  int tri_n_ = -1;
};

}  // namespace

std::unique_ptr<numerics::PcgDevice> make_pcg_device() { return std::make_unique<DevicePcg>(); }

}  // namespace yarnhom::cuda
