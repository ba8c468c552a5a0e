#pragma once
// The network description (spec section 6): an MLP d -> hidden... -> 1 with sigmoid hidden
// activations and a linear output, and the flat layout of its parameters that every kernel,
// the optimizer and the file writer share:
//
//   for each layer k: W_k [out_k, in_k] row-major, then b_k [out_k]        (y = W x + b)
#include <stdexcept>
#include <string>
#include <vector>

namespace yarnhom {

struct NetworkDesc {
  int input_dim = 1;                     // d = 1 or 2
  std::vector<int> hidden = {16, 32, 16};  // the paper's Net-3
  std::string activation = "sigmoid";

  int num_layers() const { return static_cast<int>(hidden.size()) + 1; }
  int layer_in(int k) const { return k == 0 ? input_dim : hidden[k - 1]; }
  int layer_out(int k) const { return k == num_layers() - 1 ? 1 : hidden[k]; }
  int widest() const {
    int w = input_dim;
    for (int h : hidden) w = h > w ? h : w;
    return w;
  }
  // Offsets into the flat parameter vector.
  int weight_offset(int k) const {
    int off = 0;
    for (int j = 0; j < k; ++j) off += layer_out(j) * (layer_in(j) + 1);
    return off;
  }
  int bias_offset(int k) const { return weight_offset(k) + layer_out(k) * layer_in(k); }
  int num_params() const { return weight_offset(num_layers()); }

  void validate() const {
    if (input_dim != 1 && input_dim != 2) throw std::invalid_argument("input dimension must be 1 or 2");
    if (hidden.empty()) throw std::invalid_argument("at least one hidden layer");
    if (hidden.size() > 16) throw std::invalid_argument("at most 16 hidden layers");
    for (int h : hidden)
      if (h < 1 || h > 1024) throw std::invalid_argument("hidden sizes must be in 1..1024");
    if (activation != "sigmoid") throw std::invalid_argument("only the sigmoid activation is implemented");
  }
};

// Loss weights (spec section 6), in the order Z, F, C, S, X.
struct LossWeights {
  double z = 1.0, f = 0.05, c = 1e-3, s = 1e2, x = 0.0;
};

}  // namespace yarnhom
