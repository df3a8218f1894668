// The solvers' shared vocabulary: their errors (SolverError, SolverCancelled), the checks they make
// of their own results (BalanceCheck) and the linear solve's options, which every problem's
// parameters embed. thermal.hpp, electric.hpp and thermoelastic.hpp include it; the solver library's
// internals include it alone.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/progress.hpp"

namespace foxi {

// A problem that cannot be solved as given (missing conductivity, unknown tag, ill-posed boundary
// conditions, a failed factorization, no convergence); the message names the region or tag.
struct FOXI_API SolverError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The problem as given is wrong (a missing or non-positive coefficient, an unknown or doubly constrained
// tag, a load on an empty region, ill-posed conditions, geometry beyond the range of doubles): the input
// must change. A SolverError that is not a SolverInputError is a failure of the solve itself (no
// convergence, a failed factorization, a size limit); the CLI exits 3 for the one and 1 for the other.
struct FOXI_API SolverInputError : SolverError {
  using SolverError::SolverError;
};

// The progress callback returned false (a foxi::Cancelled too).
struct FOXI_API SolverCancelled : SolverError, Cancelled {
  using SolverError::SolverError;
};

// A check a solver makes of its own result (a balance, a sign pattern, a residual): a relative figure
// against its tolerance. A result with a failed check is not to be trusted: foxi prints it as an
// UNRELIABLE line with the figures and exits with status 4.
struct BalanceCheck {
  std::string name;  // "Kirchhoff", "energy", ...
  std::string what;  // what the figure measures, in words
  double figure = 0;
  double tolerance = 0;
  bool passed = true;
};
inline BalanceCheck make_check(std::string name, std::string what, double figure, double tolerance) {
  return {std::move(name), std::move(what), figure, tolerance, figure <= tolerance};  // NaN fails
}
inline bool all_passed(const std::vector<BalanceCheck>& checks) {
  for (const BalanceCheck& c : checks)
    if (!c.passed) return false;
  return true;
}

// Where an iterative (CG) solve is: the iterations so far, counted over its restarts on the true residual
// and over the right-hand sides solved with one factorization (so the count only grows), and the relative
// residual |W r| / |W b| (the stopping test's, W as below) after the last of them.
struct IterationReport {
  std::size_t iteration = 0;
  double relative_residual = 0;
};
// Called after each CG iteration; returns false to cancel (SolverCancelled), as ProgressFn does.
using IterationFn = std::function<bool(const IterationReport&)>;

enum class LinearSolverKind : std::uint8_t {
  automatic,  // direct up to LinearSolverOptions::direct_max_unknowns, else cg_amg
  direct,     // sparse LDL^T (Eigen SimplicialLDLT, AMD ordering)
  cg_ichol,   // conjugate gradients, incomplete Cholesky preconditioner (Eigen, mesh node order)
  cg_amg,     // conjugate gradients, smoothed-aggregation algebraic multigrid V(1,1) preconditioner
};

// Options of the linear solve shared by foxi's solvers.
struct LinearSolverOptions {
  LinearSolverKind kind = LinearSolverKind::automatic;
  std::size_t direct_max_unknowns = 5000;
  // CG stops at |W (b - A x)| <= tol |W b|, and restarts on the true residual (a few times) where it
  // misses that. W = diag(A)^-1 for the scalar problems (heat, electrostatics, conduction): each row's
  // residual in units of the unknown, so that a row of FR-4 counts as much as a row of copper at a
  // contrast of 1e20; W = I for elasticity.
  double relative_tolerance = 1e-10;
  std::size_t max_iterations = 0;  // 0: 10 * unknowns + 100
  unsigned threads = 0;            // 0: std::thread::hardware_concurrency()
  ProgressFn progress;             // stages "assemble", "factorize", "solve"; false cancels
  IterationFn iterations;          // CG only (a direct solve has none); false cancels
};

}  // namespace foxi
