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

// v's three entries of a 3n array.
inline void add3(double* a, int v, const Eigen::Vector3d& g) {
  a[3 * v] += g[0], a[3 * v + 1] += g[1], a[3 * v + 2] += g[2];
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
                                    double* coupling) {
  Vec18 dq = Vec18::Zero();
  for (int i = 0; i < 3; ++i) {
    dq.segment<3>(3 * i) = move.segment<3>(3 * m.tris(t, i));
    if (fl[i]) dq.segment<3>(9 + 3 * i) = move.segment<3>(3 * m.flaps(t, i));
  }
  if (!(dq.cwiseAbs().maxCoeff() > 0)) return;
  const Vec18 r = H * dq;
  for (int i = 0; i < 3; ++i) {
    add3(coupling, m.tris(t, i), r.segment<3>(3 * i));
    if (fl[i]) add3(coupling, m.flaps(t, i), r.segment<3>(9 + 3 * i));
  }
}

// The element loop's chunks (shell_energy_derivatives): fixed runs of triangles, each
// with the vertex range and the value slots its triangles write, and arenas where each chunk
// sums its part. Kept with the pattern (sim/hessian_pattern.hpp) across calls.
// Runs of 512 triangles over the first 3/4 of the mesh, then of 128: the threads take them in
// order, so the small ones at the end even out the threads' finishing times (a 512-run is
// about 4 ms of one of the GPU host's threads), while most of the mesh goes in runs whose
// arena slices overlap less (the T-shirt's slices hold 2.4 x the matrix's slots at 512).
constexpr int kChunk = 512, kTailChunk = 128;

void sum_chunks(int64_t n, const std::vector<int64_t>& lo, const std::vector<int64_t>& hi,
                const std::vector<int64_t>& off, const std::vector<double>& arena, double* out);

}  // namespace

struct ElementChunks {
  int triangles = -1;
  std::vector<int> first;               // chunk c: triangles first[c] .. first[c + 1]
  bool with_slots = false;
  std::vector<int64_t> vlo, vhi, voff;  // gradient entries [vlo, vhi) at voff in the arenas
  std::vector<int64_t> hlo, hhi, hoff;  // value slots [hlo, hhi) at hoff in harena
  std::vector<double> garena, carena, harena;
  std::vector<double> energy;           // per chunk
};

namespace {

void layout_chunks(const Mesh& m, const HessianPattern* pattern, ElementChunks& C) {
  const int nt = m.num_triangles();
  C.first.assign(1, 0);
  for (int t = 0; t < nt;) {
    t = std::min(nt, t + (t < nt - nt / 4 ? kChunk : kTailChunk));
    C.first.push_back(t);
  }
  const int nchunks = int(C.first.size()) - 1;
  C.triangles = nt;
  C.with_slots = pattern != nullptr;
  C.vlo.assign(size_t(nchunks), INT64_MAX), C.vhi.assign(size_t(nchunks), 0);
  C.hlo.assign(pattern ? size_t(nchunks) : 0, INT64_MAX), C.hhi.assign(pattern ? size_t(nchunks) : 0, 0);
#pragma omp parallel for schedule(static) if (nt >= kParallelElements)
  for (int c = 0; c < nchunks; ++c)
    for (int t = C.first[size_t(c)]; t < C.first[size_t(c) + 1]; ++t) {
      for (int i = 0; i < 3; ++i)
        for (int v : {m.tris(t, i), m.flaps(t, i)}) {
          if (v < 0) continue;
          C.vlo[size_t(c)] = std::min(C.vlo[size_t(c)], int64_t(3 * v));
          C.vhi[size_t(c)] = std::max(C.vhi[size_t(c)], int64_t(3 * v + 3));
        }
      if (!pattern) continue;
      for (int k = 0; k < 108; ++k) {
        const int sl = pattern->elem_slots[size_t(t) * 108 + size_t(k)];
        if (sl < 0) continue;
        C.hlo[size_t(c)] = std::min(C.hlo[size_t(c)], int64_t(sl));
        C.hhi[size_t(c)] = std::max(C.hhi[size_t(c)], int64_t(sl) + 3);  // a column's slots: the first stored row and (at most) two below
      }
    }
  auto offsets = [](std::vector<int64_t>& lo, std::vector<int64_t>& hi, std::vector<int64_t>& off) {
    off.assign(lo.size() + 1, 0);
    for (size_t c = 0; c < lo.size(); ++c) {
      if (hi[c] <= lo[c]) lo[c] = hi[c] = 0;  // (a chunk that writes nothing)
      off[c + 1] = off[c] + (hi[c] - lo[c]);
    }
  };
  offsets(C.vlo, C.vhi, C.voff);
  if (pattern) offsets(C.hlo, C.hhi, C.hoff);
  C.garena.resize(size_t(C.voff.back()));
  C.harena.resize(pattern ? size_t(C.hoff.back()) : 0);
  C.energy.resize(size_t(nchunks));
}

// out[i] += the chunks' arenas at i, chunk 0 first (each entry's sum in the same order whatever
// the thread count), the entries spread over the threads in blocks, each block visiting only
// the chunks whose range reaches into it.
void sum_chunks(int64_t n, const std::vector<int64_t>& lo, const std::vector<int64_t>& hi,
                const std::vector<int64_t>& off, const std::vector<double>& arena, double* out) {
  constexpr int64_t kBlock = 4096;
  const int64_t nblocks = (n + kBlock - 1) / kBlock;
#pragma omp parallel for schedule(static) if (nblocks > 4)
  for (int64_t b = 0; b < nblocks; ++b) {
    const int64_t i0 = b * kBlock, i1 = std::min(n, i0 + kBlock);
    for (size_t c = 0; c < lo.size(); ++c) {
      const int64_t a = std::max(i0, lo[c]), e = std::min(i1, hi[c]);
      const double* src = arena.data() + off[c] - lo[c];
      for (int64_t i = a; i < e; ++i) out[i] += src[i];
    }
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
  const int nt = m.num_triangles();
  // Fixed chunks of triangles (layout_chunks), taken by the threads as they come (the cost of a triangle
  // varies: its eigenproblems, its material's tables; fixed ranges per thread left the slowest
  // of 16 threads 20 % behind the mean). Each chunk sums its energy, gradient and Hessian in its
  // own place (an arena slice over the vertices and value slots it touches, laid out once per
  // pattern); the chunks' parts are then added in chunk order. So every sum has one order, on
  // any number of threads.
  std::shared_ptr<ElementChunks> local;
  ElementChunks* C = nullptr;
  if (hess) {
    if (!pattern->chunks) pattern->chunks = std::make_shared<ElementChunks>();
    C = pattern->chunks.get();
  } else {
    local = std::make_shared<ElementChunks>();
    C = local.get();
  }
  if (C->triangles != nt || C->with_slots != hess) layout_chunks(m, hess ? pattern : nullptr, *C);
  if (couple && C->carena.size() != C->garena.size()) C->carena.resize(C->garena.size());
  const int nchunks = int(C->energy.size());
  const int nthreads = nt >= kParallelElements ? omp_get_max_threads() : 1;
  std::vector<ShellTimings> tim(nthreads);
#pragma omp parallel num_threads(nthreads) if (nthreads > 1)
  {
    ShellTimings& tm = tim[omp_get_thread_num()];
#pragma omp for schedule(dynamic, 1)
    for (int c = 0; c < nchunks; ++c) {
      // This chunk's places, zeroed, offset so that entry i of a 3n array (slot k) is g[i] (hv[k]).
      const size_t c_ = size_t(c);
      std::fill(C->garena.begin() + C->voff[c_], C->garena.begin() + C->voff[c_ + 1], 0.0);
      double* g = C->garena.data() + C->voff[c_] - C->vlo[c_];
      double* cp = nullptr;
      if (couple) {
        std::fill(C->carena.begin() + C->voff[c_], C->carena.begin() + C->voff[c_ + 1], 0.0);
        cp = C->carena.data() + C->voff[c_] - C->vlo[c_];
      }
      double* hv = nullptr;
      if (hess) {
        std::fill(C->harena.begin() + C->hoff[c_], C->harena.begin() + C->hoff[c_ + 1], 0.0);
        hv = C->harena.data() + C->hoff[c_] - C->hlo[c_];
      }
      double E = 0;
      auto t0 = Clock::now();
      for (int t = C->first[c_]; t < C->first[c_ + 1]; ++t) {
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
          add3(g, m.tris(t, i), ge.segment<3>(3 * i));
          if (fl[i]) add3(g, m.flaps(t, i), ge.segment<3>(9 + 3 * i));
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
        if (timings) {
          tm.project += since(t0);
          tm.projected += changed;
        }
        add_element_hessian(*pattern, t, H, hv);
        if (cp) add_coupling(m, t, fl, H, *move, cp);
        if (timings) tm.scatter += since(t0);
      }
      C->energy[c_] = E;
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
  }
  prof::Scope ps_sums("derivatives: elements, the chunks' sums");
  double E = 0;
  for (double e : C->energy) E += e;
  sum_chunks(grad.size(), C->vlo, C->vhi, C->voff, C->garena, grad.data());
  if (couple) sum_chunks(coupling->size(), C->vlo, C->vhi, C->voff, C->carena, coupling->data());
  if (hess) sum_chunks(pattern->matrix.nonZeros(), C->hlo, C->hhi, C->hoff, C->harena, values);
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
