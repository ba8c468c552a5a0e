#include "cpu/epoch_kernel.hpp"

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <stdexcept>

#include "cpu/epoch_kernel_impl.hpp"

namespace yarnhom::cpu {
namespace {

using epoch::Pass;
using epoch::PassInputs;
using epoch::PassSums;

// One network shape and data order: the data pass, the off-domain pass, then the sums across
// lanes. The workspace holds, 64-byte aligned: the P lane accumulators and the larger of the two
// passes' scratch.
template <class T, int D, int ORDER, int... H>
LossValues run_net(const T* params, const LossBatch<T>& batch, const LossOptions& opt, T* grad,
                   EpochWorkspace<T>& ws) {
  using S = epoch::Shape<D, H...>;
  using DataPass = Pass<T, false, ORDER, D, H...>;
  using OffPass = Pass<T, true, 1, D, H...>;
  using V = typename epoch::Simd<T>::V;
  constexpr int L = epoch::Simd<T>::L, P = S::P;
  constexpr int kVectors = P + std::max(DataPass::kScratch, OffPass::kScratch);
  if (ws.buf.size() < size_t(kVectors + 1) * L) ws.buf.assign(size_t(kVectors + 1) * L, T(0));
  V* dw = reinterpret_cast<V*>((reinterpret_cast<uintptr_t>(ws.buf.data()) + 63) & ~uintptr_t(63));
  V* scratch = dw + P;

  if (grad) std::fill(dw, dw + P, V{});
  V* acc = grad ? dw : nullptr;

  const LossWeights& w = opt.w;
  const T inv_m = batch.m > 0 ? T(1) / T(batch.m) : T(0);
  const T inv_k = batch.k > 0 ? T(1) / T(batch.k) : T(0);
  PassSums<V> sums;
  if (batch.m > 0) {
    PassInputs<T> in;
    in.n = batch.m, in.x = batch.x, in.y = batch.y, in.g = batch.g, in.wt = batch.wt;
    in.use_z = w.z != 0, in.use_f = w.f != 0, in.use_c = ORDER >= 3 && w.c != 0;
    in.cz = T(w.z) * inv_m * T(2), in.cf = T(w.f) * inv_m * T(2), in.cc = T(w.c) * inv_m;
    DataPass::run(params, in, acc, scratch, sums);
  }
  if (batch.k > 0 && w.s != 0) {
    PassInputs<T> in;
    in.n = batch.k, in.x = batch.xo, in.no = batch.no;
    in.cs = T(w.s) * inv_k * T(2);
    OffPass::run(params, in, acc, scratch, sums);
  }

  // Sums across lanes (epoch::lane_sum: a fixed order).
  const T tz = epoch::lane_sum<T>(sums.z), tf = epoch::lane_sum<T>(sums.f);
  const T tc = epoch::lane_sum<T>(sums.c), ts = epoch::lane_sum<T>(sums.s);
  if (grad)
    for (int p = 0; p < P; ++p) grad[p] = epoch::lane_sum<T>(dw[p]);
  LossValues v;
  v.z = double(tz) * double(inv_m);
  v.f = double(tf) * double(inv_m);
  v.c = double(tc) * double(inv_m);
  v.s = double(ts) * double(inv_k);
  v.total = w.z * v.z + w.f * v.f + w.c * v.c + w.s * v.s;
  return v;
}

bool hidden_is(const NetworkDesc& desc, std::initializer_list<int> h) {
  return desc.hidden.size() == h.size() && std::equal(h.begin(), h.end(), desc.hidden.begin());
}

template <class T, int D, int ORDER>
LossValues run_order(const NetworkDesc& desc, const T* params, const LossBatch<T>& batch,
                     const LossOptions& opt, T* grad, EpochWorkspace<T>& ws) {
  if (hidden_is(desc, {16, 32, 16})) return run_net<T, D, ORDER, 16, 32, 16>(params, batch, opt, grad, ws);
  return run_net<T, D, ORDER, 32, 32>(params, batch, opt, grad, ws);
}

}  // namespace

bool fused_loss_supported(const NetworkDesc& desc, const LossOptions& opt) {
  const bool shape = (desc.input_dim == 1 || desc.input_dim == 2) && desc.activation == "sigmoid" &&
                     (hidden_is(desc, {16, 32, 16}) || hidden_is(desc, {32, 32}));
  return shape && opt.w.x == 0 && !(opt.stencil_c && opt.w.c != 0);
}

template <class T>
LossValues fused_loss_grad(const NetworkDesc& desc, const T* params, const LossBatch<T>& batch,
                           const LossOptions& opt, T* grad, EpochWorkspace<T>& ws) {
  if (!fused_loss_supported(desc, opt))
    throw std::invalid_argument("fused_loss_grad: network shape or loss options not compiled in (fused_loss_supported)");
  const bool third = data_jet_order(opt) == 3;
  if (desc.input_dim == 1)
    return third ? run_order<T, 1, 3>(desc, params, batch, opt, grad, ws)
                 : run_order<T, 1, 1>(desc, params, batch, opt, grad, ws);
  return third ? run_order<T, 2, 3>(desc, params, batch, opt, grad, ws)
               : run_order<T, 2, 1>(desc, params, batch, opt, grad, ws);
}

template LossValues fused_loss_grad<float>(const NetworkDesc&, const float*, const LossBatch<float>&,
                                           const LossOptions&, float*, EpochWorkspace<float>&);
template LossValues fused_loss_grad<double>(const NetworkDesc&, const double*, const LossBatch<double>&,
                                            const LossOptions&, double*, EpochWorkspace<double>&);

}  // namespace yarnhom::cpu
