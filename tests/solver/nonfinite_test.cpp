// The solvers refuse rather than report numbers computed from NaN or infinity (issue 22: a mesh
// scaled by 1e154 has infinite tet volumes; the solve returned NaN, `foxi solve` then read outside
// an array, and with the AMG solver exited 0 printing "max temperature 0 K").
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/solver/thermal.hpp"

namespace foxi {
namespace {

ThermalParams hot_and_cold(double k) {
  ThermalParams p;
  p.conductivity = {{1, k}, {2, k}};
  p.fixed = {{1, 300.0}, {2, 400.0}};  // the x- and x+ faces
  return p;
}

bool says_nonfinite(const SolverError& e) {
  const std::string m = e.what();
  return m.find("NaN or infinity") != std::string::npos || m.find("range of double") != std::string::npos;
}

TEST(NonFinite, InfiniteVolumesAreRefused) {
  for (LinearSolverKind kind :
       {LinearSolverKind::direct, LinearSolverKind::cg_amg, LinearSolverKind::cg_ichol}) {
    Mesh m = bench::kuhn_grid_mesh(3, 0.0);
    for (double& x : m.xyz) x *= 1e154;
    ThermalParams p = hot_and_cold(1.0);
    p.solver.kind = kind;
    try {
      const ThermalReport r = solve_thermal(m, p);
      ADD_FAILURE() << "solved, max temperature " << r.max_temperature;
    } catch (const SolverError& e) {
      EXPECT_TRUE(says_nonfinite(e)) << e.what();
    }
  }
}

TEST(NonFinite, OverflowingStiffnessIsRefused) {
  // Finite volumes, but a conductivity of 1e308 on 10 m cells overflows the matrix entries.
  for (LinearSolverKind kind :
       {LinearSolverKind::direct, LinearSolverKind::cg_amg, LinearSolverKind::cg_ichol}) {
    Mesh m = bench::kuhn_grid_mesh(3, 0.0);
    for (double& x : m.xyz) x *= 10;
    ThermalParams p = hot_and_cold(1e308);
    p.solver.kind = kind;
    try {
      const ThermalReport r = solve_thermal(m, p);
      ADD_FAILURE() << "solved, max temperature " << r.max_temperature;
    } catch (const SolverError& e) {
      EXPECT_TRUE(says_nonfinite(e)) << e.what();
    }
  }
}

TEST(NonFinite, OrdinaryScalesStillSolve) {
  // The same problem at 1 m and at 1e-6 m: a linear profile from 300 K to 400 K (exact for P1).
  for (double s : {1.0, 1e-6}) {
    Mesh m = bench::kuhn_grid_mesh(3, 0.0);
    for (double& x : m.xyz) x *= s;
    const ThermalReport r = solve_thermal(m, hot_and_cold(1.0));
    EXPECT_NEAR(r.max_temperature, 400.0, 1e-6) << s;
  }
}

}  // namespace
}  // namespace foxi
