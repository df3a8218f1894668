#include "linear_solve.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "amg.hpp"
#include "p1_assembly.hpp"

namespace foxi::detail {

void multiply(const SymmetricCsr& a, const double* x, double* y, unsigned threads);

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
// Vector lengths below which the CG updates stay on one thread.
constexpr std::size_t kVectorSerialBelow = 50000;
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

// The norm every stopping test and reported residual uses: |W v| with W the row weights (the inverse
// diagonal for the scalar problems: a residual in units of the unknown, so that each row counts by its
// own scale), or the plain |v| where there are none.
double weighted_norm(const std::vector<double>& v, const std::vector<double>& w) {
  double s = 0;
  if (w.empty())
    for (double x : v) s += x * x;
  else
    for (std::size_t i = 0; i < v.size(); ++i) s += (w[i] * v[i]) * (w[i] * v[i]);
  return std::sqrt(s);
}

std::vector<double> residual(const SymmetricCsr& a, const std::vector<double>& b,
                             const std::vector<double>& x, unsigned threads) {
  std::vector<double> r(b.size());
  multiply(a, x.data(), r.data(), threads);
  for (std::size_t i = 0; i < b.size(); ++i) r[i] = b[i] - r[i];
  return r;
}

// Preconditioned conjugate gradients from x = 0; precondition(r, z) sets z = M^-1 r.
// Sum of f(i) over [0, n) on threads; the slices' sums are added in slice order, so the result is
// the same on every run with the same thread count.
template <class F>
double parallel_sum(std::size_t n, unsigned threads, F&& f) {
  std::vector<double> part(threads, 0.0);
  parallel_for(
      n, threads,
      [&](std::size_t b, std::size_t e, unsigned t) {
        double s = 0;
        for (std::size_t i = b; i < e; ++i) s += f(i);
        part[t] = s;
      },
      kVectorSerialBelow);
  double s = 0;
  for (double v : part) s += v;
  return s;
}

// Preconditioned conjugate gradients from x = 0; precondition(r, z) sets z = M^-1 r. The vector
// updates run on threads, fused so that each iteration reads every vector as few times as it can.
// The stopping test is |W r| <= tol_abs, W the row weights (none: the plain norm).
// `counter`: the iterations of the whole solve so far (IterationReport's count), advanced here.
template <class Precondition>
void pcg(const SymmetricCsr& a, const std::vector<double>& b, std::vector<double>& x, double bnorm,
         double tol, const std::vector<double>& weight, const LinearSolverOptions& options, unsigned threads,
         LinearSolveResult& result, std::size_t& counter, Precondition&& precondition) {
  const std::size_t n = a.rows();
  if (bnorm == 0) return;
  const double* wd = weight.empty() ? nullptr : weight.data();
  const std::size_t max_it = options.max_iterations ? options.max_iterations : 10 * n + 100;
  Vec r = Eigen::Map<const Vec>(b.data(), static_cast<Eigen::Index>(n)), z(static_cast<Eigen::Index>(n));
  precondition(r, z);
  Vec p = z, q(static_cast<Eigen::Index>(n));
  double* xd = x.data();
  double *rd = r.data(), *zd = z.data(), *pd = p.data(), *qd = q.data();
  double rz = parallel_sum(n, threads, [&](std::size_t i) { return rd[i] * zd[i]; });
  const double log_goal = std::log(std::max(1e-300, options.relative_tolerance));
  std::size_t it = 0;
  double rnorm = weighted_norm(b, weight);
  double shown = 0;  // the fraction reported: CG's residual is not monotone, the progress is
  while (rnorm > tol) {
    if (it == max_it)
      throw SolverError("conjugate gradients did not converge in " + std::to_string(max_it) +
                        " iterations (relative residual " + std::to_string(rnorm / bnorm) + ")");
    // q = A p and p.q in one pass.
    const double pq = parallel_sum(n, threads, [&](std::size_t i) {
      double s = 0;
      for (int k = a.start[i]; k < a.start[i + 1]; ++k)
        s += a.val[static_cast<std::size_t>(k)] * pd[a.col[static_cast<std::size_t>(k)]];
      qd[i] = s;
      return pd[i] * s;
    });
    if (!(pq > 0))
      throw SolverError(
          "conjugate gradients broke down: the matrix is not positive definite (a part with "
          "no fixed-temperature or convection boundary?)");
    const double alpha = rz / pq;
    rnorm = std::sqrt(parallel_sum(n, threads, [&](std::size_t i) {
      xd[i] += alpha * pd[i];
      rd[i] -= alpha * qd[i];
      const double wr = wd ? wd[i] * rd[i] : rd[i];
      return wr * wr;
    }));
    ++it;
    ++counter;
    if (options.iterations && !options.iterations(IterationReport{counter, rnorm / bnorm}))
      throw SolverCancelled("solve cancelled at CG iteration " + std::to_string(counter));
    if (rnorm <= tol) break;
    precondition(r, z);
    const double rz_new = parallel_sum(n, threads, [&](std::size_t i) { return rd[i] * zd[i]; });
    const double beta = rz_new / rz;
    parallel_for(
        n, threads,
        [&](std::size_t lo, std::size_t hi, unsigned) {
          for (std::size_t i = lo; i < hi; ++i) pd[i] = zd[i] + beta * pd[i];
        },
        kVectorSerialBelow);
    rz = rz_new;
    shown = std::max(shown, std::clamp(std::log(rnorm / bnorm) / log_goal, 0.0, 1.0));
    if (it % 10 == 0) report(options, "solve", shown);
  }
  result.iterations = it;
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
                            const LinearSolverOptions& options, const NearNullSpace* near_null) {
  std::vector<std::vector<double>> xs;
  LinearSolveResult result = solve_spd_many(a, {b}, xs, options, near_null);
  x = std::move(xs[0]);
  return result;
}

namespace {

// A solve whose matrix, right-hand side or solution holds NaN or infinity (geometry or coefficients
// beyond the range of double) has no result to report: conjugate gradients stop at once on a NaN
// residual (NaN > tol is false) with x = 0, and LDL^T passes a NaN pivot (NaN <= 0 is false).
void require_finite_input(const SymmetricCsr& a, const std::vector<std::vector<double>>& bs) {
  for (double v : a.val)
    if (!std::isfinite(v))
      throw SolverInputError(
          "the system matrix holds NaN or infinity (mesh geometry or coefficients beyond the "
          "range of double)");
  for (const std::vector<double>& b : bs)
    for (double v : b)
      if (!std::isfinite(v))
        throw SolverInputError(
            "the right-hand side holds NaN or infinity (loads or geometry beyond the range of "
            "double)");
}

void require_finite_output(const std::vector<std::vector<double>>& xs, const LinearSolveResult& result) {
  for (const std::vector<double>& x : xs)
    for (double v : x)
      if (!std::isfinite(v)) throw SolverError("the solution holds NaN or infinity: no result to report");
  if (!std::isfinite(result.relative_residual))
    throw SolverError("the residual is NaN or infinite: no result to report");
}

}  // namespace

struct SpdSolver::Impl {
  const SymmetricCsr& a;
  LinearSolverOptions options;
  unsigned threads = 1;
  LinearSolverKind kind = LinearSolverKind::direct;
  std::vector<double> weight;
  std::string name;
  std::size_t levels = 0;
  std::size_t iterations = 0;  // over every solve with this factorization (IterationReport's count)
  Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
  Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::NaturalOrdering<int>> ic;
  std::unique_ptr<AmgPreconditioner> amg;
  Impl(const SymmetricCsr& m, const LinearSolverOptions& o) : a(m), options(o) {}
};

SpdSolver::SpdSolver(const SymmetricCsr& a, const LinearSolverOptions& options,
                     const NearNullSpace* near_null)
    : impl_(std::make_unique<Impl>(a, options)) {
  Impl& s = *impl_;
  const std::size_t n = a.rows();
  s.threads = thread_count(options.threads);
  // Scalar problems (no near-null space) measure residuals row by row against the row's own scale
  // (W = diag(A)^-1): at a conductivity contrast of 1e20 the plain |r| is all metal rows, and a solve
  // that meets tol |b| there leaves the insulator's rows, which carry the small currents, unresolved.
  if (!near_null) {
    s.weight.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
      for (int k = a.start[i]; k < a.start[i + 1]; ++k)
        if (static_cast<std::size_t>(a.col[static_cast<std::size_t>(k)]) == i)
          s.weight[i] = 1.0 / a.val[static_cast<std::size_t>(k)];
    for (double w : s.weight)
      if (!(w > 0) || !std::isfinite(w))
        throw SolverInputError("the matrix has a non-positive diagonal (a non-positive coefficient?)");
  }
  s.kind = options.kind;
  if (s.kind == LinearSolverKind::automatic)
    s.kind = n <= options.direct_max_unknowns ? LinearSolverKind::direct : LinearSolverKind::cg_amg;
  if (n == 0) {
    s.name = "none (no unknowns)";
    return;
  }
  Eigen::Map<const SpMat> A = as_eigen(a);
  report(options, "factorize", 0.0);
  if (s.kind == LinearSolverKind::direct) {
    s.name = "SimplicialLDLT";
    s.ldlt.compute(A);
    if (s.ldlt.info() != Eigen::Success)
      throw SolverError(
          "sparse LDL^T factorization failed (matrix not positive definite: are the "
          "coefficients positive and every part connected to a fixed boundary?)");
    const Vec d = s.ldlt.vectorD();
    if (d.minCoeff() <= 0)
      throw SolverError(
          "sparse LDL^T: the matrix is singular or indefinite (a part with no fixed boundary, or a "
          "non-positive coefficient)");
  } else if (s.kind == LinearSolverKind::cg_amg) {
    AmgParams amg_params;
    amg_params.near_null = near_null;
    // The l1 smoother keeps hybrid Gauss-Seidel convergent on any thread count: without it the
    // couplings across thread blocks are relaxed like undamped Jacobi, which diverges where
    // rho(D^-1 A) > 2 (elasticity; P1 diffusion on Delaunay meshes, whose off-diagonals are not all
    // negative). 400k TetGen tets, 2 threads: 30 CG iterations with it, 41 without; 16 threads: 30
    // and 76.
    amg_params.l1_smoother = true;
    // Scalar problems: V(2,2) takes about 30% fewer CG iterations than V(1,1) (2 threads, TetGen box
    // 948k tets: 23 against 33; board+block 1M tets with a block of k 1e-20 relative to the board: 37
    // against 51, measured with the one-row strength rule before amg.cpp's two-row rule, which gives
    // 36 with V(2,2)) at about 1.4 times the work per iteration, and keeps the hard contrasts under 50.
    // Elasticity keeps V(1,1), as measured with it.
    amg_params.sweeps = near_null ? 1 : 2;
    // Elasticity keeps the tentative prolongation (plain aggregation): smoothing it halves the CG
    // iterations (250k tets: 27 against 53) but makes the coarse operators denser, for 30% more CPU
    // time in all (2.43 s against 1.88 s on the CSR products) and 1.6 times the peak memory.
    amg_params.smooth_prolongation = near_null == nullptr;
    s.name = near_null ? (amg_params.smooth_prolongation ? "CG+SmoothedAggregationAMG(rigid-body modes)"
                                                         : "CG+AggregationAMG(rigid-body modes)")
                       : "CG+SmoothedAggregationAMG";
    s.amg = std::make_unique<AmgPreconditioner>(a, s.threads, amg_params);
    s.levels = s.amg->level_count();
  } else {
    s.name = "CG+IncompleteCholesky";
    {
      SpMat lower = SpMat(A).triangularView<Eigen::Lower>();
      s.ic.compute(lower);
    }
    if (s.ic.info() != Eigen::Success) throw SolverError("incomplete Cholesky factorization failed");
  }
}

SpdSolver::~SpdSolver() = default;

const std::string& SpdSolver::name() const { return impl_->name; }
std::size_t SpdSolver::levels() const { return impl_->levels; }

LinearSolveResult SpdSolver::solve(const std::vector<double>& b, std::vector<double>& x,
                                   const std::vector<double>* reference) {
  Impl& s = *impl_;
  const SymmetricCsr& a = s.a;
  const std::size_t n = a.rows();
  LinearSolveResult result;
  result.solver = s.name;
  result.levels = s.levels;
  x.assign(n, 0.0);
  if (n == 0) return result;
  auto norm = [&](const std::vector<double>& v) { return weighted_norm(v, s.weight); };
  const double b_own = norm(b);
  const double bnorm = reference ? std::max(b_own, norm(*reference)) : b_own;
  if (s.kind == LinearSolverKind::direct) {
    Eigen::Map<const Vec> B(b.data(), static_cast<Eigen::Index>(n));
    Eigen::Map<Vec> X(x.data(), static_cast<Eigen::Index>(n));
    X = s.ldlt.solve(B);
    result.relative_residual = bnorm > 0 ? norm(residual(a, b, x, s.threads)) / bnorm : 0.0;
    return result;
  }
  if (b_own == 0) return result;
  // CG's recursive residual drifts from the true one; where the true residual misses the tolerance
  // (high contrast: the metal rows' round-off swamps the recursion), CG restarts on it (iterative
  // refinement, a few rounds).
  auto run = [&](auto&& precondition) {
    constexpr int kRefinements = 4;
    const double tol = s.options.relative_tolerance * bnorm;
    LinearSolveResult one;
    pcg(a, b, x, bnorm, tol, s.weight, s.options, s.threads, one, s.iterations, precondition);
    result.iterations += one.iterations;
    std::vector<double> r = residual(a, b, x, s.threads);
    double rnorm = norm(r);
    for (int round = 0; round < kRefinements && rnorm > tol; ++round) {
      std::vector<double> dx(n, 0.0);
      LinearSolveResult more;
      pcg(a, r, dx, bnorm, tol, s.weight, s.options, s.threads, more, s.iterations, precondition);
      result.iterations += more.iterations;
      for (std::size_t k = 0; k < n; ++k) x[k] += dx[k];
      r = residual(a, b, x, s.threads);
      rnorm = norm(r);
    }
    result.relative_residual = rnorm / bnorm;
  };
  if (s.amg)
    run([&](const Vec& r, Vec& z) { s.amg->apply(r.data(), z.data()); });
  else
    run([&](const Vec& r, Vec& z) { z = s.ic.solve(r); });
  return result;
}

namespace {

LinearSolveResult solve_spd_many_unchecked(const SymmetricCsr& a, const std::vector<std::vector<double>>& bs,
                                           std::vector<std::vector<double>>& xs,
                                           const LinearSolverOptions& options,
                                           const NearNullSpace* near_null) {
  SpdSolver solver(a, options, near_null);
  LinearSolveResult result;
  result.solver = solver.name();
  result.levels = solver.levels();
  xs.assign(bs.size(), {});
  report(options, "solve", 0.0);
  for (std::size_t i = 0; i < bs.size(); ++i) {
    report(options, "solve", static_cast<double>(i) / static_cast<double>(bs.size()));
    const LinearSolveResult one = solver.solve(bs[i], xs[i]);
    result.iterations += one.iterations;
    result.relative_residual = std::max(result.relative_residual, one.relative_residual);
  }
  report(options, "solve", 1.0);
  return result;
}

}  // namespace

LinearSolveResult solve_spd_many(const SymmetricCsr& a, const std::vector<std::vector<double>>& bs,
                                 std::vector<std::vector<double>>& xs, const LinearSolverOptions& options,
                                 const NearNullSpace* near_null) {
  require_finite_input(a, bs);
  LinearSolveResult result = solve_spd_many_unchecked(a, bs, xs, options, near_null);
  require_finite_output(xs, result);
  return result;
}

}  // namespace foxi::detail
