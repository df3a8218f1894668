#include "linear_solve.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <string>

#include "amg.hpp"
#include "p1_assembly.hpp"

namespace foxi::detail {

void multiply(const SymmetricCsr& a, const double* x, double* y, unsigned threads);

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

// Preconditioned conjugate gradients from x = 0; precondition(r, z) sets z = M^-1 r.
template <class Precondition>
void pcg(const SymmetricCsr& a, const std::vector<double>& b, std::vector<double>& x, double bnorm,
         const LinearSolverOptions& options, unsigned threads, LinearSolveResult& result,
         Precondition&& precondition) {
  const std::size_t n = a.rows();
  if (bnorm == 0) return;
  Eigen::Map<Vec> X(x.data(), static_cast<Eigen::Index>(n));
  const double tol = options.relative_tolerance * bnorm;
  const std::size_t max_it = options.max_iterations ? options.max_iterations : 10 * n + 100;
  Vec r = Eigen::Map<const Vec>(b.data(), static_cast<Eigen::Index>(n)), z(static_cast<Eigen::Index>(n));
  precondition(r, z);
  Vec p = z, q(static_cast<Eigen::Index>(n));
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
    precondition(r, z);
    const double rz_new = r.dot(z);
    p = z + (rz_new / rz) * p;
    rz = rz_new;
    if (it % 10 == 0) report(options, "solve", std::clamp(std::log(rnorm / bnorm) / log_goal, 0.0, 1.0));
  }
  result.iterations = it;
  result.relative_residual = residual_norm(a, b, x, threads) / bnorm;
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
  std::vector<std::vector<double>> xs;
  LinearSolveResult result = solve_spd_many(a, {b}, xs, options);
  x = std::move(xs[0]);
  return result;
}

LinearSolveResult solve_spd_many(const SymmetricCsr& a, const std::vector<std::vector<double>>& bs,
                                 std::vector<std::vector<double>>& xs, const LinearSolverOptions& options) {
  const std::size_t n = a.rows();
  const unsigned threads = thread_count(options.threads);
  LinearSolveResult result;
  xs.assign(bs.size(), std::vector<double>(n, 0.0));
  auto norm = [](const std::vector<double>& b) {
    double s = 0;
    for (double v : b) s += v * v;
    return std::sqrt(s);
  };
  LinearSolverKind kind = options.kind;
  if (kind == LinearSolverKind::automatic)
    kind = n <= options.direct_max_unknowns ? LinearSolverKind::direct : LinearSolverKind::cg_amg;
  if (n == 0) {
    result.solver = "none (no unknowns)";
    return result;
  }
  Eigen::Map<const SpMat> A = as_eigen(a);

  if (kind == LinearSolverKind::direct) {
    result.solver = "SimplicialLDLT";
    report(options, "factorize", 0.0);
    Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
    ldlt.compute(A);
    if (ldlt.info() != Eigen::Success)
      throw SolverError(
          "sparse LDL^T factorization failed (matrix not positive definite: are the "
          "coefficients positive and every part connected to a fixed boundary?)");
    const Vec d = ldlt.vectorD();
    if (d.minCoeff() <= 0)
      throw SolverError(
          "sparse LDL^T: the matrix is singular or indefinite (a part with no fixed boundary, or a "
          "non-positive coefficient)");
    for (std::size_t i = 0; i < bs.size(); ++i) {
      report(options, "solve", static_cast<double>(i) / static_cast<double>(bs.size()));
      Eigen::Map<const Vec> B(bs[i].data(), static_cast<Eigen::Index>(n));
      Eigen::Map<Vec> X(xs[i].data(), static_cast<Eigen::Index>(n));
      X = ldlt.solve(B);
      const double bnorm = norm(bs[i]);
      result.relative_residual = std::max(result.relative_residual,
                                          bnorm > 0 ? residual_norm(a, bs[i], xs[i], threads) / bnorm : 0.0);
    }
    report(options, "solve", 1.0);
    return result;
  }

  report(options, "factorize", 0.0);
  auto run_all = [&](auto&& precondition) {
    for (std::size_t i = 0; i < bs.size(); ++i) {
      LinearSolveResult one;
      pcg(a, bs[i], xs[i], norm(bs[i]), options, threads, one, precondition);
      result.iterations += one.iterations;
      result.relative_residual = std::max(result.relative_residual, one.relative_residual);
    }
  };
  if (kind == LinearSolverKind::cg_amg) {
    result.solver = "CG+SmoothedAggregationAMG";
    AmgPreconditioner amg(a, threads);
    report(options, "solve", 0.0);
    run_all([&](const Vec& r, Vec& z) { amg.apply(r.data(), z.data()); });
  } else {
    result.solver = "CG+IncompleteCholesky";
    Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::NaturalOrdering<int>> ic;
    {
      SpMat lower = SpMat(A).triangularView<Eigen::Lower>();
      ic.compute(lower);
    }
    if (ic.info() != Eigen::Success) throw SolverError("incomplete Cholesky factorization failed");
    report(options, "solve", 0.0);
    run_all([&](const Vec& r, Vec& z) { z = ic.solve(r); });
  }
  report(options, "solve", 1.0);
  return result;
}

}  // namespace foxi::detail
