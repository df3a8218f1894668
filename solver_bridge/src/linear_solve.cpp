#include "linear_solve.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <string>

#include "p1_assembly.hpp"

namespace foxi::detail {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Vec = Eigen::VectorXd;

Eigen::Map<const SpMat> as_eigen(const SymmetricCsr& a) {
  const auto n = static_cast<Eigen::Index>(a.rows());
  return Eigen::Map<const SpMat>(n, n, static_cast<Eigen::Index>(a.val.size()), a.start.data(), a.col.data(),
                                 a.val.data());
}

void report(const LinearSolverOptions& options, std::string_view stage, double fraction) {
  if (options.progress && !options.progress(stage, fraction))
    throw SolverCancelled("solve cancelled during '" + std::string(stage) + "'");
}

double residual_norm(const SymmetricCsr& a, const std::vector<double>& b, const std::vector<double>& x,
                     unsigned threads) {
  std::vector<double> ax(b.size());
  multiply(a, x.data(), ax.data(), threads);
  double s = 0;
  for (std::size_t i = 0; i < b.size(); ++i) s += (b[i] - ax[i]) * (b[i] - ax[i]);
  return std::sqrt(s);
}

}  // namespace

void multiply(const SymmetricCsr& a, const double* x, double* y, unsigned threads) {
  parallel_for(
      a.rows(), threads,
      [&](std::size_t b, std::size_t e, unsigned) {
        for (std::size_t i = b; i < e; ++i) {
          double s = 0;
          for (int k = a.start[i]; k < a.start[i + 1]; ++k)
            s += a.val[static_cast<std::size_t>(k)] * x[a.col[static_cast<std::size_t>(k)]];
          y[i] = s;
        }
      },
      50000);
}

LinearSolveResult solve_spd(const SymmetricCsr& a, const std::vector<double>& b, std::vector<double>& x,
                            const LinearSolverOptions& options) {
  const std::size_t n = a.rows();
  const unsigned threads = thread_count(options.threads);
  LinearSolveResult result;
  x.assign(n, 0.0);
  double bnorm = 0;
  for (double v : b) bnorm += v * v;
  bnorm = std::sqrt(bnorm);
  LinearSolverKind kind = options.kind;
  if (kind == LinearSolverKind::automatic)
    kind = n <= options.direct_max_unknowns ? LinearSolverKind::direct : LinearSolverKind::cg_ichol;
  if (n == 0) {
    result.solver = "none (no unknowns)";
    return result;
  }
  Eigen::Map<const SpMat> A = as_eigen(a);
  Eigen::Map<const Vec> B(b.data(), static_cast<Eigen::Index>(n));
  Eigen::Map<Vec> X(x.data(), static_cast<Eigen::Index>(n));

  if (kind == LinearSolverKind::direct) {
    result.solver = "SimplicialLDLT";
    report(options, "factorize", 0.0);
    Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
    ldlt.compute(A);
    if (ldlt.info() != Eigen::Success)
      throw SolverError(
          "sparse LDL^T factorization failed (matrix not positive definite: are the "
          "conductivities positive and every part connected to a fixed or convective boundary?)");
    const Vec d = ldlt.vectorD();
    if (d.minCoeff() <= 0)
      throw SolverError(
          "sparse LDL^T: the matrix is singular or indefinite (a part with no fixed-temperature "
          "or convection boundary, or a non-positive conductivity)");
    report(options, "solve", 0.0);
    X = ldlt.solve(B);
    result.relative_residual = bnorm > 0 ? residual_norm(a, b, x, threads) / bnorm : 0.0;
    report(options, "solve", 1.0);
    return result;
  }

  result.solver = "CG+IncompleteCholesky";
  report(options, "factorize", 0.0);
  Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::NaturalOrdering<int>> ic;
  {
    SpMat lower = SpMat(A).triangularView<Eigen::Lower>();
    ic.compute(lower);
  }
  if (ic.info() != Eigen::Success) throw SolverError("incomplete Cholesky factorization failed");
  report(options, "solve", 0.0);
  if (bnorm == 0) return result;
  const double tol = options.relative_tolerance * bnorm;
  const std::size_t max_it = options.max_iterations ? options.max_iterations : 10 * n + 100;
  Vec r = B, z = ic.solve(r), p = z, q(static_cast<Eigen::Index>(n));
  double rz = r.dot(z);
  const double log_goal = std::log(std::max(1e-300, options.relative_tolerance));
  std::size_t it = 0;
  double rnorm = bnorm;
  while (rnorm > tol) {
    if (it == max_it)
      throw SolverError("conjugate gradients did not converge in " + std::to_string(max_it) +
                        " iterations (relative residual " + std::to_string(rnorm / bnorm) + ")");
    multiply(a, p.data(), q.data(), threads);
    const double pq = p.dot(q);
    if (!(pq > 0))
      throw SolverError(
          "conjugate gradients broke down: the matrix is not positive definite (a part with "
          "no fixed-temperature or convection boundary?)");
    const double alpha = rz / pq;
    X += alpha * p;
    r -= alpha * q;
    rnorm = r.norm();
    ++it;
    if (rnorm <= tol) break;
    z = ic.solve(r);
    const double rz_new = r.dot(z);
    p = z + (rz_new / rz) * p;
    rz = rz_new;
    if (it % 10 == 0) report(options, "solve", std::clamp(std::log(rnorm / bnorm) / log_goal, 0.0, 1.0));
  }
  result.iterations = it;
  result.relative_residual = residual_norm(a, b, x, threads) / bnorm;
  report(options, "solve", 1.0);
  return result;
}

}  // namespace foxi::detail
