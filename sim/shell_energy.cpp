#include "sim/shell_energy.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdint>

#include "core/scope_profile.hpp"
#include "sim/inplane_strain.hpp"
#include "numerics/psd_projection.hpp"
#include "sim/shell_strain.hpp"

namespace yarnhom::sim {

namespace {

Vec18 gather(const Mesh& m, const Eigen::VectorXd& x, int t, bool has_flap[3]) {
  Vec18 q = Vec18::Zero();
  for (int i = 0; i < 3; ++i) {
    q.segment<3>(3 * i) = x.segment<3>(3 * m.tris(t, i));
    const int f = m.flaps(t, i);
    has_flap[i] = f >= 0;
    if (f >= 0) q.segment<3>(9 + 3 * i) = x.segment<3>(3 * f);
  }
  return q;
}

// Below this many triangles one thread does the loop: a fork and join costs more than the work,
// and much more when the cores are shared (OpenMP barriers wait on descheduled threads).
constexpr int kParallelElements = 1024;

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point& t0) {
  const auto t1 = Clock::now();
  const double s = std::chrono::duration<double>(t1 - t0).count();
  t0 = t1;
  return s;
}

// coupling += H_e move_e over the element's nodes (vertices and flaps), where move touches it.
// Kept out of line: the element loop's code, and so its rounding, stays as it was without it.
[[gnu::noinline]] void add_coupling(const Mesh& m, int t, const bool fl[3], const Mat18& H, const Eigen::VectorXd& move,
                                    Eigen::VectorXd& coupling) {
  Vec18 dq = Vec18::Zero();
  for (int i = 0; i < 3; ++i) {
    dq.segment<3>(3 * i) = move.segment<3>(3 * m.tris(t, i));
    if (fl[i]) dq.segment<3>(9 + 3 * i) = move.segment<3>(3 * m.flaps(t, i));
  }
  if (!(dq.cwiseAbs().maxCoeff() > 0)) return;
  const Vec18 r = H * dq;
  for (int i = 0; i < 3; ++i) {
    coupling.segment<3>(3 * m.tris(t, i)) += r.segment<3>(3 * i);
    if (fl[i]) coupling.segment<3>(3 * m.flaps(t, i)) += r.segment<3>(9 + 3 * i);
  }
}

}  // namespace

std::vector<ElementRest> make_element_rests(const Mesh& m) {
  std::vector<ElementRest> r(m.num_triangles());
  for (int t = 0; t < m.num_triangles(); ++t)
    r[t] = element_rest(m.rest.row(m.tris(t, 0)), m.rest.row(m.tris(t, 1)), m.rest.row(m.tris(t, 2)));
  return r;
}

double shell_energy(const Mesh& m, const std::vector<ElementRest>& rest, const MaterialFn& psi, const Eigen::VectorXd& x,
                    const double* theta_ref, const MaterialValueFn* value) {
  const bool fast = value && *value;
  double E = 0;
#pragma omp parallel for reduction(+ : E) schedule(static) if (m.num_triangles() >= kParallelElements)
  for (int t = 0; t < m.num_triangles(); ++t) {
    bool fl[3];
    const Vec18 q = gather(m, x, t, fl);
    const Strain6 s = shell_strain(q, rest[t], fl, nullptr, nullptr, nullptr, theta_ref ? theta_ref + 3 * t : nullptr);
    E += rest[t].area * (fast ? (*value)(s) : psi(s).psi);
  }
  return E;
}

double shell_energy_derivatives(const Mesh& m, const std::vector<ElementRest>& rest, const MaterialFn& psi,
                                const Eigen::VectorXd& x, Eigen::VectorXd& grad, const HessianPattern* pattern,
                                double* values, ShellTimings* timings, HessianModel model, const double* theta_ref,
                                numerics::EigenFilter filter, const Eigen::VectorXd* move, Eigen::VectorXd* coupling) {
  const bool hess = pattern && values;
  const bool couple = hess && move && coupling;
  const int nthreads = m.num_triangles() >= kParallelElements ? omp_get_max_threads() : 1;
  const int nt = m.num_triangles();
  // Each thread takes a contiguous range of triangles, first[k] .. first[k + 1]: with a Hessian,
  // ranges of equal estimated cost (a triangle projected at the last evaluation counts
  // kProjectedCost: the 6 x 6 eigenproblems take about 40 % of an element's time and gather
  // where the cloth is sheared or bent, so equal counts left the slowest of 16 threads 20 %
  // behind the mean); without, equal counts. The ranges depend on the last evaluation and the
  // thread count only: the same sums on a rerun.
  std::vector<int> first(size_t(nthreads) + 1, nt);
  const bool balance = hess && nthreads > 1 && pattern->projected.size() == size_t(nt);
  if (hess && pattern->projected.size() != size_t(nt)) pattern->projected.assign(size_t(nt), 0);
  if (balance) {
    constexpr double kProjectedCost = 1.7;
    double total = 0;
    for (int t = 0; t < nt; ++t) total += pattern->projected[size_t(t)] ? kProjectedCost : 1.0;
    double acc = 0;
    int k = 1;
    first[0] = 0;
    for (int t = 0; t < nt && k < nthreads; ++t) {
      acc += pattern->projected[size_t(t)] ? kProjectedCost : 1.0;
      while (k < nthreads && acc >= total * k / nthreads) first[size_t(k++)] = t + 1;
    }
  } else {
    for (int k = 0; k <= nthreads; ++k) first[size_t(k)] = int(int64_t(nt) * k / nthreads);
  }
  // The value slots each chunk of triangles writes, found once per pattern (the scan reads the
  // whole slot table, 12 MB on a T-shirt).
  constexpr int kChunk = HessianPattern::kBandChunk;
  const int nchunks = (nt + kChunk - 1) / kChunk;
  if (hess && pattern->chunk_bands.size() != size_t(nchunks)) {
    pattern->chunk_bands.assign(size_t(nchunks), {INT32_MAX, -1});
#pragma omp parallel for schedule(static) if (nthreads > 1)
    for (int c = 0; c < nchunks; ++c) {
      int lo = INT32_MAX, hi = -1;
      for (int t = c * kChunk; t < std::min(nt, (c + 1) * kChunk); ++t)
        for (int k = 0; k < 108; ++k) {
          const int sl = pattern->elem_slots[size_t(t) * 108 + size_t(k)];
          if (sl < 0) continue;
          lo = std::min(lo, sl);
          hi = std::max(hi, sl + 2);  // a column's slots: the first stored row and (at most) two below
        }
      pattern->chunk_bands[size_t(c)] = {lo, hi};
    }
  }
  // Thread 0 accumulates straight into the outputs; the others into their own arrays. A
  // thread's Hessian array spans only the value slots its triangles' chunks write (a band of
  // the matrix), set up by the thread itself; thread k holds slots [h_lo[k], h_lo[k] +
  // h_local[k].size()).
  std::vector<Eigen::VectorXd> g_local(nthreads - 1);
  std::vector<std::vector<double>> h_local(hess ? nthreads - 1 : 0);
  std::vector<size_t> h_lo(h_local.size(), 0);
  std::vector<Eigen::VectorXd> c_local(couple ? nthreads - 1 : 0);
  std::vector<ShellTimings> tim(nthreads);
  std::vector<double> setup(size_t(nthreads), 0.0);  // each thread's time before its loop
  double E = 0;
#pragma omp parallel num_threads(nthreads) reduction(+ : E) if (nthreads > 1)
  {
    const int tid = omp_get_thread_num();
    const auto t_setup = Clock::now();
    if (tid > 0) {
      g_local[tid - 1] = Eigen::VectorXd::Zero(grad.size());
      if (couple) c_local[tid - 1] = Eigen::VectorXd::Zero(grad.size());
    }
    const int t_begin = first[size_t(tid)], t_end = first[size_t(tid) + 1];
    if (hess && tid > 0 && t_end > t_begin) {
      int lo = INT32_MAX, hi = -1;
      for (int c = t_begin / kChunk; c <= (t_end - 1) / kChunk; ++c)
        lo = std::min(lo, pattern->chunk_bands[size_t(c)][0]), hi = std::max(hi, pattern->chunk_bands[size_t(c)][1]);
      if (hi >= lo) {
        h_lo[tid - 1] = size_t(lo);
        h_local[tid - 1].assign(size_t(hi - lo + 1), 0.0);
      }
    }
    Eigen::VectorXd& g = tid == 0 ? grad : g_local[tid - 1];
    double* hv = hess ? (tid == 0 ? values : h_local[tid - 1].data() - h_lo[tid - 1]) : nullptr;
    ShellTimings& tm = tim[tid];
    Eigen::VectorXd* cp = couple ? (tid == 0 ? coupling : &c_local[tid - 1]) : nullptr;
    auto t0 = Clock::now();
    setup[size_t(tid)] = std::chrono::duration<double>(t0 - t_setup).count();
    for (int t = t_begin; t < t_end; ++t) {
      bool fl[3];
      const Vec18 q = gather(m, x, t, fl);
      Jac6x18 J;
      const double* ref = theta_ref ? theta_ref + 3 * t : nullptr;
      const Strain6 s = shell_strain(q, rest[t], fl, &J, nullptr, nullptr, ref);
      if (timings) tm.strain += since(t0);
      const MaterialEval me = psi(s);
      if (timings) tm.material += since(t0);
      const double A = rest[t].area;
      E += A * me.psi;
      const Vec18 ge = A * (J.transpose() * me.grad);
      for (int i = 0; i < 3; ++i) {
        g.segment<3>(3 * m.tris(t, i)) += ge.segment<3>(3 * i);
        if (fl[i]) g.segment<3>(3 * m.flaps(t, i)) += ge.segment<3>(9 + 3 * i);
      }
      if (!hess) continue;
      Mat18 H;
      bool changed = false;
      if (model == HessianModel::Split) {
        // J^T [H]_+ J + C^T [Hf]_+ C (sim/hessian_model.hpp); no bending curvature term.
        Eigen::Matrix<double, 6, 6> Hs = me.hess;
        changed = numerics::project_psd(Hs, filter);
        if (timings) tm.project += since(t0);  // the in-plane term's 6 x 6 projection counts as chain rule
        H.noalias() = J.transpose() * Hs * J;
        Mat9 Hin;
        const Eigen::Vector3d gin = me.grad.head<3>();
        inplane_strain(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), rest[t].Binv, nullptr, &gin, &Hin, true, filter);
        H.block<9, 9>(0, 0) += Hin;
        H *= A;
        if (timings) tm.chain += since(t0);
      } else {
        shell_strain(q, rest[t], fl, nullptr, &me.grad, &H, ref);
        H += J.transpose() * me.hess * J;
        H *= A;
        if (timings) tm.chain += since(t0);
        changed = model == HessianModel::ProjectedElement && numerics::project_psd(H, filter);
      }
      pattern->projected[size_t(t)] = changed;
      if (timings) {
        tm.project += since(t0);
        tm.projected += changed;
      }
      add_element_hessian(*pattern, t, H, hv);
      if (cp) add_coupling(m, t, fl, H, *move, *cp);
      if (timings) tm.scatter += since(t0);
    }
  }
  if (timings && nthreads > 1) {  // the loop's balance: its slowest thread against the mean
    double slowest = 0, sum = 0;
    for (const ShellTimings& t : tim) {
      const double s = t.strain + t.material + t.chain + t.project + t.scatter;
      slowest = std::max(slowest, s), sum += s;
    }
    prof::add("derivatives: elements, the slowest thread's loop", slowest);
    prof::add("derivatives: elements, the threads' mean loop", sum / nthreads);
    prof::add("derivatives: elements, the slowest thread's set-up", *std::max_element(setup.begin(), setup.end()));
  }
  prof::Scope ps_sums("derivatives: elements, the threads' sums");
  // The threads' gradients added entry by entry, thread 1 first (the same sums as one thread's
  // array after another), the entries spread over the threads.
  if (nthreads > 1) {
    const int64_t n = int64_t(grad.size());
#pragma omp parallel for schedule(static)
    for (int64_t i = 0; i < n; ++i)
      for (int k = 0; k < nthreads - 1; ++k) {
        grad[i] += g_local[size_t(k)][i];
        if (couple) (*coupling)[i] += c_local[size_t(k)][i];
      }
  }
  // The threads' Hessian bands added slot by slot, thread 1 first (each slot's sum in the same
  // order as one thread after another; a slot outside a band would add 0), the slots spread
  // over the threads in blocks, each block visiting only the bands that reach into it.
  if (hess && !h_local.empty()) {
    const int64_t nnz = int64_t(pattern->matrix.nonZeros());
    constexpr int64_t kBlock = 4096;
    const int64_t nblocks = (nnz + kBlock - 1) / kBlock;
#pragma omp parallel for schedule(static)
    for (int64_t b = 0; b < nblocks; ++b) {
      const int64_t i0 = b * kBlock, i1 = std::min(nnz, i0 + kBlock);
      for (size_t k = 0; k < h_local.size(); ++k) {
        const int64_t lo = std::max(i0, int64_t(h_lo[k])), hi = std::min(i1, int64_t(h_lo[k] + h_local[k].size()));
        const double* src = h_local[k].data() - h_lo[k];
        for (int64_t i = lo; i < hi; ++i) values[i] += src[i];
      }
    }
  }
  if (timings) {
    for (const ShellTimings& tm : tim) *timings += tm;  // per-thread elements are 0: counted below
    timings->elements += m.num_triangles();
  }
  return E;
}

std::vector<Strain6> triangle_strains(const Mesh& m, const std::vector<ElementRest>& rest, const Eigen::VectorXd& x,
                                      const double* theta_ref) {
  std::vector<Strain6> out(m.num_triangles());
#pragma omp parallel for schedule(static) if (m.num_triangles() >= kParallelElements)
  for (int t = 0; t < m.num_triangles(); ++t) {
    bool fl[3];
    out[t] = shell_strain(gather(m, x, t, fl), rest[t], fl, nullptr, nullptr, nullptr, theta_ref ? theta_ref + 3 * t : nullptr);
  }
  return out;
}

}  // namespace yarnhom::sim
