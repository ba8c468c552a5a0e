#include "cpu/mlp_jet.hpp"

#include "cpu/sigmoid_jet.hpp"

namespace yarnhom::cpu {

template <class T>
void mlp_jet_forward(const NetworkDesc& desc, const T* params, const T* x, int batch, int order,
                     T* out, JetWorkspace<T>& ws) {
  using RowMat = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const int d = desc.input_dim, B = batch, C = jet_channels(d, order);
  const int L = desc.num_layers();
  ws.z.resize(L);
  ws.a.resize(L - 1);
  ws.W.resize(L);
  ws.b.resize(L);
  ws.batch = B;
  ws.order = order;
  for (int k = 0; k < L; ++k) {
    const int n = desc.layer_out(k), m = desc.layer_in(k);
    ws.W[k] = Eigen::Map<const RowMat>(params + desc.weight_offset(k), n, m);
    ws.b[k] = Eigen::Map<const Eigen::Matrix<T, Eigen::Dynamic, 1>>(params + desc.bias_offset(k), n);
  }
  ws.X = Eigen::Map<const RowMat>(x, B, d);

  // The input jet is (x, e_i, 0, 0): so the first layer's pre-activation jet is
  // z = W x + b, z_i = W[:, i] for every point, and zero at orders 2 and 3.
  {
    const int n = desc.layer_out(0);
    const auto& W = ws.W[0];
    const auto& b = ws.b[0];
    const auto& X = ws.X;
    Mat<T>& Z = ws.z[0];
    Z.resize(n, C * B);
    Z.leftCols(B).noalias() = W * X.transpose();
    Z.leftCols(B).colwise() += b;
    for (int i = 0; i < d && order >= 1; ++i) Z.middleCols((1 + i) * B, B).colwise() = W.col(i);
    if (C > 1 + d) Z.rightCols((C - 1 - d) * B).setZero();
  }
  for (int k = 1; k < L; ++k) {
    sigmoid_jet_forward<T>(d, order, B, ws.z[k - 1], ws.a[k - 1]);
    const int n = desc.layer_out(k);
    const auto& W = ws.W[k];
    const auto& b = ws.b[k];
    Mat<T>& Z = ws.z[k];
    Z.resize(n, C * B);
    Z.noalias() = W * ws.a[k - 1];
    Z.leftCols(B).colwise() += b;
  }
  // The output layer is linear: its pre-activation jet is the network's jet.
  Eigen::Map<Eigen::Matrix<T, 1, Eigen::Dynamic>>(out, C * B) = ws.z[L - 1].row(0);
}

template void mlp_jet_forward<float>(const NetworkDesc&, const float*, const float*, int, int,
                                     float*, JetWorkspace<float>&);
template void mlp_jet_forward<double>(const NetworkDesc&, const double*, const double*, int, int,
                                      double*, JetWorkspace<double>&);

}  // namespace yarnhom::cpu
