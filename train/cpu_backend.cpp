// The CPU backend: every network trains in one thread with its own workspace; networks run
// in parallel over OpenMP threads. A lone network spreads its batch's chunks over the threads
// instead. Results do not depend on the thread count (cpu/loss_step.hpp reduces in a fixed
// order).
#include <omp.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "core/jet_layout.hpp"
#include "cpu/adam_simd.hpp"
#include "cpu/epoch_kernel.hpp"
#include "cpu/flush_denormals.hpp"
#include "cpu/loss_step.hpp"
#include "train/cpu_backend.hpp"
#include "train/epoch_plan.hpp"

namespace yarnhom {
namespace {

struct CpuNetwork {
  const NetworkJob* job = nullptr;
  std::vector<float> params, grad, m, v;
  int64_t step = 0;
  cpu::LossWorkspace<float> ws;
  cpu::EpochWorkspace<float> fws;  // the fused kernel's, for the shapes it covers
  std::vector<int> order;
  std::vector<float> bx, by, bg, xo, no;  // the current batch
};

class CpuBackend final : public Backend {
 public:
  std::string name() const override { return "cpu"; }

  void setup(const std::vector<NetworkJob>& jobs, const TrainConfig& cfg) override {
    const char* env = std::getenv("YARNHOM_CPU_EPOCH_KERNEL");
    fused_ = !(env && std::string(env) == "general");
    jobs_ = jobs;
    cfg_ = cfg;
    nets_.assign(jobs_.size(), {});
    for (size_t j = 0; j < jobs_.size(); ++j) {
      CpuNetwork& n = nets_[j];
      n.job = &jobs_[j];
      n.params = jobs_[j].init_params;
      const size_t P = n.params.size();
      if (P != size_t(jobs_[j].desc.num_params()))
        throw std::invalid_argument("initial weights do not match the network of " + jobs_[j].name);
      n.grad.assign(P, 0.f);
      n.m.assign(P, 0.f);
      n.v.assign(P, 0.f);
    }
  }

  void run_epoch(int epoch, const std::vector<double>& lr, const std::vector<char>& active,
                 std::vector<EpochStats>& stats) override {
    stats.resize(nets_.size());
    std::vector<int> todo;
    for (size_t j = 0; j < nets_.size(); ++j)
      if (active[j]) todo.push_back(int(j));
    // Longest first, so the dynamic schedule ends each epoch with the short jobs and the
    // threads wait less for one another (each network's cost: its points times its channels).
    auto cost = [&](int j) {
      const NetworkJob& b = *nets_[j].job;
      return double(b.n_train) * jet_channels(b.desc.input_dim, 3);
    };
    std::stable_sort(todo.begin(), todo.end(), [&](int a, int b) { return cost(a) > cost(b); });
    const int T = std::max(1, cfg_.threads);
    if (todo.size() == 1 || T == 1) {
      for (int j : todo) stats[j] = epoch_one(nets_[j], epoch, lr[j], T);
    } else {
#pragma omp parallel for num_threads(std::min<int>(T, todo.size())) schedule(dynamic, 1)
      for (size_t i = 0; i < todo.size(); ++i) stats[todo[i]] = epoch_one(nets_[todo[i]], epoch, lr[todo[i]], 1);
    }
  }

  std::vector<float> params(int j) override { return nets_[j].params; }

  bool independent_networks() const override { return true; }
  EpochStats run_network_epoch(int j, int epoch, double lr) override { return epoch_one(nets_[j], epoch, lr, 1); }

 private:
  // One loss evaluation: on the fused kernel (cpu/epoch_kernel.hpp, one thread) for the network
  // shapes and loss options it covers (the recipes'), else on cpu::mlp_loss_grad, whose chunks
  // spread over the threads for large batches. Either way the result does not depend on threads.
  // YARNHOM_CPU_EPOCH_KERNEL=general keeps every network on the general kernel (for comparisons).
  cpu::LossValues loss(CpuNetwork& n, const cpu::LossBatch<float>& batch, float* grad, int threads) {
    if (fused_ && cpu::fused_loss_supported(n.job->desc, cfg_.loss))
      return cpu::fused_loss_grad<float>(n.job->desc, n.params.data(), batch, cfg_.loss, grad, n.fws);
    return cpu::mlp_loss_grad<float>(n.job->desc, n.params.data(), batch, cfg_.loss, grad, n.ws, threads);
  }

  EpochStats epoch_one(CpuNetwork& n, int epoch, double lr, int threads) {
    cpu::flush_denormals();
    const double t0 = omp_get_wtime();
    const NetworkJob& job = *n.job;
    const int d = job.desc.input_dim, N = job.n_train, B = job.batch_size, K = cfg_.off_domain;
    n.order.resize(N);
    shuffled_order(job.key, epoch, N, n.order.data());
    const int batches = num_batches(N, B);
    n.bx.resize(size_t(B) * d);
    n.by.resize(B);
    n.bg.resize(size_t(B) * d);
    n.xo.resize(size_t(K) * d);
    n.no.resize(size_t(K) * d);
    cpu::AdamParams adam = cfg_.adam;
    adam.lr = lr;
    EpochStats st;
    for (int b = 0; b < batches; ++b) {
      const int begin = b * B, m = std::min(B, N - begin);
      for (int i = 0; i < m; ++i) {
        const int src = n.order[begin + i];
        n.by[i] = job.y_train[src];
        for (int k = 0; k < d; ++k) {
          n.bx[i * d + k] = job.x_train[size_t(src) * d + k];
          n.bg[i * d + k] = job.g_train[size_t(src) * d + k];
        }
      }
      const uint64_t okey = batch_offdomain_key(job.key, epoch, b);
      for (int k = 0; k < K; ++k) offdomain_point<float>(d, okey, k, &n.xo[k * d], &n.no[k * d]);
      cpu::LossBatch<float> batch{m, n.bx.data(), n.by.data(), n.bg.data(), K, n.xo.data(), n.no.data()};
      cpu::LossValues v = loss(n, batch, n.grad.data(), threads);
      cpu::adam_update_simd(n.params.data(), n.grad.data(), n.m.data(), n.v.data(), int(n.params.size()),
                            adam, ++n.step);
      st.train.total += v.total;
      st.train.z += v.z;
      st.train.f += v.f;
      st.train.c += v.c;
      st.train.s += v.s;
      st.train.x += v.x;
    }
    const double inv = 1.0 / batches;
    st.train.total *= inv;
    st.train.z *= inv;
    st.train.f *= inv;
    st.train.c *= inv;
    st.train.s *= inv;
    st.train.x *= inv;
    cpu::LossBatch<float> val{job.n_val, job.x_val.data(), job.y_val.data(), job.g_val.data(),
                              int(job.xo_val.size()) / d, job.xo_val.data(), job.no_val.data()};
    st.val = loss(n, val, nullptr, threads);
    st.seconds = omp_get_wtime() - t0;
    return st;
  }

  std::vector<NetworkJob> jobs_;
  TrainConfig cfg_;
  std::vector<CpuNetwork> nets_;
  bool fused_ = true;
};

}  // namespace

std::unique_ptr<Backend> make_cpu_backend() { return std::make_unique<CpuBackend>(); }

}  // namespace yarnhom
