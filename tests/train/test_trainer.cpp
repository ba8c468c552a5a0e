// The trainer on synthetic data: it learns (validation L_Z falls at least 100-fold), it is
// deterministic (same seed: identical weights, whatever the thread count), and a network whose
// loss becomes non-finite stops alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "produce/synthetic.hpp"
#include "cpu/loss_step.hpp"
#include "train/trainer.hpp"

using namespace yarnhom;

namespace {

// Validation L_Z of a job with given weights.
double val_lz(const NetworkJob& job, const std::vector<float>& params) {
  cpu::LossWorkspace<float> ws;
  cpu::LossBatch<float> b{job.n_val, job.x_val.data(), job.y_val.data(), job.g_val.data(), 0, nullptr, nullptr};
  return cpu::mlp_loss_grad<float>(job.desc, params.data(), b, cpu::LossOptions{}, nullptr, ws).z;
}

TrainResult train(const Dataset& ds, const std::vector<Term>& terms, int epochs, int threads,
                  uint64_t seed = 3) {
  TrainerOptions opt;
  opt.seed = seed;
  opt.config.epochs = epochs;
  opt.config.threads = threads;
  auto be = make_backend("cpu");
  return train_terms(ds, "synthetic", terms, opt, *be);
}

}  // namespace

TEST(Trainer, ValidationEnergyLossFallsHundredfold) {
  Dataset ds = make_synthetic_dataset("paper");
  // Term 25 is one of the 2D terms the recipe fits well (docs/benchmarks.md lists all 14).
  std::vector<Term> terms = {term_by_name("0"), term_by_name("25")};
  TrainResult res = train(ds, terms, 500, 2);
  ASSERT_TRUE(res.all_ok());
  ASSERT_EQ(res.model.networks.size(), 2u);
  TrainerOptions opt;
  opt.seed = 3;
  for (size_t j = 0; j < terms.size(); ++j) {
    NetworkJob job = make_job(*ds.find(terms[j].name), opt, nullptr);
    const double before = val_lz(job, job.init_params);
    const double after = val_lz(job, res.model.networks[j].params);
    EXPECT_LT(after * 100, before) << terms[j].name << ": before " << before << " after " << after;
    EXPECT_EQ(res.model.networks[j].history.size(), 500u);
  }
}

TEST(Trainer, SameSeedSameWeightsForAnyThreadCount) {
  Dataset ds = make_synthetic_dataset("quick");
  std::vector<Term> terms = {term_by_name("1"), term_by_name("12"), term_by_name("5")};
  TrainResult a = train(ds, terms, 30, 1), b = train(ds, terms, 30, 2), c = train(ds, terms, 30, 2);
  for (size_t j = 0; j < terms.size(); ++j) {
    EXPECT_EQ(a.model.networks[j].params, b.model.networks[j].params) << terms[j].name;
    EXPECT_EQ(b.model.networks[j].params, c.model.networks[j].params) << terms[j].name;
  }
  TrainResult d = train(ds, terms, 30, 2, 4);
  EXPECT_NE(a.model.networks[0].params, d.model.networks[0].params) << "the seed must matter";
}

TEST(Trainer, LoneNetworkTrainsTheSameAsInAGroup) {
  Dataset ds = make_synthetic_dataset("quick");
  TrainResult a = train(ds, {term_by_name("02")}, 20, 2);
  TrainResult b = train(ds, {term_by_name("0"), term_by_name("02")}, 20, 2);
  EXPECT_EQ(a.model.networks[0].params, b.model.networks[1].params);
}

TEST(Trainer, NonFiniteLossStopsThatNetworkOnly) {
  Dataset ds = make_synthetic_dataset("quick");
  // Term 1: energies with a spread of 1e-30 but O(1) gradients. Normalized gradient targets
  // become ~1e30 and their squares overflow float: the loss is infinite from the first batch.
  TermData& t = const_cast<TermData&>(*ds.find("1"));
  for (int i = 0; i < t.n; ++i) {
    t.energy[i] = 1e-30 * (i % 2);
    t.gradient[i] = 1.0;
  }
  TrainResult res = train(ds, {term_by_name("0"), term_by_name("1")}, 10, 2);
  EXPECT_FALSE(res.all_ok());
  EXPECT_EQ(res.rows[0].status, "ok");
  EXPECT_EQ(res.rows[1].status, "non-finite loss at epoch 1");
  ASSERT_EQ(res.model.networks.size(), 1u);
  EXPECT_EQ(res.model.networks[0].term.name, "0");
  EXPECT_EQ(res.model.networks[0].epochs, 10);
}

// The epochs' fused kernel (cpu/epoch_kernel.hpp) against the general kernel
// (YARNHOM_CPU_EPOCH_KERNEL=general) over 20 epochs of every quick synthetic term, Net-3 and
// Net-2 for the 2D terms: the same function with float sums in another order, so the weights
// may drift apart only by float rounding (the bounds of the CUDA backend's twin test,
// tests/cuda/test_cuda_train.cpp: a wrong channel or term shows up at 1e-3 or more).
TEST(Trainer, FusedEpochKernelMatchesTheGeneralKernelWithinFloatDrift) {
  static const Dataset ds = make_synthetic_dataset("quick");
  std::vector<Term> terms;
  for (auto& t : ds.terms) terms.push_back(t.term);
  for (const std::vector<int>& h2 : {std::vector<int>{}, std::vector<int>{32, 32}}) {
    TrainerOptions opt;
    opt.hidden_2d = h2;
    opt.seed = 3;
    opt.config.epochs = 20;
    opt.config.threads = 2;
    auto run = [&](bool general) {
      if (general) setenv("YARNHOM_CPU_EPOCH_KERNEL", "general", 1);
      auto be = make_backend("cpu");
      TrainResult r = train_terms(ds, "synthetic-quick", terms, opt, *be);
      unsetenv("YARNHOM_CPU_EPOCH_KERNEL");
      return r;
    };
    const TrainResult f = run(false), g = run(true);
    double worst_w = 0, worst_l = 0;
    ASSERT_EQ(f.model.networks.size(), terms.size());
    ASSERT_EQ(g.model.networks.size(), terms.size());
    for (size_t j = 0; j < terms.size(); ++j) {
      const auto& a = f.model.networks[j];
      const auto& b = g.model.networks[j];
      double num = 0, den = 0;
      for (size_t i = 0; i < a.params.size(); ++i) {
        num += (double(a.params[i]) - b.params[i]) * (double(a.params[i]) - b.params[i]);
        den += double(b.params[i]) * b.params[i];
      }
      const double dw = std::sqrt(num / den);
      const double dl0 = std::abs(a.history.train_loss[0] - b.history.train_loss[0]) / b.history.train_loss[0];
      const double dl = std::abs(a.history.val_loss.back() - b.history.val_loss.back()) / b.history.val_loss.back();
      worst_w = std::max(worst_w, dw);
      worst_l = std::max(worst_l, dl);
      EXPECT_NE(dw, 0.0) << a.term.name << ": the switch must select the other kernel";
      EXPECT_LT(dl0, 2e-5) << a.term.name << " 2D hidden " << h2.size();
      EXPECT_LT(dw, 1e-5) << a.term.name << " 2D hidden " << h2.size();
      EXPECT_LT(dl, 1e-5) << a.term.name << " 2D hidden " << h2.size();
    }
    std::printf("  2D hidden %s: worst relative weight difference %.3e, final validation loss %.3e\n",
                h2.empty() ? "Net-3" : "Net-2", worst_w, worst_l);
  }
}
