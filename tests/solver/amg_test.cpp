// The scalar AMG (solver_bridge/src/amg.cpp) on unstructured Delaunay meshes as a user's mesher makes
// them (the tetgen program, -pq1.414 without mesh optimisation, TetGen's node order): CG with it
// reaches 1e-10 in at most 50 iterations on several threads, and its answer is the analytic one (a
// layered slab: P1 is exact for a piecewise-linear temperature) or the direct solver's (a block on a
// board, contrast 1e4). Before the fine matrix was renumbered and the smoother took l1 sums, these
// meshes took hundreds to thousands of iterations on 2 or more threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/solver/thermal.hpp"
#include "layered_box.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

// Threads for the AMG runs: more than one, so that the hybrid smoother's blocks and their couplings
// are exercised whatever machine runs the test (the smoother is sequential below 250k nonzeros, so
// the meshes are larger than that).
constexpr unsigned kThreads = 4;

// `poly` meshed by tetgen -pq1.414 -a`max_volume` -O0 (no flips or smoothing, as foxi meshes).
Mesh tetgen_o0_mesh(const std::string& poly, double max_volume) {
  test::TempDir dir;
  test::write_text(dir / "in.poly", poly);
  std::ostringstream cmd;
  cmd.precision(17);
  cmd << "tetgen -pq1.414AO0Qa" << max_volume << " '" << (dir / "in.poly").string() << "'";
  if (test::run(cmd.str(), dir / "log") != 0)
    throw std::runtime_error("tetgen failed: " + test::read_text(dir / "log"));
  Mesh mesh = read_tetgen(dir / "in.1");
  validate_and_repair(mesh);
  return mesh;
}

ThermalReport solve(Mesh& m, ThermalParams p, LinearSolverKind kind, double tolerance = 1e-10) {
  p.solver.kind = kind;
  p.solver.relative_tolerance = tolerance;
  p.solver.threads = kThreads;
  return solve_thermal(m, p);
}

// A 10 x 10 x 2 box in two layers (z < 1: k 1, z > 1: k 1e4), 300 K at z = 0 and 400 K at z = 2:
// the temperature is piecewise linear in z (the series resistance 1/k1 + 1/k2 per unit area), which
// P1 reproduces exactly at every node.
TEST(Amg, TwoLayerBoxOnTetgenMeshConvergesToTheAnalyticTemperature) {
  const double k1 = 1, k2 = 1e4;
  Mesh m = tetgen_o0_mesh(test::layered_box_poly(10, 10, {0, 1, 2}), 0.003);
  ASSERT_GT(m.tet_count(), 120000u);
  ThermalParams p;
  p.conductivity = {{1, k1}, {2, k2}};
  p.fixed = {{5, 300}, {6, 400}};
  const ThermalReport r = solve(m, p, LinearSolverKind::cg_amg);
  EXPECT_EQ(r.solver, "CG+SmoothedAggregationAMG");
  EXPECT_LE(r.iterations, 50u);
  EXPECT_LE(r.relative_residual, 1e-10);
  // Interface temperature: equal fluxes k1 (Ti - 300) / 1 = k2 (400 - Ti) / 1.
  const double ti = (k1 * 300 + k2 * 400) / (k1 + k2);
  const std::vector<double>& t = m.find_field("temperature")->values;
  double worst = 0;
  for (std::size_t v = 0; v < m.node_count(); ++v) {
    const double z = m.xyz[3 * v + 2];
    const double exact = z <= 1 ? 300 + (ti - 300) * z : ti + (400 - ti) * (z - 1);
    worst = std::max(worst, std::abs(t[v] - exact));
  }
  EXPECT_LT(worst, 1e-6) << "largest nodal error, K";
}

// The board and block of issue 18 (10 x 10 x 1 board, 4 x 4 x 0.5 block on it, TetGen's own
// region attributes 1 and 2), 300 K on the board's bottom (marker 1) and 400 K on the block's top
// (marker 6), the block 1e4 times less or more conductive than the board: AMG's temperatures equal
// the sparse direct solver's.
const char* const kBoardBlockPoly = R"(16 3 0 0
1 0 0 0
2 10 0 0
3 10 10 0
4 0 10 0
5 0 0 1
6 10 0 1
7 10 10 1
8 0 10 1
9 3 3 1
10 7 3 1
11 7 7 1
12 3 7 1
13 3 3 1.5
14 7 3 1.5
15 7 7 1.5
16 3 7 1.5
15 1
1 0 1
4 1 2 3 4
1 0 2
4 1 2 6 5
1 0 2
4 2 3 7 6
1 0 2
4 3 4 8 7
1 0 2
4 4 1 5 8
1 0 3
4 5 6 10 9
1 0 3
4 6 7 11 10
1 0 3
4 7 8 12 11
1 0 3
4 8 5 9 12
1 0 4
4 9 10 11 12
1 0 5
4 9 10 14 13
1 0 5
4 10 11 15 14
1 0 5
4 11 12 16 15
1 0 5
4 12 9 13 16
1 0 6
4 13 14 15 16
0
2
1 5 5 0.5 1 -1
2 5 5 1.25 2 -1
)";

TEST(Amg, BoardAndBlockAtContrast1e4MatchesTheDirectSolver) {
  Mesh m = tetgen_o0_mesh(kBoardBlockPoly, 0.0018);
  ASSERT_GT(m.tet_count(), 120000u);
  for (double block_k : {1e-4, 1e4}) {
    SCOPED_TRACE("block k " + std::to_string(block_k));
    ThermalParams p;
    p.conductivity = {{1, 1.0}, {2, block_k}};
    p.fixed = {{1, 300}, {6, 400}};
    const ThermalReport amg = solve(m, p, LinearSolverKind::cg_amg);
    EXPECT_LE(amg.iterations, 50u);
    // The comparison at a tighter tolerance: at 1e-10 the nodal error is bounded only through the
    // condition number (a contrast of 1e4 left 3e-5 K).
    solve(m, p, LinearSolverKind::cg_amg, 1e-13);
    const std::vector<double> t_amg = m.find_field("temperature")->values;
    const ThermalReport direct = solve(m, p, LinearSolverKind::direct);
    EXPECT_EQ(direct.solver, "SimplicialLDLT");
    const std::vector<double>& t_direct = m.find_field("temperature")->values;
    double worst = 0;
    for (std::size_t v = 0; v < m.node_count(); ++v)
      worst = std::max(worst, std::abs(t_amg[v] - t_direct[v]));
    EXPECT_LT(worst, 1e-6) << "largest nodal difference, K";
  }
}

}  // namespace
}  // namespace foxi
