// Internal: the symmetric positive definite solve shared by foxi's solvers (Eigen behind it).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "foxi/solver/solver.hpp"

namespace foxi::detail {

// A symmetric matrix with both triangles stored, rows sorted (CSR, which is also its CSC).
struct SymmetricCsr {
  std::vector<int> start;  // rows + 1
  std::vector<int> col;
  std::vector<double> val;
  std::size_t rows() const { return start.empty() ? 0 : start.size() - 1; }
};

struct LinearSolveResult {
  std::string solver;
  std::size_t iterations = 0;
  double relative_residual = 0;
  std::size_t levels = 0;  // AMG levels (0 for the other solvers)
};

// The near-null space of the operator for smoothed-aggregation AMG (Vanek, Mandel, Brezina 1996):
// `vectors` vectors given per unknown (values[unknown * vectors + k]) and the node of each unknown;
// the unknowns of one node are always aggregated together. For 3D elasticity: the 6 rigid-body modes
// with 3 (or fewer, where constrained) unknowns per node. Without one, AMG aggregates single unknowns
// and interpolates constants (right for diffusion).
struct NearNullSpace {
  std::vector<std::uint32_t> node;  // per unknown, < nodes
  std::size_t nodes = 0;
  std::size_t vectors = 0;
  std::vector<double> values;  // unknowns * vectors
};

// Solves A x = b (A symmetric positive definite) with the solver `options` chooses. Throws
// SolverError when the factorization fails or CG does not reach the tolerance, SolverCancelled when
// the progress callback says so.
LinearSolveResult solve_spd(const SymmetricCsr& a, const std::vector<double>& b, std::vector<double>& x,
                            const LinearSolverOptions& options, const NearNullSpace* near_null = nullptr);

// The same for several right-hand sides with one factorization or preconditioner; iterations are
// summed and the relative residual is the largest.
LinearSolveResult solve_spd_many(const SymmetricCsr& a, const std::vector<std::vector<double>>& b,
                                 std::vector<std::vector<double>>& x, const LinearSolverOptions& options,
                                 const NearNullSpace* near_null = nullptr);

// A factorization or preconditioner of A built once for many solves one after another (a time
// stepper's fixed matrix). `a` is referenced, not copied: it must outlive the solver. The
// constructor throws SolverError as solve_spd does; solve() throws on CG failure and does not check
// for NaN (the caller's results do).
class SpdSolver {
 public:
  SpdSolver(const SymmetricCsr& a, const LinearSolverOptions& options,
            const NearNullSpace* near_null = nullptr);
  ~SpdSolver();
  SpdSolver(const SpdSolver&) = delete;
  SpdSolver& operator=(const SpdSolver&) = delete;
  // With `reference`, the goal is |r| <= tol max(|b|, |reference|) and the relative residual is
  // measured against that: a time step that solves for its increment b = rhs - A x0 passes its full
  // right-hand side, so that each step meets the accuracy of a solve of A x = rhs from zero (the
  // increment alone would be reduced by tol at every step, however small it is).
  LinearSolveResult solve(const std::vector<double>& b, std::vector<double>& x,
                          const std::vector<double>* reference = nullptr);
  const std::string& name() const;
  std::size_t levels() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// y = A x on `threads` threads.
void multiply(const SymmetricCsr& a, const double* x, double* y, unsigned threads);

}  // namespace foxi::detail
