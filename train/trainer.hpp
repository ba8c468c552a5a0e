#pragma once
// The trainer: from a dataset to a model. For each selected term it prepares the problem
// (seeded 90/10 split, normalization to [-1,1]^d and unit-variance energies, PyTorch's default
// initialization, fixed validation off-domain points), then drives a backend epoch by epoch
// with ReduceLROnPlateau on the validation loss, records the history, and stops a network
// whose loss becomes non-finite (the others go on). On a backend whose networks are
// independent (the CPU's) with several threads, each thread takes whole networks, all their
// epochs and then their polish, with no barrier between epochs; the weights are the same.
#include <functional>
#include <string>
#include <vector>

#include "core/dataset.hpp"
#include "core/fit_metrics.hpp"
#include "core/model.hpp"
#include "train/backend.hpp"
#include "train/plateau.hpp"
#include "train/polish.hpp"

namespace yarnhom {

struct TrainerOptions {
  TrainConfig config;
  PlateauParams plateau;
  PolishOptions polish;      // the full-batch L-BFGS polish after the epochs (0 iterations: none)
  NetworkDesc net;           // hidden sizes and activation; input_dim set per term
  std::vector<int> hidden_2d;  // the 2D terms' hidden sizes; empty: net.hidden, as the 1D terms
  uint64_t seed = 0;
  int batch_1d = 4, batch_2d = 128;
  double val_fraction = 0.1;
  std::string recipe = "paper";  // recorded in the model file
};

// Progress after each epoch: per network (in job order) its name, the epoch's stats, the
// learning rate, and whether it is still training.
struct ProgressRow {
  std::string name;
  EpochStats stats;
  double lr = 0;
  int epochs_done = 0;
  bool active = true;
  std::string status = "ok";
};
using ProgressFn = std::function<void(int epoch, int epochs, const std::vector<ProgressRow>&)>;

struct TrainResult {
  Model model;                 // networks that trained to the end, in catalogue order
  std::vector<ProgressRow> rows;  // final row per network, failed ones included
  std::vector<double> seconds;    // wall time attributed to each network (share of epochs + polish)
  std::vector<PolishResult> polish;  // per network (empty results when there was no polish)
  std::vector<FitQuality> val_fit, all_fit;  // per network: physical fit on the validation
                                             // points and on all points (core/fit_metrics.hpp)
  bool all_ok() const;
};

// The problem of one term: exposed for tests and for the reference checks. rest_hessian: the
// dataset's measured d2Psi/ds2 at s = 0 ([36] row-major, Dataset::rest_hessian), or null /
// empty when it has none (NetworkJob::curvature_rest says what is held then).
NetworkJob make_job(const TermData& data, const TrainerOptions& opt, Normalization* norm,
                    const std::vector<double>* rest_hessian = nullptr);

TrainResult train_terms(const Dataset& ds, const std::string& dataset_path,
                        const std::vector<Term>& terms, const TrainerOptions& opt,
                        Backend& backend, const ProgressFn& progress = {});

}  // namespace yarnhom
