// Linear thermoelasticity (issue 7), with CalculiX in the same run.
//   foxi_thermoelastic/amg_250k    foxi::solve_thermoelastic: row-parallel 3x3-block assembly + CG with
//                                  smoothed-aggregation AMG on the 6 rigid-body modes, to a relative
//                                  residual of 1e-10 (counters: assembly and solve seconds, CG
//                                  iterations, AMG levels, DOF/s, peak RSS of the process so far)
//   foxi_thermoelastic/ichol_250k  the same with Eigen's incomplete Cholesky (the non-AMG option)
//   foxi_thermoelastic/direct_48k  SimplicialLDLT on a smaller mesh (fill-in grows fast in 3D)
//   ccx_250k                       CalculiX (Debian's ccx, SPOOLES) on the same mesh and problem, deck
//                                  written by foxi::write_calculix_thermoelastic; wall time of ccx alone
//                                  and its peak RSS (getrusage of the children). Skipped when ccx is
//                                  not installed or FOXI_BENCH_NO_CCX is set.
// Mesh: a jittered 35^3 Kuhn grid (257k tets, 46.7k nodes, 138k unknowns), lower and upper halves
// silicon-like (E 130 GPa, nu 0.28, alpha 2.6e-6) and copper-like (117 GPa, 0.34, 16.5e-6), the bottom
// fixed, dT = 100 K; n = 20 (48k tets) for the direct solver.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/solver/calculix.hpp"
#include "foxi/solver/thermoelastic.hpp"

namespace {

using namespace foxi;

Mesh& grid(std::uint32_t n) {
  static std::unique_ptr<Mesh> meshes[2];
  auto& m = meshes[n == 35 ? 0 : 1];
  if (!m) m = std::make_unique<Mesh>(bench::kuhn_grid_mesh(n));
  return *m;
}

ThermoelasticParams params(LinearSolverKind kind) {
  ThermoelasticParams p;
  p.materials = {{1, 130e9, 0.28, 2.6e-6}, {2, 117e9, 0.34, 16.5e-6}};
  p.fixed = {{5}};
  p.delta_t = 100;
  p.solver.kind = kind;
  p.solver.relative_tolerance = 1e-10;
  return p;
}

double peak_rss_mb(int who) {
  rusage u{};
  getrusage(who, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

void foxi_thermoelastic(benchmark::State& state, LinearSolverKind kind, std::uint32_t n) {
  Mesh& m = grid(n);
  const ThermoelasticParams p = params(kind);
  ThermoelasticReport r;
  double assembly = 0, solve = 0;
  for (auto _ : state) {
    r = solve_thermoelastic(m, p);
    assembly += r.assembly_seconds;
    solve += r.solve_seconds;
  }
  const double it = static_cast<double>(state.iterations());
  state.counters["tets"] = static_cast<double>(m.tet_count());
  state.counters["unknowns"] = static_cast<double>(r.unknowns);
  state.counters["assembly_s"] = assembly / it;
  state.counters["solve_s"] = solve / it;
  state.counters["cg_iterations"] = static_cast<double>(r.iterations);
  state.counters["amg_levels"] = static_cast<double>(r.amg_levels);
  state.counters["residual"] = r.relative_residual;
  state.counters["DOF_per_s"] = static_cast<double>(r.unknowns) / ((assembly + solve) / it);
  state.counters["ns_per_tet"] = 1e9 * (assembly + solve) / it / static_cast<double>(m.tet_count());
  state.counters["max_von_mises"] = r.max_von_mises;
  state.counters["peak_rss_MB"] = peak_rss_mb(RUSAGE_SELF);
}

void ccx_250k(benchmark::State& state) {
  if (std::getenv("FOXI_BENCH_NO_CCX") != nullptr || std::system("command -v ccx > /dev/null 2>&1") != 0) {
    state.SkipWithError("ccx not installed (or FOXI_BENCH_NO_CCX set)");
    return;
  }
  Mesh& m = grid(35);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("foxi-bench-ccx-" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(dir);
  write_calculix_thermoelastic(m, params(LinearSolverKind::automatic), dir / "stress.inp");
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = std::system(("cd '" + dir.string() + "' && ccx -i stress > ccx.log 2>&1").c_str());
    const auto t1 = std::chrono::steady_clock::now();
    if (rc != 0) state.SkipWithError("ccx failed");
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  }
  state.counters["tets"] = static_cast<double>(m.tet_count());
  state.counters["peak_rss_MB"] = peak_rss_mb(RUSAGE_CHILDREN);
  std::filesystem::remove_all(dir);
}

BENCHMARK_CAPTURE(foxi_thermoelastic, amg_250k, LinearSolverKind::cg_amg, 35u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);
BENCHMARK(ccx_250k)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(foxi_thermoelastic, ichol_250k, LinearSolverKind::cg_ichol, 35u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(foxi_thermoelastic, direct_48k, LinearSolverKind::direct, 20u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
