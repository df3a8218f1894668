// Transient heat conduction (issue 18, "Performance"), with its baselines in the same run:
//   transient/kuhn_N    one run does, on the same mesh and problem:
//                       - one steady solve (foxi::solve_thermal, AMG-CG to 1e-10): steady_s
//                       - the transient solve, 100 BDF2 steps, the temperature written as a .vtu
//                         every 10th step (10 files, as `foxi solve --physics transient --steps 100
//                         --write-every 10` does): transient_s, the benchmark's time; the target is
//                         x_steady = transient_s / steady_s <= 15
//                       - CalculiX (Debian's ccx, SPOOLES) on the same mesh, materials, conditions
//                         and the same 100 fixed increments (*HEAT TRANSFER, DIRECT), writing NT
//                         every 10th increment (FOXI_BENCH_CCX=1; skipped otherwise): ccx_s and
//                         x_ccx = transient_s / ccx_s
//                       counters also: tets, CG iterations of the transient (all steps), its energy
//                       check's figure (the run is an error when the check fails), CPU seconds of
//                       the process for each (steady_cpu_s, transient_cpu_s, x_steady_cpu: steadier
//                       than wall time on a loaded machine) and the
//                       1-minute load average when the run started (load_1min), which the figures
//                       must be read with on a shared machine.
// Sizes: the Kuhn grid of bench_thermal.cpp (two regions, k 1 and 10 W/(m K), fixed 300 K at z = 0,
// convection h 100 to 300 K at z = n, 1 kW in the upper half), rho c 1.6e6 J/(m^3 K), from 300 K
// (--initial 300), end time 0.05 n^2 rho c / k (a tenth of the way to the steady state, so that
// the steps are transient work): n = 30 (162k tets) always, n = 57 (1.11M tets) with FOXI_BENCH_1M=1.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "bench_ccx.hpp"
#include "bench_meshes.hpp"
#include "foxi/model/io_vtk.hpp"
#include "foxi/solver/calculix.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/solver/transient.hpp"

namespace {

using namespace foxi;

constexpr double kRhoC = 1.6e6;  // J/(m^3 K): rho 2000 kg/m^3, c 800 J/(kg K)
constexpr std::size_t kSteps = 100, kWriteEvery = 10;

ThermalParams steady_params() {
  ThermalParams p;
  p.conductivity = {{1, 1.0}, {2, 10.0}};
  p.fixed = {{5, 300}};
  p.convection = {{6, 100, 300}};
  p.sources = {{2, 1000, true}};
  p.solver.kind = LinearSolverKind::cg_amg;
  p.solver.relative_tolerance = 1e-10;
  return p;
}

double load_1min() {
  std::ifstream in("/proc/loadavg");
  double l = -1;
  in >> l;
  return l;
}

// The steady deck of write_calculix_thermal made transient: density and specific heat per material,
// a uniform initial temperature, *HEAT TRANSFER, DIRECT with fixed increments dt up to end_time,
// NT written every kWriteEvery increments. The body flux (the power) is a step at t = 0 (AMPLITUDE
// of constant 1), as foxi's step waveform.
std::string transient_deck(const std::string& steady, double dt, double end_time) {
  std::istringstream in(steady);
  std::ostringstream out;
  char buf[128];
  bool after_conductivity = false;
  for (std::string line; std::getline(in, line);) {
    if (line == "*STEP") {
      out << "*INITIAL CONDITIONS, TYPE=TEMPERATURE\nNALL, 300\n*AMPLITUDE, NAME=ON\n0, 1, 1e30, 1\n";
      out << line << ", INC=100000\n";
      continue;
    }
    if (line == "*HEAT TRANSFER, STEADY STATE") {
      std::snprintf(buf, sizeof buf, "*HEAT TRANSFER, DIRECT\n%.17g, %.17g\n", dt, end_time);
      out << buf;
      continue;
    }
    if (line == "*DFLUX") {
      out << "*DFLUX, AMPLITUDE=ON\n";
      continue;
    }
    if (line == "*NODE OUTPUT" || line == "*NODE FILE") {  // the deck asks for binary results
      out << line << ", FREQUENCY=" << kWriteEvery << "\n";
      continue;
    }
    out << line << "\n";
    if (after_conductivity) {  // the conductivity's value line
      std::snprintf(buf, sizeof buf, "*DENSITY\n2000\n*SPECIFIC HEAT\n%.17g\n", kRhoC / 2000);
      out << buf;
    }
    after_conductivity = line == "*CONDUCTIVITY";
  }
  return out.str();
}

void transient(benchmark::State& state, std::uint32_t n) {
  if (n > 40 && std::getenv("FOXI_BENCH_1M") == nullptr) {
    state.SkipWithError("the 1M-tet case: set FOXI_BENCH_1M=1 (minutes, and ccx much longer)");
    return;
  }
  state.counters["load_1min"] = load_1min();
  Mesh mesh = bench::kuhn_grid_mesh(n);
  const ThermalParams steady = steady_params();
  TransientParams tp;
  tp.thermal = steady;
  tp.thermal.sources.clear();
  tp.power = {{2, PowerWaveform::step_of(1000)}};
  tp.heat_capacity = {{1, kRhoC}, {2, kRhoC}};
  tp.end_time = 0.05 * double(n) * double(n) * kRhoC / 1.0;
  tp.steps = kSteps;
  tp.initial_temperature = 300;
  tp.junctions = {2};
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("foxi-bench-transient-" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(dir);
  Mesh frame = mesh;
  frame.fields.clear();
  std::size_t written = 0;
  tp.on_step = [&](std::size_t step, double, std::span<const double> temperature) {
    if (step % kWriteEvery != 0 || step == 0) return true;
    frame.fields = {
        Field{"temperature", FieldLocation::node, 1, "K", {}, {temperature.begin(), temperature.end()}}};
    char name[32];
    std::snprintf(name, sizeof name, "run_%04zu.vtu", written++);
    write_vtu(frame, dir / name);
    return true;
  };
  double steady_s = 0, transient_s = 0, steady_cpu = 0, transient_cpu = 0;
  TransientReport r;
  for (auto _ : state) {
    double c0 = bench::process_cpu_seconds();
    auto t0 = std::chrono::steady_clock::now();
    const ThermalReport s = solve_thermal(mesh, steady);
    auto t1 = std::chrono::steady_clock::now();
    steady_cpu = bench::process_cpu_seconds() - c0;
    benchmark::DoNotOptimize(s.max_temperature);
    steady_s = std::chrono::duration<double>(t1 - t0).count();
    written = 0;
    c0 = bench::process_cpu_seconds();
    t0 = std::chrono::steady_clock::now();
    r = solve_transient_thermal(mesh, tp);
    t1 = std::chrono::steady_clock::now();
    transient_cpu = bench::process_cpu_seconds() - c0;
    transient_s = std::chrono::duration<double>(t1 - t0).count();
    state.SetIterationTime(transient_s);
  }
  state.counters["tets"] = double(mesh.tet_count());
  state.counters["steady_s"] = steady_s;
  state.counters["transient_s"] = transient_s;
  state.counters["x_steady"] = transient_s / steady_s;
  state.counters["steady_cpu_s"] = steady_cpu;
  state.counters["transient_cpu_s"] = transient_cpu;
  state.counters["x_steady_cpu"] = transient_cpu / steady_cpu;
  state.counters["cg_iterations"] = double(r.iterations);
  state.counters["files"] = double(written);
  state.counters["Tj_end"] = r.junction_temperature[0].back();
  // The solver's own energy check (heat in against stored energy): a fast wrong run is no figure.
  for (const BalanceCheck& c : r.checks)
    if (c.name == "energy") state.counters["energy_check"] = c.figure;
  if (!all_passed(r.checks)) state.SkipWithError("the transient's energy check failed");
  if (std::getenv("FOXI_BENCH_CCX") != nullptr && std::system("command -v ccx > /dev/null 2>&1") == 0) {
    write_calculix_thermal(mesh, steady, dir / "steady.inp");
    std::ostringstream steady_text;
    steady_text << std::ifstream(dir / "steady.inp").rdbuf();
    std::ofstream(dir / "heat.inp") << transient_deck(steady_text.str(), tp.end_time / double(kSteps),
                                                      tp.end_time);
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = std::system(("cd '" + dir.string() + "' && ccx -i heat > ccx.log 2>&1").c_str());
    const double ccx_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (rc != 0) {
      state.SkipWithError(("ccx failed; see its log in " + dir.string()).c_str());
      return;
    }
    // The last written block's largest temperature (the heated upper region holds the maximum),
    // beside foxi's Tj_end: a check that ccx solved the same problem (ccx's C3D4 heat capacity is
    // consistent, foxi's lumped, so they differ a little), not a timing.
    const std::vector<FrdBlock> blocks = read_frd(dir / "heat.frd");
    double tmax = -1e300;
    std::size_t nt = 0;
    for (const FrdBlock& b : blocks)
      if (b.name == "NDTEMP") ++nt;
    for (auto it = blocks.rbegin(); it != blocks.rend(); ++it)
      if (it->name == "NDTEMP") {
        for (double v : it->values) tmax = std::max(tmax, v);
        break;
      }
    state.counters["ccx_s"] = ccx_s;
    state.counters["x_ccx"] = transient_s / ccx_s;
    state.counters["ccx_Tmax_end"] = tmax;
    state.counters["ccx_frames"] = double(nt);
    state.counters["peak_rss_ccx_MB"] = bench::peak_rss_mb(RUSAGE_CHILDREN);
  }
  std::filesystem::remove_all(dir);
}

// A quick one: the deck and the counters in seconds.
BENCHMARK_CAPTURE(transient, kuhn_10k, 12u)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(transient, kuhn_162k, 30u)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(transient, kuhn_1M, 57u)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
