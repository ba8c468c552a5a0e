#pragma once
// Sparse symmetric positive-definite solves for the Newton systems. The pattern is fixed for a
// simulation (sim/hessian_pattern.hpp), so the fill-reducing ordering and symbolic analysis
// are done once and each Newton iteration only refactors numerically.
//
// Backends: Eigen's SimplicialLDLT (always there) and CHOLMOD's supernodal Cholesky through
// Eigen's CholmodSupport (when the build found SuiteSparse; docs/benchmarks.md has the
// comparison).
#include <Eigen/Sparse>
#include <memory>
#include <string>

namespace yarnhom::sim {

enum class SolverKind { Auto, Ldlt, Cholmod };

SolverKind parse_solver_kind(const std::string& name);  // "auto", "ldlt", "cholmod"
bool cholmod_available();

class LinearSolver {
 public:
  explicit LinearSolver(SolverKind kind = SolverKind::Auto);
  ~LinearSolver();
  LinearSolver(const LinearSolver&) = delete;
  LinearSolver& operator=(const LinearSolver&) = delete;

  // A: lower triangle. The first call (or a call with a new pattern size) analyses the pattern.
  // Returns false when A is not numerically positive definite.
  bool factorize(const Eigen::SparseMatrix<double>& A);
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  const char* name() const;
  // Nonzeros of the last factor (L, or L and D), for benchmarks; 0 before the first factorization.
  double factor_nonzeros() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace yarnhom::sim
