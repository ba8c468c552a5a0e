#include "sim/linear_solver.hpp"

#include <stdexcept>

#include "core/serial_openmp.hpp"

#ifdef YARNHOM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

namespace yarnhom::sim {

SolverKind parse_solver_kind(const std::string& name) {
  if (name == "auto") return SolverKind::Auto;
  if (name == "ldlt") return SolverKind::Ldlt;
  if (name == "cholmod") {
    if (!cholmod_available()) throw std::invalid_argument("--solver cholmod: this build has no CHOLMOD (SuiteSparse)");
    return SolverKind::Cholmod;
  }
  throw std::invalid_argument("solver '" + name + "': expected auto, ldlt or cholmod");
}

bool cholmod_available() {
#ifdef YARNHOM_HAVE_CHOLMOD
  return true;
#else
  return false;
#endif
}

struct LinearSolver::Impl {
  bool use_cholmod = false;
  Eigen::Index analysed_size = -1, analysed_nnz = -1;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt;
#ifdef YARNHOM_HAVE_CHOLMOD
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> cholmod;
#endif
};

LinearSolver::LinearSolver(SolverKind kind) : impl_(std::make_unique<Impl>()) {
  impl_->use_cholmod = kind == SolverKind::Cholmod || (kind == SolverKind::Auto && cholmod_available());
#ifdef YARNHOM_HAVE_CHOLMOD
  // A failed factorization is an expected event (the Newton solver shifts and retries): no
  // warning on the terminal.
  impl_->cholmod.cholmod().print = 0;
#endif
}

LinearSolver::~LinearSolver() = default;

bool LinearSolver::factorize(const Eigen::SparseMatrix<double>& A) {
  Impl& s = *impl_;
  const bool fresh = A.rows() != s.analysed_size || A.nonZeros() != s.analysed_nnz;
#ifdef YARNHOM_HAVE_CHOLMOD
  if (s.use_cholmod) {
    const SerialOpenMP serial;  // CHOLMOD's own OpenMP regions (core/serial_openmp.hpp)
    if (fresh) s.cholmod.analyzePattern(A);
    s.analysed_size = A.rows();
    s.analysed_nnz = A.nonZeros();
    s.cholmod.factorize(A);
    return s.cholmod.info() == Eigen::Success;
  }
#endif
  if (fresh) s.ldlt.analyzePattern(A);
  s.analysed_size = A.rows();
  s.analysed_nnz = A.nonZeros();
  s.ldlt.factorize(A);
  if (s.ldlt.info() != Eigen::Success) return false;
  // LDL^T exists for indefinite matrices too: positive definite means every pivot > 0.
  return (s.ldlt.vectorD().array() > 0).all();
}

Eigen::VectorXd LinearSolver::solve(const Eigen::VectorXd& b) const {
#ifdef YARNHOM_HAVE_CHOLMOD
  if (impl_->use_cholmod) return impl_->cholmod.solve(b);
#endif
  return impl_->ldlt.solve(b);
}

double LinearSolver::factor_nonzeros() const {
#ifdef YARNHOM_HAVE_CHOLMOD
  if (impl_->use_cholmod) return impl_->analysed_size < 0 ? 0.0 : double(impl_->cholmod.cholmod().lnz);
#endif
  return impl_->analysed_size < 0 ? 0.0 : double(impl_->ldlt.matrixL().nestedExpression().nonZeros());
}

const char* LinearSolver::name() const { return impl_->use_cholmod ? "cholmod" : "ldlt"; }

}  // namespace yarnhom::sim
