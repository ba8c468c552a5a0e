// The trainer on synthetic data: it learns (validation L_Z falls at least 100-fold), it is
// deterministic (same seed: identical weights, whatever the thread count), and a network whose
// loss becomes non-finite stops alone.
#include <gtest/gtest.h>

#include <cmath>

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
