#include "linear_solve.hpp"

#include <Eigen/Dense>
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

double residual_norm(const SymmetricCsr& a, const std::vector<double>& b, const std::vector<double>& x,
                     unsigned threads) {
  std::vector<double> ax(b.size());
  multiply(a, x.data(), ax.data(), threads);
  double s = 0;
  for (std::size_t i = 0; i < b.size(); ++i) s += (b[i] - ax[i]) * (b[i] - ax[i]);
  return std::sqrt(s);
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
template <class Precondition>
void pcg(const SymmetricCsr& a, const std::vector<double>& b, std::vector<double>& x, double bnorm,
         const LinearSolverOptions& options, unsigned threads, LinearSolveResult& result,
         Precondition&& precondition) {
  const std::size_t n = a.rows();
  if (bnorm == 0) return;
  const double tol = options.relative_tolerance * bnorm;
  const std::size_t max_it = options.max_iterations ? options.max_iterations : 10 * n + 100;
  Vec r = Eigen::Map<const Vec>(b.data(), static_cast<Eigen::Index>(n)), z(static_cast<Eigen::Index>(n));
  precondition(r, z);
  Vec p = z, q(static_cast<Eigen::Index>(n));
  double* xd = x.data();
  double *rd = r.data(), *zd = z.data(), *pd = p.data(), *qd = q.data();
  double rz = parallel_sum(n, threads, [&](std::size_t i) { return rd[i] * zd[i]; });
  const double log_goal = std::log(std::max(1e-300, options.relative_tolerance));
  std::size_t it = 0;
  double rnorm = bnorm;
  while (rnorm > tol) {
    if (it == max_it)
      throw SolverError("conjugate gradients did not converge in " + std::to_string(max_it) +
                        " iterations (relative residual " + std::to_string(rnorm / bnorm) + ")");
    multiply(a, pd, qd, threads);
    const double pq = parallel_sum(n, threads, [&](std::size_t i) { return pd[i] * qd[i]; });
    if (!(pq > 0))
      throw SolverError(
          "conjugate gradients broke down: the matrix is not positive definite (a part with "
          "no fixed-temperature or convection boundary?)");
    const double alpha = rz / pq;
    rnorm = std::sqrt(parallel_sum(n, threads, [&](std::size_t i) {
      xd[i] += alpha * pd[i];
      rd[i] -= alpha * qd[i];
      return rd[i] * rd[i];
    }));
    ++it;
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
    if (it % 10 == 0) report(options, "solve", std::clamp(std::log(rnorm / bnorm) / log_goal, 0.0, 1.0));
  }
  result.iterations = it;
  result.relative_residual = residual_norm(a, b, x, threads) / bnorm;
}

// Aggregation algebraic multigrid for systems with several unknowns per node (elasticity): aggregates
// of strongly connected nodes, a tentative prolongation that interpolates the near-null space (the 6
// rigid-body modes) exactly on each aggregate, orthonormalised per aggregate by a QR whose R factors
// become the coarse level's near-null space; Galerkin coarse operators, symmetric (hybrid)
// Gauss-Seidel V(1,1) cycles, LDL^T on the coarsest level. Scalar problems use the smoothed-aggregation
// AMG on plain arrays in amg.cpp. TODO: move this block variant onto amg.cpp's CSR machinery too.
class BlockAmg {
 public:
  BlockAmg(const SymmetricCsr& a, const NearNullSpace& near_null) {
    RMat fine = Eigen::Map<const RMat>(
        static_cast<Eigen::Index>(a.rows()), static_cast<Eigen::Index>(a.rows()),
        static_cast<Eigen::Index>(a.val.size()), a.start.data(), a.col.data(), a.val.data());
    levels_.push_back({std::move(fine), {}, {}, {}, 1, {}});
    NearNullSpace ns = near_null;
    // Block problems: coarse levels are nearly dense (6 unknowns per aggregate, wide stencils), so
    // coarsen further and factorize the coarsest level densely.
    const Eigen::Index coarsest = kCoarsestBlock;
    while (levels_.back().a.rows() > coarsest && levels_.size() < 12) {
      Level& l = levels_.back();
      l.diag = l.a.diagonal();
      RMat tentative = block_tentative(l.a, ns);
      if (tentative.cols() == 0 || tentative.cols() >= l.a.rows() * 9 / 10) break;  // no longer coarsening
      // Block problems keep the tentative prolongation (plain aggregation): smoothing it made the
      // coarse operators 3.5 times denser and the setup 4 times slower for 35% fewer CG iterations
      // (250k tets), a net loss.
      RMat p = std::move(tentative);
      RMat r = p.transpose();
      RMat ap = product(l.a, p);
      RMat coarse = product(r, ap);
      l.p = std::move(p);
      l.r = std::move(r);
      levels_.push_back({std::move(coarse), {}, {}, {}, 1, {}});
    }
    levels_.back().diag = levels_.back().a.diagonal();
    for (Level& l : levels_) prepare_smoother(l);
    if (levels_.back().a.rows() <= 3 * kCoarsestBlock) {
      dense_coarse_.compute(Eigen::MatrixXd(levels_.back().a));
      if (dense_coarse_.info() != Eigen::Success)
        throw SolverError("AMG: the coarsest system could not be factorized");
      return;
    }
    coarse_.compute(Eigen::SparseMatrix<double>(levels_.back().a));
    if (coarse_.info() != Eigen::Success)
      throw SolverError("AMG: the coarsest system could not be factorized");
  }

  void apply(const Vec& r, Vec& z) const { cycle(0, r, z); }
  std::size_t level_count() const { return levels_.size(); }

 private:
  using RMat = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
  static constexpr Eigen::Index kCoarsestBlock = 600;
  struct Level {
    RMat a, p, r;
    Vec diag;
    // Hybrid Gauss-Seidel: `threads` contiguous row blocks swept at once, each with the other blocks'
    // values from before the sweep; smoother_diag is the l1 diagonal a_ii + sum |a_ij| over the
    // other blocks' columns (Baker, Falgout, Kolev, Yang 2011), which keeps the smoother convergent
    // and so the V-cycle a positive definite preconditioner. One block: plain Gauss-Seidel.
    unsigned threads = 1;
    Vec smoother_diag;
  };
  std::vector<Level> levels_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> coarse_;
  Eigen::LDLT<Eigen::MatrixXd> dense_coarse_;

  // a * b with the rows of a split between two threads (Eigen's sparse product is serial).
  static RMat product(const RMat& a, const RMat& b) {
    const Eigen::Index n = a.rows(), h = n / 2;
    if (n < 20000 || std::thread::hardware_concurrency() < 2) return RMat(a * b);
    RMat top, bottom;
    std::thread first([&] { top = a.topRows(h) * b; });
    bottom = a.bottomRows(n - h) * b;
    first.join();
    top.makeCompressed();
    bottom.makeCompressed();
    RMat c(n, b.cols());
    const Eigen::Index nt = top.nonZeros(), nb = bottom.nonZeros();
    c.resizeNonZeros(nt + nb);
    std::copy_n(top.innerIndexPtr(), nt, c.innerIndexPtr());
    std::copy_n(bottom.innerIndexPtr(), nb, c.innerIndexPtr() + nt);
    std::copy_n(top.valuePtr(), nt, c.valuePtr());
    std::copy_n(bottom.valuePtr(), nb, c.valuePtr() + nt);
    std::copy_n(top.outerIndexPtr(), h + 1, c.outerIndexPtr());
    for (Eigen::Index i = 1; i <= n - h; ++i)
      c.outerIndexPtr()[h + i] = static_cast<int>(nt) + bottom.outerIndexPtr()[i];
    return c;
  }

  // Aggregates of the graph (start, col) under the predicate strong(i, k) for edge k of node i, whose
  // strength is weight[k]: per node its aggregate; `count` gets the number of aggregates.
  template <class Strong>
  static std::vector<int> aggregate(std::size_t n, const int* start, const int* col, const double* weight,
                                    Strong&& strong, int& count) {
    std::vector<int> agg(n, -1);
    count = 0;
    // Pass 1: a node whose strong neighbours are all free starts an aggregate with them.
    for (std::size_t i = 0; i < n; ++i) {
      if (agg[i] >= 0) continue;
      bool free = true;
      int neighbours = 0;
      for (int k = start[i]; k < start[i + 1] && free; ++k)
        if (strong(i, k)) {
          ++neighbours;
          free = agg[col[k]] < 0;
        }
      if (!free || neighbours == 0) continue;
      agg[i] = count;
      for (int k = start[i]; k < start[i + 1]; ++k)
        if (strong(i, k)) agg[col[k]] = count;
      ++count;
    }
    // Pass 2: the rest join the aggregate of their strongest aggregated neighbour.
    std::vector<int> joined = agg;
    for (std::size_t i = 0; i < n; ++i) {
      if (agg[i] >= 0) continue;
      double best = 0;
      for (int k = start[i]; k < start[i + 1]; ++k)
        if (strong(i, k) && agg[col[k]] >= 0 && std::abs(weight[k]) > best) {
          best = std::abs(weight[k]);
          joined[i] = agg[col[k]];
        }
    }
    agg = std::move(joined);
    // Pass 3: what is still alone becomes an aggregate of its own.
    for (std::size_t i = 0; i < n; ++i)
      if (agg[i] < 0) agg[i] = count++;
    return agg;
  }

  // Systems of several unknowns per node: aggregates of nodes (strength from the Frobenius norms of
  // the node blocks, ||A_IJ|| >= theta sqrt(||A_II|| ||A_JJ||)), the near-null space orthonormalised
  // per aggregate; `ns` becomes the coarse level's near-null space (one coarse node per aggregate).
  static RMat block_tentative(const RMat& a, NearNullSpace& ns) {
    const std::size_t n = static_cast<std::size_t>(a.rows()), nodes = ns.nodes, k = ns.vectors;
    const int* start = a.outerIndexPtr();
    const int* col = a.innerIndexPtr();
    const double* val = a.valuePtr();
    // Unknowns of each node.
    std::vector<int> node_start(nodes + 1, 0), node_dof(n);
    for (std::size_t i = 0; i < n; ++i) ++node_start[ns.node[i] + 1];
    for (std::size_t v = 0; v < nodes; ++v) node_start[v + 1] += node_start[v];
    {
      std::vector<int> fill(node_start.begin(), node_start.end() - 1);
      for (std::size_t i = 0; i < n; ++i) node_dof[static_cast<std::size_t>(fill[ns.node[i]]++)] = static_cast<int>(i);
    }
    // The node graph with block norms.
    std::vector<int> gstart(nodes + 1, 0), gcol;
    std::vector<double> gval, acc(nodes, 0.0), self(nodes, 0.0);
    std::vector<std::uint32_t> mark(nodes, UINT32_MAX), touched;
    gcol.reserve(a.nonZeros() / 6);
    gval.reserve(a.nonZeros() / 6);
    for (std::size_t v = 0; v < nodes; ++v) {
      touched.clear();
      for (int d = node_start[v]; d < node_start[v + 1]; ++d) {
        const int i = node_dof[static_cast<std::size_t>(d)];
        for (int q = start[i]; q < start[i + 1]; ++q) {
          const std::uint32_t w = ns.node[static_cast<std::size_t>(col[q])];
          if (mark[w] != v) {
            mark[w] = static_cast<std::uint32_t>(v);
            acc[w] = 0;
            touched.push_back(w);
          }
          acc[w] += val[q] * val[q];
        }
      }
      std::sort(touched.begin(), touched.end());
      for (std::uint32_t w : touched) {
        gcol.push_back(static_cast<int>(w));
        gval.push_back(std::sqrt(acc[w]));
        if (w == v) self[v] = std::sqrt(acc[w]);
      }
      gstart[v + 1] = static_cast<int>(gcol.size());
    }
    // Measured on 250k tets (plain aggregation): theta 0.08 gives 61 CG iterations and 4 levels, 0.02
    // 53 iterations and 3 levels (30% less work), 0 56 iterations.
    const double theta = 0.02;
    auto strong = [&](std::size_t v, int q) {
      const auto w = static_cast<std::size_t>(gcol[static_cast<std::size_t>(q)]);
      return w != v && gval[static_cast<std::size_t>(q)] >= theta * std::sqrt(self[v] * self[w]);
    };
    int count = 0;
    const std::vector<int> agg = aggregate(nodes, gstart.data(), gcol.data(), gval.data(), strong, count);
    // Unknowns of each aggregate, their near-null space block, its QR.
    std::vector<int> agg_start(static_cast<std::size_t>(count) + 1, 0), agg_dof(n);
    for (std::size_t i = 0; i < n; ++i) ++agg_start[static_cast<std::size_t>(agg[ns.node[i]]) + 1];
    for (std::size_t g = 0; g < static_cast<std::size_t>(count); ++g) agg_start[g + 1] += agg_start[g];
    {
      std::vector<int> fill(agg_start.begin(), agg_start.end() - 1);
      for (std::size_t i = 0; i < n; ++i)
        agg_dof[static_cast<std::size_t>(fill[static_cast<std::size_t>(agg[ns.node[i]])]++)] = static_cast<int>(i);
    }
    NearNullSpace coarse;
    coarse.vectors = k;
    coarse.nodes = static_cast<std::size_t>(count);
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(n * k);
    int columns = 0;
    for (std::size_t g = 0; g < static_cast<std::size_t>(count); ++g) {
      const auto m = static_cast<Eigen::Index>(agg_start[g + 1] - agg_start[g]);
      const Eigen::Index r = std::min<Eigen::Index>(m, static_cast<Eigen::Index>(k));
      if (r == 0) continue;  // a node with every unknown constrained
      Eigen::MatrixXd b(m, static_cast<Eigen::Index>(k));
      for (Eigen::Index i = 0; i < m; ++i) {
        const auto dof = static_cast<std::size_t>(agg_dof[static_cast<std::size_t>(agg_start[g] + i)]);
        for (std::size_t c = 0; c < k; ++c) b(i, static_cast<Eigen::Index>(c)) = ns.values[dof * k + c];
      }
      Eigen::HouseholderQR<Eigen::MatrixXd> qr(b);
      const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(m, r);
      const Eigen::MatrixXd rf = qr.matrixQR().topRows(r).triangularView<Eigen::Upper>();
      for (Eigen::Index c = 0; c < r; ++c) {
        for (Eigen::Index i = 0; i < m; ++i)
          t.emplace_back(agg_dof[static_cast<std::size_t>(agg_start[g] + i)], columns + static_cast<int>(c), q(i, c));
        coarse.node.push_back(static_cast<std::uint32_t>(g));
        for (std::size_t c2 = 0; c2 < k; ++c2) coarse.values.push_back(rf(c, static_cast<Eigen::Index>(c2)));
      }
      columns += static_cast<int>(r);
    }
    RMat tentative(a.rows(), columns);
    tentative.setFromTriplets(t.begin(), t.end());
    ns = std::move(coarse);
    return tentative;
  }

  static void prepare_smoother(Level& l) {
    const Eigen::Index n = l.a.rows();
    l.threads = n >= 20000 && std::thread::hardware_concurrency() >= 2 ? 2u : 1u;
    l.smoother_diag = l.a.diagonal();
    if (l.threads == 1) return;
    const int* start = l.a.outerIndexPtr();
    const int* col = l.a.innerIndexPtr();
    const double* val = l.a.valuePtr();
    for (unsigned t = 0; t < l.threads; ++t) {
      const Eigen::Index lo = n * t / l.threads, hi = n * (t + 1) / l.threads;
      for (Eigen::Index i = lo; i < hi; ++i)
        for (int k = start[i]; k < start[i + 1]; ++k)
          if (col[k] < lo || col[k] >= hi) l.smoother_diag[i] += std::abs(val[k]);
    }
  }

  // Gauss-Seidel sweep on level l, forward or backward (hybrid over the level's row blocks).
  static void gauss_seidel(const Level& l, const Vec& b, Vec& x, bool forward, bool x_is_zero) {
    const Eigen::Index n = l.a.rows();
    const int* start = l.a.outerIndexPtr();
    const int* col = l.a.innerIndexPtr();
    const double* val = l.a.valuePtr();
    const Vec before = (l.threads > 1 && !x_is_zero) ? x : Vec();
    auto sweep = [&](Eigen::Index lo, Eigen::Index hi) {
      for (Eigen::Index s = lo; s < hi; ++s) {
        const Eigen::Index i = forward ? s : hi - 1 - (s - lo);
        double sum = b[i];
        for (int k = start[i]; k < start[i + 1]; ++k) {
          const int j = col[k];
          const double xj = (j >= lo && j < hi) ? x[j] : before.size() ? before[j] : 0.0;
          sum -= val[k] * xj;
        }
        x[i] += sum / l.smoother_diag[i];
      }
    };
    if (l.threads == 1) {
      sweep(0, n);
      return;
    }
    std::thread other([&] { sweep(n / 2, n); });
    sweep(0, n / 2);
    other.join();
  }

  // b - A x on the level's threads.
  static Vec residual(const Level& l, const Vec& b, const Vec& x) {
    Vec r(b.size());
    const int* start = l.a.outerIndexPtr();
    const int* col = l.a.innerIndexPtr();
    const double* val = l.a.valuePtr();
    parallel_for(static_cast<std::size_t>(b.size()), l.threads, [&](std::size_t lo, std::size_t hi, unsigned) {
      for (std::size_t i = lo; i < hi; ++i) {
        double s = b[static_cast<Eigen::Index>(i)];
        for (int k = start[i]; k < start[i + 1]; ++k) s -= val[k] * x[col[k]];
        r[static_cast<Eigen::Index>(i)] = s;
      }
    });
    return r;
  }

  void cycle(std::size_t level, const Vec& b, Vec& x) const {
    const Level& l = levels_[level];
    if (level + 1 == levels_.size()) {
      x = dense_coarse_.rows() > 0 ? Vec(dense_coarse_.solve(b)) : Vec(coarse_.solve(b));
      return;
    }
    x.setZero(b.size());
    gauss_seidel(l, b, x, true, true);
    const Vec coarse_b = l.r * residual(l, b, x);
    Vec coarse_x(coarse_b.size());
    cycle(level + 1, coarse_b, coarse_x);
    x += l.p * coarse_x;
    gauss_seidel(l, b, x, false, false);
  }
};
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

LinearSolveResult solve_spd_many(const SymmetricCsr& a, const std::vector<std::vector<double>>& bs,
                                 std::vector<std::vector<double>>& xs, const LinearSolverOptions& options,
                                 const NearNullSpace* near_null) {
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
    if (near_null) {
      result.solver = "CG+AggregationAMG(rigid-body modes)";
      BlockAmg amg(a, *near_null);
      result.levels = amg.level_count();
      report(options, "solve", 0.0);
      run_all([&](const Vec& r, Vec& z) { amg.apply(r, z); });
    } else {
      result.solver = "CG+SmoothedAggregationAMG";
      AmgPreconditioner amg(a, threads);
      result.levels = amg.level_count();
      report(options, "solve", 0.0);
      run_all([&](const Vec& r, Vec& z) { amg.apply(r.data(), z.data()); });
    }
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
