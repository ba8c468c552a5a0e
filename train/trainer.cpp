#include "train/trainer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/offdomain.hpp"
#include "core/rng.hpp"
#include "cpu/network_eval.hpp"

namespace yarnhom {

bool TrainResult::all_ok() const {
  for (const ProgressRow& r : rows)
    if (r.status != "ok") return false;
  return true;
}

namespace {

int catalogue_index(const Term& t) {
  const auto& all = all_terms();
  for (size_t i = 0; i < all.size(); ++i)
    if (all[i].name == t.name) return int(i);
  throw std::invalid_argument("unknown term " + t.name);
}

// PyTorch's nn.Linear default initialization: W and b uniform in +-1/sqrt(fan_in).
std::vector<float> init_params(const NetworkDesc& desc, uint64_t key) {
  std::vector<float> p(desc.num_params());
  const uint64_t k = rng_key(key, kRngInit);
  uint64_t counter = 0;
  for (int l = 0; l < desc.num_layers(); ++l) {
    const double bound = 1.0 / std::sqrt(double(desc.layer_in(l)));
    const int n = desc.layer_out(l) * (desc.layer_in(l) + 1);
    for (int i = 0; i < n; ++i)
      p[desc.weight_offset(l) + i] = float(bound * (2.0 * rng_uniform(k, counter++) - 1.0));
  }
  return p;
}

}  // namespace

NetworkJob make_job(const TermData& data, const TrainerOptions& opt, Normalization* norm_out,
                    const std::vector<double>* rest_hessian) {
  const int d = data.dim(), n = data.n;
  NetworkJob job;
  job.name = data.term.name;
  job.desc = opt.net;
  job.desc.input_dim = d;
  if (d == 2 && !opt.hidden_2d.empty()) job.desc.hidden = opt.hidden_2d;
  job.desc.validate();
  job.key = rng_key(opt.seed, uint64_t(catalogue_index(data.term)));
  job.batch_size = d == 1 ? opt.batch_1d : opt.batch_2d;

  // Seeded split: a permutation; the first n_val indices validate.
  std::vector<int> perm(n);
  for (int i = 0; i < n; ++i) perm[i] = i;
  const uint64_t sk = rng_key(job.key, kRngSplit);
  for (int i = n - 1; i > 0; --i) std::swap(perm[i], perm[int(rng_uniform(sk, i) * (i + 1))]);
  int n_val = int(std::lround(opt.val_fraction * n));
  n_val = std::clamp(n_val, 1, n - 1);
  job.n_val = n_val;
  job.n_train = n - n_val;
  job.val_rows.assign(perm.begin(), perm.begin() + n_val);

  Normalization norm;
  for (int k = 0; k < d; ++k) {
    norm.center.push_back(0.5 * (data.lower[k] + data.upper[k]));
    norm.halfwidth.push_back(0.5 * (data.upper[k] - data.lower[k]));
  }
  double mean = 0, var = 0;
  for (int i = n_val; i < n; ++i) mean += data.energy[perm[i]];
  mean /= job.n_train;
  for (int i = n_val; i < n; ++i) var += (data.energy[perm[i]] - mean) * (data.energy[perm[i]] - mean);
  double sd = std::sqrt(var / job.n_train);
  // A term that is identically constant on its training points has nothing to scale by.
  if (!(sd > 0) || !std::isfinite(sd)) sd = 1.0;
  norm.out_mean = mean;
  norm.out_std = sd;

  auto fill = [&](int from, int to, std::vector<float>& x, std::vector<float>& y, std::vector<float>& g) {
    for (int i = from; i < to; ++i) {
      const int s = perm[i];
      y.push_back(float((data.energy[s] - mean) / sd));
      for (int k = 0; k < d; ++k) {
        x.push_back(float((data.strain[s * d + k] - norm.center[k]) / norm.halfwidth[k]));
        g.push_back(float(data.gradient[s * d + k] * norm.halfwidth[k] / sd));
      }
    }
  };
  fill(0, n_val, job.x_val, job.y_val, job.g_val);
  fill(n_val, n, job.x_train, job.y_train, job.g_train);

  bool inside = true;
  for (int k = 0; k < d; ++k) inside = inside && data.lower[k] < 0 && data.upper[k] > 0;
  if (inside) {
    for (int k = 0; k < d; ++k) job.x_rest[k] = float((0.0 - norm.center[k]) / norm.halfwidth[k]);
    // A second derivative in strain units to normalized ones.
    auto normalized = [&](double h, int a, int b) { return float(h * norm.halfwidth[a] * norm.halfwidth[b] / sd); };
    if (rest_hessian && rest_hessian->size() == 36) {
      const int i = data.term.indices[0], j = data.term.indices[d - 1];
      if (d == 1) {
        job.curvature_rest[0] = normalized((*rest_hessian)[i * 6 + i], 0, 0);
      } else {
        // Only the mixed one: the material takes a 2D network's axis projection
        // N(a,b) - N(a,0) - N(0,b) + N(0,0) (bake/term_function.hpp), whose f_aa and f_bb at the
        // origin are 0 whatever N is, and whose f_ab is N's.
        job.curvature_rest[1] = normalized((*rest_hessian)[i * 6 + j], 0, 1);
      }
    } else if (d == 1) {
      // The nodes nearest the rest on either side (all of them, training and validation).
      int lo = -1, hi = -1;
      for (int i = 0; i < n; ++i) {
        const double s = data.strain[i];
        if (s < 0 && (lo < 0 || s > data.strain[lo])) lo = i;
        if (s > 0 && (hi < 0 || s < data.strain[hi])) hi = i;
      }
      if (lo >= 0 && hi >= 0)
        job.curvature_rest[0] =
            normalized((data.gradient[hi] - data.gradient[lo]) / (data.strain[hi] - data.strain[lo]), 0, 0);
    }
  }

  const int kv = opt.config.val_off_domain;
  job.xo_val.resize(size_t(kv) * d);
  job.no_val.resize(size_t(kv) * d);
  const uint64_t vk = rng_key(job.key, kRngValOffDomain);
  for (int j = 0; j < kv; ++j) offdomain_point<float>(d, vk, j, &job.xo_val[j * d], &job.no_val[j * d]);
  job.init_params = init_params(job.desc, job.key);
  if (norm_out) *norm_out = norm;
  return job;
}

TrainResult train_terms(const Dataset& ds, const std::string& dataset_path,
                        const std::vector<Term>& terms, const TrainerOptions& opt, Backend& backend,
                        const ProgressFn& progress) {
  std::vector<NetworkJob> jobs;
  std::vector<Normalization> norms;
  std::vector<const TermData*> datas;
  for (const Term& t : terms) {
    const TermData* td = ds.find(t.name);
    if (!td) throw std::invalid_argument(dataset_path + ": the dataset has no term '" + t.name + "'");
    Normalization norm;
    jobs.push_back(make_job(*td, opt, &norm, &ds.rest_hessian));
    norms.push_back(norm);
    datas.push_back(td);
  }
  backend.setup(jobs, opt.config);

  const size_t J = jobs.size();
  std::vector<ReduceLROnPlateau> sched;
  for (size_t j = 0; j < J; ++j) sched.emplace_back(opt.config.adam.lr, opt.plateau);
  std::vector<double> lr(J, opt.config.adam.lr);
  std::vector<char> active(J, 1);
  std::vector<History> hist(J);
  TrainResult res;
  res.rows.resize(J);
  res.seconds.assign(J, 0.0);
  for (size_t j = 0; j < J; ++j) res.rows[j].name = jobs[j].name;
  // One network's epoch in the books: history, status, the plateau schedule. False once the
  // network has stopped (non-finite loss).
  auto record_epoch = [&](size_t j, int e, const EpochStats& st) {
    res.seconds[j] += st.seconds;
    ProgressRow& row = res.rows[j];
    row.stats = st;
    row.lr = lr[j];
    row.epochs_done = e + 1;
    if (!std::isfinite(st.train.total) || !std::isfinite(st.val.total)) {
      row.status = "non-finite loss at epoch " + std::to_string(e + 1);
      row.active = false;
      active[j] = 0;
      return false;
    }
    History& h = hist[j];
    h.train_loss.push_back(st.train.total);
    h.val_loss.push_back(st.val.total);
    h.lr.push_back(lr[j]);
    h.loss_z.push_back(st.train.z);
    h.loss_f.push_back(st.train.f);
    h.loss_c.push_back(st.train.c);
    h.loss_s.push_back(st.train.s);
    lr[j] = sched[j].step(st.val.total);
    return true;
  };
  // Longest first (cost ~ points x jet channels), as in the CPU backend's epochs.
  auto longest_first = [&](std::vector<int>& v) {
    std::stable_sort(v.begin(), v.end(), [&](int a, int b) {
      return double(jobs[a].n_train) * (jobs[a].desc.input_dim == 1 ? 4 : 10) >
             double(jobs[b].n_train) * (jobs[b].desc.input_dim == 1 ? 4 : 10);
    });
  };
  res.polish.assign(J, {});
  std::vector<std::vector<float>> final_params(J);
  const bool polish = opt.polish.iterations > 0;
  const int threads = std::max(1, opt.config.threads);

  if (backend.independent_networks() && J > 1 && threads > 1) {
    // Whole networks per thread: each task runs one network's epochs, then its polish, with no
    // barrier between the networks (a barrier per epoch waited for the slowest network of every
    // epoch, and on shared cores for every preempted thread). Each network's arithmetic is
    // what the per-epoch loop does, so the weights are the same for any thread count.
    std::vector<int> order(J);
    for (size_t j = 0; j < J; ++j) order[j] = int(j);
    longest_first(order);
    long done = 0;       // network-epochs recorded
    int reported = 0;    // epochs shown by the progress (done / J)
#pragma omp parallel for num_threads(std::min<int>(threads, int(J))) schedule(dynamic, 1)
    for (size_t i = 0; i < J; ++i) {
      const int j = order[i];
      for (int e = 0; e < opt.config.epochs; ++e) {
        const EpochStats st = backend.run_network_epoch(j, e, lr[j]);
        bool go = true;
#pragma omp critical(yarnhom_trainer_books)
        {
          go = record_epoch(size_t(j), e, st);
          const int ep = int(++done / long(J));
          if (progress && ep > reported && ep < opt.config.epochs) {
            reported = ep;
            progress(ep, opt.config.epochs, res.rows);
          }
        }
        if (!go) break;
      }
      if (res.rows[j].status == "ok") {
        final_params[j] = backend.params(j);
        if (polish) res.polish[j] = polish_network(jobs[j], opt.config, opt.polish, final_params[j]);
      }
    }
    if (progress) progress(opt.config.epochs, opt.config.epochs, res.rows);
  } else {
    std::vector<EpochStats> stats;
    for (int e = 0; e < opt.config.epochs; ++e) {
      backend.run_epoch(e, lr, active, stats);
      bool any = false;
      for (size_t j = 0; j < J; ++j)
        if (active[j]) any = record_epoch(j, e, stats[j]) || any;
      if (progress) progress(e + 1, opt.config.epochs, res.rows);
      if (!any) break;
    }
    for (size_t j = 0; j < J; ++j)
      if (res.rows[j].status == "ok") final_params[j] = backend.params(int(j));
    // The polish: independent per network, so the networks run in parallel (one per thread).
    if (polish) {
      std::vector<int> todo;
      for (size_t j = 0; j < J; ++j)
        if (res.rows[j].status == "ok") todo.push_back(int(j));
      longest_first(todo);
      // The backend's device takes what it can (the CUDA backend: all of the default recipe's
      // networks in one launch); the CPU polishes the rest, one network per thread.
      const std::vector<char> took = backend.polish(jobs, opt.config, opt.polish, todo, final_params, res.polish);
      std::vector<int> host;
      for (size_t i = 0; i < todo.size(); ++i)
        if (!took[i]) host.push_back(todo[i]);
      const int T = std::max(1, std::min<int>(threads, int(host.size())));
#pragma omp parallel for num_threads(T) schedule(dynamic, 1)
      for (size_t i = 0; i < host.size(); ++i) {
        const int j = host[i];
        res.polish[j] = polish_network(jobs[j], opt.config, opt.polish, final_params[j]);
      }
    }
  }
  if (polish)
    for (size_t j = 0; j < J; ++j) {
      if (res.rows[j].status != "ok") continue;
      res.seconds[j] += res.polish[j].seconds;
      if (!std::isfinite(res.polish[j].val_end)) res.rows[j].status = "non-finite loss in the polish";
    }

  res.val_fit.assign(J, {});
  res.all_fit.assign(J, {});
  res.model.dataset = dataset_path;
  res.model.areal_density = ds.areal_density;
  res.model.seed = opt.seed;
  for (size_t j = 0; j < J; ++j) {
    res.rows[j].active = false;
    if (res.rows[j].status != "ok") continue;
    ModelNetwork n;
    n.term = datas[j]->term;
    n.lower = datas[j]->lower;
    n.upper = datas[j]->upper;
    n.desc = jobs[j].desc;
    n.params = std::move(final_params[j]);
    n.norm = norms[j];
    n.weights = opt.config.loss.w;
    n.epochs = res.rows[j].epochs_done;
    n.backend = backend.name();
    n.history = std::move(hist[j]);
    n.history.polish_train = res.polish[j].train_loss;
    n.history.polish_val = res.polish[j].val_loss;
    n.recipe = opt.recipe;
    n.val_index = jobs[j].val_rows;
    // The fit in physical units, on the held-out points and on all of them.
    const std::vector<double> jet = cpu::eval_network_physical(n, datas[j]->strain.data(), datas[j]->n, 1);
    res.val_fit[j] = fit_quality(*datas[j], jet, n.val_index);
    res.all_fit[j] = fit_quality(*datas[j], jet);
    res.model.networks.push_back(std::move(n));
  }
  return res;
}

}  // namespace yarnhom
