#include "cpu/mlp_jet.hpp"
#include "cpu/sigmoid_jet.hpp"

namespace yarnhom::cpu {

// Reverse mode over the layers of mlp_jet_forward. For a linear layer Z = W A + b (b in
// channel 0 only) with adjoint Zbar:  dW += Zbar A^T (summed over all channels and points),
// db += sum over points of Zbar's channel 0, Abar = W^T Zbar. The sigmoid's jet map is undone
// by sigmoid_jet_backward. The first layer's input jet is (x, e_i, 0, 0), so its weight
// gradient is Zbar_0 X^T plus, in column i, the sum of Zbar's channel e_i.
// Weights and inputs are the workspace's copies made by the forward pass (see JetWorkspace).
template <class T>
void mlp_jet_backward(const NetworkDesc& desc, const T* params, const T* x, int batch, int order,
                      const T* dout, T* dparams, JetWorkspace<T>& ws) {
  using RowMat = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  using Vec = Eigen::Matrix<T, Eigen::Dynamic, 1>;
  const int d = desc.input_dim, B = batch, C = jet_channels(d, order);
  const int L = desc.num_layers();

  ws.zbar.resize(1, C * B);
  ws.zbar.row(0) = Eigen::Map<const Eigen::Matrix<T, 1, Eigen::Dynamic>>(dout, C * B);
  for (int k = L - 1; k >= 1; --k) {
    const int n = desc.layer_out(k), m = desc.layer_in(k);
    const auto& W = ws.W[k];
    Eigen::Map<RowMat> dW(dparams + desc.weight_offset(k), n, m);
    Eigen::Map<Vec> db(dparams + desc.bias_offset(k), n);
    ws.dW.noalias() = ws.zbar * ws.a[k - 1].transpose();
    dW += ws.dW;
    ws.db.noalias() = ws.zbar.leftCols(B).rowwise().sum();
    db += ws.db;
    ws.abar.resize(m, C * B);
    ws.abar.noalias() = W.transpose() * ws.zbar;
    sigmoid_jet_backward<T>(d, order, B, ws.z[k - 1], ws.abar, ws.zbar);
  }
  const int n = desc.layer_out(0);
  Eigen::Map<RowMat> dW(dparams + desc.weight_offset(0), n, d);
  Eigen::Map<Vec> db(dparams + desc.bias_offset(0), n);
  ws.dW.noalias() = ws.zbar.leftCols(B) * ws.X;
  dW += ws.dW;
  for (int i = 0; i < d && order >= 1; ++i) {
    ws.db.noalias() = ws.zbar.middleCols((1 + i) * B, B).rowwise().sum();
    dW.col(i) += ws.db;
  }
  ws.db.noalias() = ws.zbar.leftCols(B).rowwise().sum();
  db += ws.db;
}

template void mlp_jet_backward<float>(const NetworkDesc&, const float*, const float*, int, int,
                                      const float*, float*, JetWorkspace<float>&);
template void mlp_jet_backward<double>(const NetworkDesc&, const double*, const double*, int, int,
                                       const double*, double*, JetWorkspace<double>&);

}  // namespace yarnhom::cpu
