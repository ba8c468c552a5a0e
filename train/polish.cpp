#include "train/polish.hpp"

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <type_traits>

#include "core/offdomain.hpp"
#include "core/rng.hpp"
#include "cpu/flush_denormals.hpp"
#include "cpu/loss_step.hpp"
#include "cpu/mlp_jet.hpp"
#include "cpu/polish_kernel.hpp"
#include "train/lbfgs.hpp"

namespace yarnhom {

static_assert(std::string_view(kLbfgsNoProgress) == std::string_view(kPolishNoProgress));

namespace {

// A regular midpoint grid of the off-domain band [-1.5, 1.5]^d minus [-1, 1]^d with spacing
// 0.5 / layers, and the normals of core/offdomain.hpp (nearest face; in a corner the face the
// point is farthest beyond). A dense deterministic set: with a few hundred random points held
// fixed, L-BFGS learned to satisfy L_S at exactly those points (measured: training L_S 1e-6
// while the validation L_S at other points rose 20-fold).
void offdomain_grid(int d, int layers, std::vector<float>& x, std::vector<float>& n) {
  const double w = kOffDomainOuter - 1.0, h = w / layers;
  x.clear();
  n.clear();
  if (d == 1) {
    for (int side : {-1, 1})
      for (int k = 0; k < layers; ++k) {
        x.push_back(float(side * (1.0 + (k + 0.5) * h)));
        n.push_back(float(side));
      }
    return;
  }
  const int m = int(std::lround(2 * kOffDomainOuter / h));  // cells per axis over [-1.5, 1.5]
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      const double px = -kOffDomainOuter + (i + 0.5) * h, py = -kOffDomainOuter + (j + 0.5) * h;
      const double ex = std::abs(px) - 1.0, ey = std::abs(py) - 1.0;  // excess beyond the faces
      if (ex < 0 && ey < 0) continue;
      x.push_back(float(px));
      x.push_back(float(py));
      const bool along_x = ex >= ey;
      n.push_back(float(along_x ? (px > 0 ? 1.0 : -1.0) : 0.0));
      n.push_back(float(along_x ? 0.0 : (py > 0 ? 1.0 : -1.0)));
    }
}

}  // namespace

namespace {

// The relative fit's weight of a point with |g|^2 = a, before normalization.
double raw_relative_weight(double a, double g2, double floor) { return 1.0 + 1.0 / (a / g2 + floor * floor); }

double squared_norm(const std::vector<float>& g, int d, size_t p) {
  double a = 0;
  for (int i = 0; i < d; ++i) a += double(g[p * d + i]) * g[p * d + i];
  return a;
}

}  // namespace

RelativeFitScale relative_fit_scale(const std::vector<float>& g_train, int d, double floor) {
  RelativeFitScale sc;
  const size_t n = g_train.size() / size_t(d);
  if (n == 0) return sc;
  double g2 = 0;
  for (float v : g_train) g2 += double(v) * v;
  sc.g2 = g2 / double(n);
  if (!(sc.g2 > 0)) sc.g2 = 1;  // a flat term: every weight is the same
  double mean = 0;
  for (size_t p = 0; p < n; ++p) mean += raw_relative_weight(squared_norm(g_train, d, p), sc.g2, floor);
  sc.norm = double(n) / mean;
  return sc;
}

std::vector<float> relative_fit_weights(const std::vector<float>& g, int d, double floor,
                                        const RelativeFitScale& sc) {
  const size_t n = g.size() / size_t(d);
  std::vector<float> w(n);
  for (size_t p = 0; p < n; ++p) w[p] = float(sc.norm * raw_relative_weight(squared_norm(g, d, p), sc.g2, floor));
  return w;
}

namespace {

// The job's float data as T: the vector itself for float, a converted copy for double;
// nullptr when empty. Not copyable (it may point into itself).
template <class T>
class AsT {
 public:
  explicit AsT(const std::vector<float>& v) {
    if constexpr (std::is_same_v<T, float>) {
      p_ = v.empty() ? nullptr : v.data();
    } else {
      copy_.assign(v.begin(), v.end());
      p_ = copy_.empty() ? nullptr : copy_.data();
    }
  }
  AsT(const AsT&) = delete;
  AsT& operator=(const AsT&) = delete;
  const T* data() const { return p_; }

 private:
  std::vector<T> copy_;
  const T* p_ = nullptr;
};

// The polish computing its losses in T (float or double; the L-BFGS state is double either way).
template <class T>
PolishResult polish_in(const NetworkJob& job, const TrainConfig& cfg, const PolishOptions& opt,
                       std::vector<float>& params) {
  cpu::flush_denormals();
  const double t0 = omp_get_wtime();
  PolishResult res;
  const int d = job.desc.input_dim, P = job.desc.num_params();
  std::vector<float> xo, no;
  if ((opt.w_s >= 0 ? opt.w_s : cfg.loss.w.s) != 0 && opt.off_domain_layers > 0) offdomain_grid(d, opt.off_domain_layers, xo, no);
  const int K = int(xo.size()) / d;
  std::vector<float> wt_train, wt_val;
  const double floor = opt.relative_floor[d == 1 ? 0 : 1];
  if (floor > 0) {
    const RelativeFitScale sc = relative_fit_scale(job.g_train, d, floor);
    wt_train = relative_fit_weights(job.g_train, d, floor, sc);
    wt_val = relative_fit_weights(job.g_val, d, floor, sc);
  }
  // The data in T (copies only when T is double).
  const AsT<T> xt(job.x_train), yt(job.y_train), gt(job.g_train), xv(job.x_val), yv(job.y_val), gv(job.g_val),
      xot(xo), not_(no), xov(job.xo_val), nov(job.no_val), wtt(wt_train), wtv(wt_val);
  const cpu::LossBatch<T> train{job.n_train, xt.data(), yt.data(), gt.data(), K, xot.data(), not_.data(), wtt.data()};
  const cpu::LossBatch<T> val{job.n_val, xv.data(), yv.data(), gv.data(), int(job.xo_val.size()) / d, xov.data(),
                              nov.data(), wtv.data()};
  cpu::LossWorkspace<T> ws;
  std::vector<T> pf(P), gf(P);
  auto to_float = [&](const Eigen::VectorXd& x) {
    for (int i = 0; i < P; ++i) pf[i] = T(x[i]);
  };
  // The loss of the polish: the epochs' loss, with L_C's weight replaced if asked.
  cpu::LossOptions loss = cfg.loss;
  if (opt.w_c >= 0) loss.w.c = opt.w_c;
  if (opt.w_s >= 0) loss.w.s = opt.w_s;
  // The rest curvature penalty: the jet at x_rest to second order, its second-order channels
  // against NetworkJob::curvature_rest (those that are known).
  const int c2 = jet_first(d, 2), n2 = jet_num_pairs(d);
  const double rest_w = d == 1 ? opt.rest_weight : opt.rest_weight_2d;
  bool rest = rest_w > 0;
  for (int k = 0; k < d; ++k) rest = rest && std::isfinite(job.x_rest[k]);
  bool any = false;
  for (int c = 0; c < n2; ++c) any = any || std::isfinite(job.curvature_rest[c]);
  rest = rest && any;
  cpu::JetWorkspace<T> rws;
  auto rest_penalty = [&](const std::vector<T>& p, T* grad) -> double {
    if (!rest) return 0.0;
    const T xr[2] = {T(job.x_rest[0]), T(job.x_rest[d - 1])};
    T jet[kMaxJetChannels], dj[kMaxJetChannels] = {};
    cpu::mlp_jet_forward<T>(job.desc, p.data(), xr, 1, 2, jet, rws);
    double pen = 0;
    for (int c = 0; c < n2; ++c) {
      if (!std::isfinite(job.curvature_rest[c])) continue;
      const double r = double(jet[c2 + c]) - double(job.curvature_rest[c]);
      dj[c2 + c] = T(2 * rest_w * r);
      pen += rest_w * r * r;
    }
    if (grad) cpu::mlp_jet_backward<T>(job.desc, p.data(), xr, 1, 2, dj, grad, rws);
    return pen;
  };
  // Which iterate to keep is judged by the data terms on the validation points: the fit
  // the model is for. (The validation L_S, at other off-domain points than the polish's,
  // would reward iterates that fit worse; see off_domain_layers.)
  // The default recipe's polish (data losses only, order-1 jets, Net-2 or Net-3) runs on the
  // fused kernel (cpu/polish_kernel.hpp); anything else on the epochs' mlp_loss_grad.
  const bool fused = loss.w.c == 0 && loss.w.x == 0 && (K == 0 || loss.w.s == 0) &&
                     cpu::fused_order1_supported(job.desc);
  cpu::FusedWorkspace<T> fws;
  auto data_loss = [&](const T* p, const cpu::LossBatch<T>& b, T* grad) {
    return fused ? cpu::fused_data_loss_grad<T>(job.desc, p, b, loss.w, grad, fws)
                 : cpu::mlp_loss_grad<T>(job.desc, p, b, loss, grad, ws, 1);
  };
  auto val_loss = [&](const std::vector<T>& p, const double* pen = nullptr) {
    const cpu::LossValues v = data_loss(p.data(), val, nullptr);
    return loss.w.z * v.z + loss.w.f * v.f + (pen ? *pen : rest_penalty(p, nullptr));
  };
  double last_pen = 0;  // the rest penalty at pf, the point of the last evaluation
  const LbfgsObjective fg = [&](const Eigen::VectorXd& x, Eigen::VectorXd& g) {
    to_float(x);
    const cpu::LossValues v = data_loss(pf.data(), train, gf.data());
    const double pen = last_pen = rest_penalty(pf, gf.data());
    for (int i = 0; i < P; ++i) g[i] = gf[i];
    return v.total + pen;
  };

  std::vector<T> best(params.begin(), params.end());
  res.val_start = res.val_end = val_loss(best);
  double best_val = res.val_start;
  const LbfgsObserver observe = [&](int k, const Eigen::VectorXd& x, double f) {
    // The accepted iterate is the point of the last evaluation (lbfgs_minimize evaluates there
    // last): when pf already holds it bit for bit, its rest penalty is last_pen.
    bool same = true;
    for (int i = 0; i < P; ++i) {
      const T t = T(x[i]);
      same = same && std::memcmp(&t, &pf[i], sizeof(T)) == 0;
      pf[i] = t;
    }
    const double v = val_loss(pf, same ? &last_pen : nullptr);
    res.train_loss.push_back(f);
    res.val_loss.push_back(v);
    if (!opt.keep_best || v < best_val || !std::isfinite(best_val)) {
      best_val = v;
      best = pf;
      res.best_iteration = k;
    }
    return true;
  };
  Eigen::VectorXd x(P);
  for (int i = 0; i < P; ++i) x[i] = params[i];
  LbfgsOptions lo;
  lo.max_iterations = d == 1 && opt.iterations_1d >= 0 ? opt.iterations_1d : opt.iterations;
  lo.memory = polish_memory(opt, d);
  const LbfgsResult r = lbfgs_minimize(x, fg, lo, observe);
  res.iterations = r.iterations;
  res.evaluations = r.evaluations;
  res.train_start = r.f0;
  res.stop = r.stop;
  params.assign(best.begin(), best.end());
  res.val_end = best_val;
  res.train_end = res.best_iteration > 0 ? res.train_loss[res.best_iteration - 1] : r.f0;
  res.seconds = omp_get_wtime() - t0;
  return res;
}

}  // namespace

int polish_memory(const PolishOptions& opt, int input_dim) {
  return input_dim == 2 && opt.memory_2d > 0 ? opt.memory_2d : opt.memory;
}

bool polish_stalled_high(const PolishResult& r, const PolishOptions& opt) {
  if (!(opt.stall_ratio > 0) || r.iterations == 0 || r.stop != kPolishNoProgress) return false;
  return r.train_loss.back() > opt.stall_ratio * r.train_start;
}

PolishResult choose_polish_retry(PolishResult first, PolishResult retry, std::vector<float>& params,
                                 std::vector<float>& retry_params) {
  const double seconds = first.seconds + retry.seconds;
  const bool take = retry.val_end < first.val_end || (!std::isfinite(first.val_end) && std::isfinite(retry.val_end));
  PolishResult& kept = take ? retry : first;
  if (take) params.swap(retry_params);
  char note[200];
  std::snprintf(note, sizeof note,
                "; stalled in float at %.3g of the start's loss after %d iterations, retried in double (%d): kept "
                "the %s run",
                first.train_loss.back() / first.train_start, first.iterations, retry.iterations,
                take ? "double" : "float");
  kept.stop += note;
  kept.retried = true;
  kept.seconds = seconds;
  return std::move(kept);
}

PolishResult polish_network(const NetworkJob& job, const TrainConfig& cfg, const PolishOptions& opt,
                            std::vector<float>& params) {
  if (opt.in_double[job.desc.input_dim == 1 ? 0 : 1]) return polish_in<double>(job, cfg, opt, params);
  std::vector<float> again = params;
  PolishResult r = polish_in<float>(job, cfg, opt, params);
  if (!polish_stalled_high(r, opt)) return r;
  // A float polish stuck far above where it started from (a flat region whose decreases are
  // below the float loss's rounding): the whole polish again in double, from the same start.
  PolishResult r2 = polish_in<double>(job, cfg, opt, again);
  return choose_polish_retry(std::move(r), std::move(r2), params, again);
}

}  // namespace yarnhom
