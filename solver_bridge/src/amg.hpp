// Internal: (smoothed-)aggregation algebraic multigrid (Vanek, Mandel, Brezina 1996) as the
// preconditioner of CG: aggregates of strongly connected unknowns (or of nodes, for systems with a
// near-null space such as elasticity's rigid-body modes), a tentative prolongation that interpolates
// the near-null space (the constants for scalar problems) on each aggregate, optionally smoothed by one
// damped Jacobi step, Galerkin coarse operators, symmetric Gauss-Seidel V(1,1) cycles, LDL^T on the
// coarsest level.
//
// Plain CSR arrays throughout (no sparse-matrix library in the setup): the products P^T (A P) run
// row-parallel in two passes (count, then fill) so that nothing is built twice, and the work vectors of the
// cycle are allocated once. The smoother is "hybrid" Gauss-Seidel: each thread sweeps its own contiguous
// block of rows and takes the values of the other blocks from before the sweep, the backward sweep mirroring
// the forward one, so one cycle stays a symmetric positive definite operator (and is plain symmetric
// Gauss-Seidel on one thread). The fine matrix is first renumbered breadth-first (a copy, in the hierarchy),
// so that the threads' blocks are compact bands of the mesh whatever the caller's node order: in a mesher's
// order (TetGen's Steiner points) most couplings crossed blocks, and the board-and-block TetGen mesh of 1M
// tets on 2 threads took 1,889 CG iterations instead of 35.
#pragma once

#include <cstddef>
#include <memory>

#include "linear_solve.hpp"

namespace foxi::detail {

struct AmgParams {
  // The near-null space (referenced only while the constructor runs): with one, nodes are aggregated
  // (their unknowns together) and the tentative prolongation interpolates these vectors exactly per
  // aggregate (orthonormalised by a QR); without one, single unknowns and the constants.
  const NearNullSpace* near_null = nullptr;
  // Smooth the tentative prolongation by one damped Jacobi step (smoothed aggregation); off: plain
  // aggregation, sparser coarse levels for more iterations.
  bool smooth_prolongation = true;
  // Hybrid Gauss-Seidel divides by a_ii + sum |a_ij| over the other threads' columns (the l1 smoother
  // of Baker, Falgout, Kolev, Yang 2011), which keeps it convergent where A is far from diagonally
  // dominant (elasticity); same as plain Gauss-Seidel on one thread.
  bool l1_smoother = false;
  // Smoothing sweeps before and after the coarse correction: forward, backward, forward, ... before,
  // their adjoints in reverse order after (1: V(1,1) symmetric Gauss-Seidel; 2: V(2,2), a symmetric
  // Gauss-Seidel step on each side).
  int sweeps = 1;
};

class AmgPreconditioner {
 public:
  // Builds the hierarchy of `a` (referenced, not copied: it must outlive this object) on `threads`
  // threads. Throws SolverError when the coarsest matrix cannot be factorized or a coarse matrix
  // would exceed 2^31 nonzeros.
  AmgPreconditioner(const SymmetricCsr& a, unsigned threads, const AmgParams& params = {});
  ~AmgPreconditioner();
  AmgPreconditioner(const AmgPreconditioner&) = delete;
  AmgPreconditioner& operator=(const AmgPreconditioner&) = delete;

  // z = M^-1 r by one V(1,1) cycle from zero; r and z have a.rows() entries. Uses the object's work
  // vectors: one call at a time.
  void apply(const double* r, double* z);
  std::size_t level_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace foxi::detail
