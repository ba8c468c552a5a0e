#include "numerics/sparse_cholesky.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "core/scope_profile.hpp"
#include "numerics/block_jacobi_pcg.hpp"
#include "numerics/serial_openmp.hpp"
#ifdef YARNHOM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

namespace yarnhom::numerics {

SolverKind parse_solver_kind(const std::string& name) {
  if (name == "auto") return SolverKind::Auto;
  if (name == "ldlt") return SolverKind::Ldlt;
  if (name == "cholmod") {
    if (!cholmod_available()) throw std::invalid_argument("--solver cholmod: this build has no CHOLMOD (SuiteSparse)");
    return SolverKind::Cholmod;
  }
  if (name == "pcg") return SolverKind::Pcg;
  if (name == "pcg-cuda") {
    if (!pcg_device_factory()) throw std::invalid_argument("--solver pcg-cuda: this build has no CUDA");
    return SolverKind::PcgCuda;
  }
  throw std::invalid_argument("solver '" + name + "': expected auto, ldlt, cholmod, pcg or pcg-cuda");
}

const char* solver_kind_name(SolverKind k) {
  switch (k) {
    case SolverKind::Ldlt: return "ldlt";
    case SolverKind::Cholmod: return "cholmod";
    case SolverKind::Pcg: return "pcg";
    case SolverKind::PcgCuda: return "pcg-cuda";
    case SolverKind::Auto: break;
  }
  return cholmod_available() ? "cholmod" : "ldlt";
}

bool cholmod_available() {
#ifdef YARNHOM_HAVE_CHOLMOD
  return true;
#else
  return false;
#endif
}

struct SparseCholesky::Impl {
  bool use_cholmod = false;
  SolverKind kind = SolverKind::Auto;
  // The iterative kinds.
  BlockJacobiBuilder builder;
  BlockCsr system;
  std::unique_ptr<PcgDevice> device;
  double tol = 1e-3;
  int max_iterations = 20000;
  mutable long long iterations = 0, solves = 0;
  bool iterative() const { return kind == SolverKind::Pcg || kind == SolverKind::PcgCuda; }
  int analyses = 0;
  std::vector<int> last_outer, last_inner;  // the analysed pattern
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt;
#ifdef YARNHOM_HAVE_CHOLMOD
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> cholmod;
#endif

  bool same_pattern(const Eigen::SparseMatrix<double>& A) const {
    const Eigen::Index n = A.outerSize();
    if (last_outer.size() != size_t(n + 1) || last_inner.size() != size_t(A.nonZeros()) ||
        !std::equal(last_outer.begin(), last_outer.end(), A.outerIndexPtr()))
      return false;
    // (a simulator's matrix: millions of row indices, compared on the threads)
    const int64_t nnz = int64_t(last_inner.size());
    const int* a = A.innerIndexPtr();
    bool same = true;
#pragma omp parallel for schedule(static) reduction(&& : same) if (nnz >= (int64_t(1) << 18))
    for (int64_t k = 0; k < nnz; ++k) same = same && last_inner[size_t(k)] == a[k];
    return same;
  }
  void remember_pattern(const Eigen::SparseMatrix<double>& A) {
    last_outer.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
    last_inner.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    ++analyses;
  }
};

SparseCholesky::SparseCholesky(SolverKind kind, Ordering ordering) : impl_(std::make_unique<Impl>()) {
  impl_->kind = kind;
  impl_->use_cholmod = kind == SolverKind::Cholmod || (kind == SolverKind::Auto && cholmod_available());
  if (kind == SolverKind::PcgCuda) {
    if (!pcg_device_factory()) throw std::invalid_argument("solver pcg-cuda: this build has no CUDA");
    impl_->device = pcg_device_factory()();
  }
#ifdef YARNHOM_HAVE_CHOLMOD
  if (ordering != Ordering::Default) {
    impl_->cholmod.cholmod().nmethods = 1;
    impl_->cholmod.cholmod().method[0].ordering = ordering == Ordering::Metis ? CHOLMOD_METIS : CHOLMOD_NESDIS;
  }
  impl_->cholmod.cholmod().print = 0;  // a failed factorization is expected, not news
  // and ends at the first supernode that is not positive definite: nothing of a failed factor
  // is used, and a Newton solver's shift loop fails often.
  impl_->cholmod.cholmod().quick_return_if_not_posdef = 1;
#else
  (void)ordering;
#endif
}

SparseCholesky::~SparseCholesky() = default;

bool SparseCholesky::factorize(const Eigen::SparseMatrix<double>& A) {
  Impl& s = *impl_;
  const bool fresh = !s.same_pattern(A);
  if (s.iterative()) {
    if (fresh) s.remember_pattern(A);
    if (s.device) {
      // The pattern on the host (again only when it changed), the values straight from A's
      // triangle to the device, which scatters them and inverts the blocks.
      {
        prof::Scope ps("solver: the block pattern");
        s.builder.build_pattern(A, s.system, !fresh);
      }
      prof::Scope pu("solver: uploaded and built on the GPU");
      return s.device->upload_triangle(s.system, s.builder.map(), A.valuePtr(), int(A.nonZeros()));
    }
    prof::Scope ps("solver: the block system built");
    return s.builder.build(A, s.system, !fresh);
  }
#ifdef YARNHOM_HAVE_CHOLMOD
  if (s.use_cholmod) {
    const SerialOpenMP serial;  // CHOLMOD's own OpenMP regions (numerics/serial_openmp.hpp)
    if (fresh) {
      s.cholmod.analyzePattern(A);
      s.remember_pattern(A);
    }
    s.cholmod.factorize(A);
    return s.cholmod.info() == Eigen::Success;
  }
#endif
  if (fresh) {
    s.ldlt.analyzePattern(A);
    s.remember_pattern(A);
  }
  s.ldlt.factorize(A);
  if (s.ldlt.info() != Eigen::Success) return false;
  // LDL^T exists for indefinite matrices too: positive definite means every pivot > 0.
  return (s.ldlt.vectorD().array() > 0).all();
}

Eigen::VectorXd SparseCholesky::solve(const Eigen::VectorXd& b) const {
  if (impl_->iterative()) {
    prof::Scope ps("solver: CG iterations");
    Eigen::VectorXd x(b.size());
    const BlockPcgResult r = impl_->device ? impl_->device->solve(b.data(), x.data(), impl_->tol, impl_->max_iterations)
                                      : block_jacobi_pcg(impl_->system, b.data(), x.data(), impl_->tol,
                                                         impl_->max_iterations);
    impl_->iterations += r.iterations;
    ++impl_->solves;
    return x;
  }
#ifdef YARNHOM_HAVE_CHOLMOD
  if (impl_->use_cholmod) return impl_->cholmod.solve(b);
#endif
  return impl_->ldlt.solve(b);
}

double SparseCholesky::factor_nonzeros() const {
  if (impl_->analyses == 0 || impl_->iterative()) return 0.0;
#ifdef YARNHOM_HAVE_CHOLMOD
  if (impl_->use_cholmod) return double(impl_->cholmod.cholmod().lnz);
#endif
  return double(impl_->ldlt.matrixL().nestedExpression().nonZeros());
}

double SparseCholesky::factor_flops() const {
#ifdef YARNHOM_HAVE_CHOLMOD
  if (impl_->use_cholmod && impl_->analyses > 0) return impl_->cholmod.cholmod().fl;
#endif
  return 0.0;
}

const char* SparseCholesky::name() const {
  if (impl_->kind == SolverKind::Pcg) return "pcg (block Jacobi, CPU)";
  if (impl_->kind == SolverKind::PcgCuda) return impl_->device->name();
  return impl_->use_cholmod ? "cholmod" : "ldlt";
}

void SparseCholesky::set_iterative(double tolerance, int max_iterations) {
  impl_->tol = tolerance;
  impl_->max_iterations = max_iterations;
}
long long SparseCholesky::iterations() const { return impl_->iterations; }
long long SparseCholesky::solves() const { return impl_->solves; }

int SparseCholesky::analyses() const { return impl_->analyses; }

}  // namespace yarnhom::numerics
