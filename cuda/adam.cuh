#pragma once
// One parameter's PyTorch Adam step on the device (twin of cpu/adam.hpp), written with
// __fmul_rn/__fadd_rn/__fdiv_rn/__fsqrt_rn so that nothing is contracted into an FMA and it
// rounds like the CPU's; the bias corrections come in already made (step_size = lr / bc1,
// bc2_sqrt = sqrt(bc2), computed in double on the host or once per block). Used by
// cuda::adam_update (cuda/adam.cu); the fused epoch kernel's step (train/cuda_backend.cu) is
// the same arithmetic.

namespace yarnhom::cuda::detail {

#ifdef __CUDACC__

__device__ __forceinline__ void adam_step(float& w, float& m, float& v, float g, float b1, float b2, float one_b1,
                                          float one_b2, float eps, float step_size, float bc2_sqrt) {
  const float mi = __fadd_rn(__fmul_rn(m, b1), __fmul_rn(one_b1, g));
  const float vi = __fadd_rn(__fmul_rn(v, b2), __fmul_rn(__fmul_rn(one_b2, g), g));
  m = mi;
  v = vi;
  const float denom = __fadd_rn(__fdiv_rn(__fsqrt_rn(vi), bc2_sqrt), eps);
  w = __fsub_rn(w, __fmul_rn(step_size, __fdiv_rn(mi, denom)));
}

#endif  // __CUDACC__

}  // namespace yarnhom::cuda::detail
