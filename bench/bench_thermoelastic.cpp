// Linear thermoelasticity (issue 7), with CalculiX in the same run.
//   foxi_thermoelastic/amg_250k    foxi::solve_thermoelastic: row-parallel 3x3-block assembly + CG with
//                                  aggregation AMG (amg.hpp) on the 6 rigid-body modes, to a relative
//                                  residual of 1e-10 (counters: assembly and solve seconds, CG
//                                  iterations, AMG levels, DOF/s, peak RSS of the process so far,
//                                  process_cpu_s: CPU seconds of all threads per run)
//   foxi_thermoelastic/ichol_250k  the same with Eigen's incomplete Cholesky (the non-AMG option)
//   foxi_thermoelastic/direct_10k  SimplicialLDLT on a smaller mesh (fill-in grows fast in 3D: on 48k
//                                  tets it took 23 s of CPU against about 1 s for AMG on 250k)
//   foxi_thermoelastic/p1_48k, p2_48k  linear and quadratic (10-node) tets with AMG on one 20^3 grid
//                                  (48k tets; P2 has about 7x the unknowns of P1)
//   ccx_c3d10_48k                  ccx on the same P2 problem (C3D10 deck with foxi's mid-edge nodes)
//   ccx_250k                       CalculiX (Debian's ccx, SPOOLES) on the same mesh and problem, deck
//                                  written by foxi::write_calculix_thermoelastic; wall time of ccx alone
//                                  and its peak RSS (getrusage of the children). Skipped when ccx is
//                                  not installed or FOXI_BENCH_NO_CCX is set.
// Mesh: a jittered 35^3 Kuhn grid (257k tets, 46.7k nodes, 138k unknowns), lower and upper halves
// silicon-like (E 130 GPa, nu 0.28, alpha 2.6e-6) and copper-like (117 GPa, 0.34, 16.5e-6), the bottom
// fixed, dT = 100 K; n = 12 (10k tets) for the direct solver.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "bench_ccx.hpp"
#include "bench_meshes.hpp"
#include "foxi/solver/calculix.hpp"
#include "foxi/solver/thermoelastic.hpp"

namespace {

using namespace foxi;

Mesh& grid(std::uint32_t n) {
  static std::unique_ptr<Mesh> meshes[3];
  auto& m = meshes[n == 35 ? 0 : n == 20 ? 1 : 2];  // 35, 20 or 12
  if (!m) m = std::make_unique<Mesh>(bench::kuhn_grid_mesh(n));
  return *m;
}

ThermoelasticParams params(LinearSolverKind kind, int order = 1) {
  ThermoelasticParams p;
  p.order = order;
  p.materials = {{1, 130e9, 0.28, 2.6e-6}, {2, 117e9, 0.34, 16.5e-6}};
  p.fixed = {{5}};
  p.delta_t = 100;
  p.solver.kind = kind;
  p.solver.relative_tolerance = 1e-10;
  return p;
}

void foxi_thermoelastic(benchmark::State& state, LinearSolverKind kind, std::uint32_t n, int order = 1) {
  Mesh& m = grid(n);
  const ThermoelasticParams p = params(kind, order);
  ThermoelasticReport r;
  double assembly = 0, solve = 0;
  const double cpu_before = bench::process_cpu_seconds();
  for (auto _ : state) {
    r = solve_thermoelastic(m, p);
    assembly += r.assembly_seconds;
    solve += r.solve_seconds;
  }
  const double it = static_cast<double>(state.iterations());
  state.counters["process_cpu_s"] = (bench::process_cpu_seconds() - cpu_before) / it;
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
  state.counters["peak_rss_MB"] = bench::peak_rss_mb(RUSAGE_SELF);
}

void ccx_run(benchmark::State& state, std::uint32_t n, int order) {
  Mesh& m = grid(n);
  bench::time_ccx(
      state, "stress",
      [&](const std::filesystem::path& inp) {
        write_calculix_thermoelastic(m, params(LinearSolverKind::automatic, order), inp);
      },
      std::getenv("FOXI_BENCH_NO_CCX") == nullptr, "ccx not installed (or FOXI_BENCH_NO_CCX set)");
  state.counters["tets"] = static_cast<double>(m.tet_count());
}
void ccx_250k(benchmark::State& state) { ccx_run(state, 35, 1); }
void ccx_c3d10_48k(benchmark::State& state) { ccx_run(state, 20, 2); }

BENCHMARK_CAPTURE(foxi_thermoelastic, amg_250k, LinearSolverKind::cg_amg, 35u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);
BENCHMARK(ccx_250k)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(foxi_thermoelastic, ichol_250k, LinearSolverKind::cg_ichol, 35u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(foxi_thermoelastic, direct_10k, LinearSolverKind::direct, 12u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(foxi_thermoelastic, p1_48k, LinearSolverKind::cg_amg, 20u, 1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(foxi_thermoelastic, p2_48k, LinearSolverKind::cg_amg, 20u, 2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK(ccx_c3d10_48k)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
