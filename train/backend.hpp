#pragma once
// The one interface between the trainer and a compute backend (CPU now, CUDA behind the same
// calls). The trainer prepares each network's problem (normalized data, split, initial
// weights) and owns the schedule (epochs, learning rates, history); a backend owns the
// weights and optimizer state for the whole run and executes whole epochs: shuffling,
// batching, off-domain sampling, forward, losses, backward, Adam, validation. The trainer
// never touches the weights between epochs, so a device backend synchronizes with the host
// once per epoch (to return the losses that drive the plateau schedule).
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/network.hpp"
#include "cpu/adam.hpp"
#include "cpu/loss_types.hpp"

namespace yarnhom {

struct PolishOptions;  // train/polish.hpp
struct PolishResult;

// One network's training problem, in normalized units (float, row-major).
struct NetworkJob {
  std::string name;
  NetworkDesc desc;
  uint64_t key = 0;              // the network's random stream key (core/rng.hpp)
  int batch_size = 4;
  int n_train = 0, n_val = 0;
  std::vector<float> x_train, y_train, g_train;  // [n, d], [n], [n, d]
  std::vector<float> x_val, y_val, g_val;
  std::vector<float> xo_val, no_val;             // fixed validation off-domain points [k, d]
  std::vector<float> init_params;
  std::vector<int> val_rows;                     // dataset rows of the validation points
  // The rest s = 0 in normalized units, and the second derivatives the polish holds there
  // (normalized, in jet channel order: 1D f_xx; 2D f_xx, f_xy, f_yy); NaN when unknown. From
  // the dataset's measured rest Hessian (yarn/rve/rest_hessian.hpp) when it has one: 1D H_ii; 2D
  // f_xy = H_ij only (the material's axis projection of a 2D network has f_xx = f_yy = 0 at
  // the origin by construction, so the 1D terms carry H_ii). Without one, 1D terms take the
  // central difference of the gradients of the nodes on either side of 0, and 2D terms hold
  // nothing.
  float x_rest[2] = {NAN, NAN};
  float curvature_rest[3] = {NAN, NAN, NAN};
};

struct TrainConfig {
  cpu::LossOptions loss;
  cpu::AdamParams adam;   // adam.lr is the initial rate
  int epochs = 500;
  int off_domain = 50;    // fresh off-domain points per batch
  int val_off_domain = 256;
  int threads = 1;
};

// Means over the epoch's batches of each loss term (train), and the validation losses.
struct EpochStats {
  cpu::LossValues train, val;
  double seconds = 0;  // compute time the backend spent on this network this epoch
};

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string name() const = 0;
  // Takes the problems and the initial weights; allocates everything for the run.
  virtual void setup(const std::vector<NetworkJob>& jobs, const TrainConfig& cfg) = 0;
  // One epoch (0-based) of every network j with active[j], at learning rate lr[j].
  virtual void run_epoch(int epoch, const std::vector<double>& lr, const std::vector<char>& active,
                         std::vector<EpochStats>& stats) = 0;
  // The current weights of network j.
  virtual std::vector<float> params(int j) = 0;
  // Backends whose networks share nothing (the CPU's) can also run one network's epoch on its
  // own, from any thread, one call per network at a time: the trainer then gives each thread
  // whole networks (all their epochs, then their polish) instead of a barrier after every epoch
  // (train/trainer.cpp). The same weights either way.
  virtual bool independent_networks() const { return false; }
  virtual EpochStats run_network_epoch(int j, int epoch, double lr) {
    (void)j, (void)epoch, (void)lr;
    return {};
  }
  // The full-batch polish after the epochs (train/polish.hpp) of the networks `which` of the run,
  // on this backend's device: params[j] is polished in place and results[j] filled for every j
  // it takes; it returns, per entry of `which`, whether it took it (the trainer polishes the
  // others with polish_network on the CPU). The CPU backend takes none; the CUDA backend takes
  // every network its kernel supports (train/cuda_polish.hpp), all in one launch.
  virtual std::vector<char> polish(const std::vector<NetworkJob>& jobs, const TrainConfig& cfg,
                                   const PolishOptions& opt, const std::vector<int>& which,
                                   std::vector<std::vector<float>>& params, std::vector<PolishResult>& results) {
    (void)jobs, (void)cfg, (void)opt, (void)params, (void)results;
    return std::vector<char>(which.size(), 0);
  }
};

// "cpu", or "cuda" when built with CUDA; throws std::invalid_argument naming the choices.
std::unique_ptr<Backend> make_backend(const std::string& name);
std::vector<std::string> available_backends();

}  // namespace yarnhom
