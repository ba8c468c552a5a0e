// Adam and ReduceLROnPlateau against sequences produced by PyTorch itself (torch 1.13,
// float64; the script is in the comments), including the scheduler's threshold, patience,
// cooldown, min_lr and eps edge cases.
#include <gtest/gtest.h>

#include "cpu/adam.hpp"
#include "train/plateau.hpp"

using namespace yarnhom;

// p = Parameter([1.0, -2.0]); Adam([p], lr=0.1, betas=(0.9, 0.999), eps=1e-8);
// gradients below, one opt.step() each; p after every step.
TEST(Adam, MatchesPyTorchSequence) {
  std::vector<double> p = {1.0, -2.0}, m(2, 0.0), v(2, 0.0);
  const double grads[5][2] = {{0.5, -3.0}, {-0.2, 1.0}, {0.1, 0.0}, {2.0, -0.5}, {0.0, 0.3}};
  const double expect[5][2] = {{0.900000002, -1.9000000003333333},
                               {0.8654394181165108, -1.8599781433169098},
                               {0.8275002408356956, -1.8290411318785376},
                               {0.7632478092384046, -1.7949227007336388},
                               {0.7089398532690245, -1.771309948794461}};
  cpu::AdamParams a;
  a.lr = 0.1;
  for (int t = 0; t < 5; ++t) {
    cpu::adam_update<double>(p.data(), grads[t], m.data(), v.data(), 2, a, t + 1);
    EXPECT_NEAR(p[0], expect[t][0], 1e-14) << "step " << t + 1;
    EXPECT_NEAR(p[1], expect[t][1], 1e-14) << "step " << t + 1;
  }
}

TEST(Adam, FloatFollowsTheDoubleSequence) {
  std::vector<float> p = {1.0f, -2.0f}, m(2, 0.f), v(2, 0.f);
  const float grads[2][2] = {{0.5f, -3.0f}, {-0.2f, 1.0f}};
  cpu::AdamParams a;
  a.lr = 0.1;
  for (int t = 0; t < 2; ++t) cpu::adam_update<float>(p.data(), grads[t], m.data(), v.data(), 2, a, t + 1);
  EXPECT_NEAR(p[0], 0.8654394181165108, 1e-6);
  EXPECT_NEAR(p[1], -1.8599781433169098, 1e-6);
}

namespace {
std::vector<double> run(const std::vector<double>& seq, PlateauParams pp) {
  ReduceLROnPlateau s(1.0, pp);
  std::vector<double> out;
  for (double v : seq) out.push_back(s.step(v));
  return out;
}
const std::vector<double> kSeq = {1.0,   0.995, 0.98,  0.985, 0.97,  0.969, 0.968,
                                  0.95,  0.949, 0.948, 0.947, 0.946, 0.945, 0.9};

void expect_seq(const std::vector<double>& got, const std::vector<double>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_DOUBLE_EQ(got[i], want[i]) << "epoch " << i;
}
}  // namespace

// ReduceLROnPlateau(SGD lr=1, mode='min', factor=0.5, patience=2, threshold=0.01, 'rel')
TEST(Plateau, RelativeThresholdAndPatience) {
  PlateauParams p;
  p.patience = 2;
  expect_seq(run(kSeq, p), {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0.5, 0.5, 0.5, 0.5});
}

// patience=1, cooldown=2, min_lr=0.3
TEST(Plateau, CooldownAndMinLr) {
  PlateauParams p;
  p.patience = 1;
  p.cooldown = 2;
  p.min_lr = 0.3;
  expect_seq(run(kSeq, p), {1, 1, 1, 1, 1, 1, 0.5, 0.5, 0.5, 0.5, 0.3, 0.3, 0.3, 0.3});
}

// patience=0, threshold=0.005, threshold_mode='abs', cooldown=1
TEST(Plateau, AbsoluteThresholdZeroPatience) {
  PlateauParams p;
  p.patience = 0;
  p.threshold = 0.005;
  p.relative = false;
  p.cooldown = 1;
  expect_seq(run(kSeq, p), {1.0, 0.5, 0.5, 0.25, 0.25, 0.125, 0.125, 0.125, 0.0625, 0.0625,
                            0.03125, 0.03125, 0.015625, 0.015625});
}

// factor=0.1, patience=0, min_lr=1e-9, constant loss: the last reduction (1e-8 -> 1e-9) is
// skipped because it changes the rate by less than eps = 1e-8.
TEST(Plateau, ReductionsSmallerThanEpsAreSkipped) {
  PlateauParams p;
  p.factor = 0.1;
  p.patience = 0;
  p.min_lr = 1e-9;
  auto got = run(std::vector<double>(12, 1.0), p);
  const std::vector<double> want = {1.0, 0.1, 0.010000000000000002, 0.0010000000000000002,
                                    0.00010000000000000003, 1.0000000000000004e-05,
                                    1.0000000000000004e-06, 1.0000000000000005e-07,
                                    1.0000000000000005e-08, 1.0000000000000005e-08,
                                    1.0000000000000005e-08, 1.0000000000000005e-08};
  expect_seq(got, want);
}

TEST(Plateau, NaNIsNeverAnImprovement) {
  PlateauParams p;
  p.patience = 1;
  ReduceLROnPlateau s(1.0, p);
  s.step(1.0);
  s.step(std::nan(""));
  EXPECT_EQ(s.step(std::nan("")), 0.5);
}
