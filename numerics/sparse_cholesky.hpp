#pragma once
// Sparse symmetric positive-definite factorization for every Newton system of the project
// (the yarn RVE's and strips' through numerics/hessian_factor.hpp, the continuum simulator's
// directly): one wrapper around CHOLMOD's supernodal Cholesky (SuiteSparse, through Eigen's
// CholmodSupport), with Eigen's SimplicialLDLT as the alternative a user can ask for.
//
// The fill-reducing ordering and symbolic analysis are redone only when the sparsity pattern
// changes (compared entry for entry; a simulation's pattern is fixed, a yarn strip's changes
// with its contacts), so that most Newton iterations only refactor numerically.
#include <Eigen/Sparse>
#include <memory>
#include <string>

namespace yarnhom::numerics {

enum class SolverKind { Auto, Ldlt, Cholmod, Pcg, PcgCuda };
// CHOLMOD's fill-reducing ordering. Default: CHOLMOD's own choice (AMD, METIS only when AMD's
// factor is very dense; what every solve of the project uses). Metis, NestedDissection: those
// orderings alone (CHOLMOD_METIS, CHOLMOD_NESDIS), for benchmarks: on the 16k-triangle drape's
// matrix 25-28 % fewer flops than AMD, no faster measured, 4x the analysis time
// (docs/benchmarks.md, "Drape at 16k triangles").
enum class Ordering { Default, Metis, NestedDissection };
SolverKind parse_solver_kind(const std::string& name);  // "auto", "ldlt", "cholmod", "pcg", "pcg-cuda"
// The name parse_solver_kind takes for k; Auto as what it runs ("cholmod", or "ldlt" without CHOLMOD).
const char* solver_kind_name(SolverKind k);
bool cholmod_available();

class SparseCholesky {
 public:
  explicit SparseCholesky(SolverKind kind = SolverKind::Auto, Ordering ordering = Ordering::Default);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  // A: lower triangle, compressed. Analyses the pattern when it differs from the last one's.
  // Returns false when A is not numerically positive definite (an expected outcome: callers
  // shift the diagonal and retry, so CHOLMOD prints nothing).
  bool factorize(const Eigen::SparseMatrix<double>& A);
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  const char* name() const;
  // Nonzeros of the last factor (L, or L and D), for benchmarks; 0 before the first factorization.
  double factor_nonzeros() const;
  // Floating-point operations of one numeric factorization, as CHOLMOD's analysis counts them
  // (cholmod_common's fl); 0 before the first factorization and with LDL^T.
  double factor_flops() const;
  // Symbolic analyses done so far.
  int analyses() const;
  // The iterative kinds' stopping rule (default: relative residual 1e-3, 20,000 iterations), and
  // what their solves took so far (0 for the direct kinds).
  void set_iterative(double tolerance, int max_iterations);
  long long iterations() const;
  long long solves() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace yarnhom::numerics
