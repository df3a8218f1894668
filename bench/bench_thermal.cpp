// Steady heat conduction (issue 7), with its baselines in the same run.
//   foxi_thermal/amg       foxi::solve_thermal: row-parallel assembly + CG with smoothed-aggregation
//                          AMG to a relative residual of 1e-10 (counters: assembly and solve seconds,
//                          iterations, DOF/s)
//   foxi_thermal/ichol     the same with Eigen's incomplete Cholesky as the preconditioner
//   foxi_thermal/direct    the same with SimplicialLDLT (smaller mesh only: fill-in)
//   triplet_assembly       the textbook assembly: one serial triplet list, Eigen setFromTriplets
//   ccx_1M                 CalculiX (Debian's ccx, SPOOLES) on the same mesh and problem, deck written
//                          by foxi::write_calculix_thermal (wall time of ccx alone; set FOXI_BENCH_CCX=1,
//                          it takes about half a minute)
//   eigen_cg_jacobi        Eigen's ConjugateGradient with the diagonal (Jacobi) preconditioner on the
//                          same system (what scipy's Jacobi-CG does)
//   foxi_thermal/amg_6M    the 6M-tet figure (goal: <= 6 s assembly + solve, <= 3 GB peak): a 100^3
//                          Kuhn grid (6.0M tets, 1.03M nodes); counters peak_MB (VmHWM of the process
//                          while solving, mesh included), solver_MB (what the solve adds) and
//                          process_cpu_s (CPU seconds of all threads per run)
//   tetgen_thermal/{amg,ichol}_{box_948k,board_1M}, tetgen_ccx/{box_948k,board_1M}
//                          the meshes users have: TetGen -pq1.414 -O0 meshes made in the run (tetgen
//                          program) of a box with fixed bottom and top and of a board carrying a block
//                          (k 1 and 1000, fixed board bottom and block top), AMG against incomplete
//                          Cholesky and ccx (FOXI_BENCH_CCX=1) on the same mesh and problem
// Mesh: a 57^3 Kuhn grid (1.11M tets, 195k nodes), two regions (k 1 and 10 W/(m K)), fixed 300 K at
// z = 0, convection (h 100, 300 K) at z = 1, 1 kW in the upper region; with n = 30 (162k tets) for
// the direct solver.
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <sys/resource.h>

#include <Eigen/Geometry>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <array>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>

#include "bench_ccx.hpp"
#include "bench_meshes.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/solver/calculix.hpp"
#include "foxi/solver/thermal.hpp"

namespace {

using namespace foxi;

// One cached mesh at a time, so that the memory counters of a case do not include another's mesh.
template <class Make>
Mesh& cached_mesh(const std::string& key, Make&& make) {
  static std::string cached_key;
  static std::unique_ptr<Mesh> cached;
  if (!cached || cached_key != key) {
    cached.reset();
    cached = std::make_unique<Mesh>(make());
    cached_key = key;
  }
  return *cached;
}

Mesh& grid(std::uint32_t n) {
  return cached_mesh("kuhn" + std::to_string(n), [n] { return bench::kuhn_grid_mesh(n); });
}

// The meshes users have (issue 18): TetGen's -pq1.414 -O0 (no flips or smoothing) in TetGen's node
// order, made by the tetgen program in the run. "box": 10 x 10 x 2, markers 1 bottom, 2 top, 3 sides,
// 948k tets. "board": a 10 x 10 x 1 board (region 1) carrying a 4 x 4 x 0.5 block (region 2),
// markers 1 board bottom, 6 block top (/work/shared/peers/box_block.poly), 1.0M tets.
const char* const kBoxPoly =
    "8 3 0 0\n1 0 0 0\n2 10 0 0\n3 10 10 0\n4 0 10 0\n5 0 0 2\n6 10 0 2\n7 10 10 2\n8 0 10 2\n"
    "6 1\n1 0 1\n4 1 2 3 4\n1 0 2\n4 5 6 7 8\n1 0 3\n4 1 2 6 5\n1 0 3\n4 2 3 7 6\n1 0 3\n4 3 4 8 7\n"
    "1 0 3\n4 4 1 5 8\n0\n0\n";
const char* const kBoardPoly =
    "16 3 0 0\n1 0 0 0\n2 10 0 0\n3 10 10 0\n4 0 10 0\n5 0 0 1\n6 10 0 1\n7 10 10 1\n8 0 10 1\n"
    "9 3 3 1\n10 7 3 1\n11 7 7 1\n12 3 7 1\n13 3 3 1.5\n14 7 3 1.5\n15 7 7 1.5\n16 3 7 1.5\n"
    "15 1\n1 0 1\n4 1 2 3 4\n1 0 2\n4 1 2 6 5\n1 0 2\n4 2 3 7 6\n1 0 2\n4 3 4 8 7\n1 0 2\n4 4 1 5 8\n"
    "1 0 3\n4 5 6 10 9\n1 0 3\n4 6 7 11 10\n1 0 3\n4 7 8 12 11\n1 0 3\n4 8 5 9 12\n1 0 4\n4 9 10 11 12\n"
    "1 0 5\n4 9 10 14 13\n1 0 5\n4 10 11 15 14\n1 0 5\n4 11 12 16 15\n1 0 5\n4 12 9 13 16\n"
    "1 0 6\n4 13 14 15 16\n0\n2\n1 5 5 0.5 1 -1\n2 5 5 1.25 2 -1\n";

// Null (and the benchmark skipped with the reason) where tetgen is missing or fails.
Mesh* tetgen_mesh(benchmark::State& state, const std::string& which) {
  if (std::system("command -v tetgen > /dev/null 2>&1") != 0) {
    state.SkipWithError("needs the tetgen program (Debian's tetgen)");
    return nullptr;
  }
  bool failed = false;
  Mesh& m = cached_mesh("tetgen-" + which, [&] {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                      ("foxi-bench-tetgen-" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "in.poly") << (which == "box" ? kBoxPoly : kBoardPoly);
    const char* volume = which == "box" ? "0.00042" : "0.00022";
    Mesh out;
    if (std::system(("tetgen -Qpq1.414AO0a" + std::string(volume) + " '" + (dir / "in.poly").string() + "'")
                        .c_str()) == 0)
      out = read_tetgen(dir / "in.1");
    else
      failed = true;
    std::filesystem::remove_all(dir);
    return out;
  });
  if (failed || m.tet_count() == 0) {
    state.SkipWithError("tetgen failed");
    return nullptr;
  }
  return &m;
}

// box: 300 K bottom, 400 K top, k 1; board: 300 K under the board, 400 K on the block, k 1 in the
// board and 1000 in the block.
ThermalParams tetgen_params(const std::string& which, LinearSolverKind kind) {
  ThermalParams p;
  if (which == "box") {
    p.conductivity = {{1, 1.0}};
    p.fixed = {{1, 300}, {2, 400}};
  } else {
    p.conductivity = {{1, 1.0}, {2, 1000.0}};
    p.fixed = {{1, 300}, {6, 400}};
  }
  p.solver.kind = kind;
  p.solver.relative_tolerance = 1e-10;
  return p;
}

// kB of a "VmHWM:" / "VmRSS:" line of /proc/self/status (0 where there is none).
double proc_status_kb(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return std::atof(line.c_str() + std::strlen(key));
  return 0;
}

// Resets the process's peak resident size (VmHWM) to its current size (Linux >= 4.0).
void reset_peak_rss() { std::ofstream("/proc/self/clear_refs") << "5"; }

ThermalParams params(LinearSolverKind kind) {
  ThermalParams p;
  p.conductivity = {{1, 1.0}, {2, 10.0}};
  p.fixed = {{5, 300}};
  p.convection = {{6, 100, 300}};
  p.sources = {{2, 1000, true}};
  p.solver.kind = kind;
  p.solver.relative_tolerance = 1e-10;
  return p;
}

void measure_thermal(benchmark::State& state, Mesh& m, const ThermalParams& p) {
  ThermalReport r;
  double assembly = 0, solve = 0;
  // The fields of an earlier run are dropped so that every run allocates them anew.
  m.fields.clear();
  m.fields.shrink_to_fit();
  malloc_trim(0);  // hand freed heap back, so that the solve's own allocations show in the peak
  reset_peak_rss();
  const double rss_before = proc_status_kb("VmRSS:");
  const double cpu_before = bench::process_cpu_seconds();
  for (auto _ : state) {
    r = solve_thermal(m, p);
    assembly += r.assembly_seconds;
    solve += r.solve_seconds;
  }
  const double peak = proc_status_kb("VmHWM:");
  // CPU of all threads per run: on a busy machine a steadier figure than the wall time.
  state.counters["process_cpu_s"] =
      (bench::process_cpu_seconds() - cpu_before) / static_cast<double>(state.iterations());
  // Process peak while solving (mesh and benchmark included) and what the solve added to it.
  state.counters["peak_MB"] = peak / 1024;
  state.counters["solver_MB"] = (peak - rss_before) / 1024;
  const double it = static_cast<double>(state.iterations());
  state.counters["tets"] = static_cast<double>(m.tet_count());
  state.counters["unknowns"] = static_cast<double>(r.unknowns);
  state.counters["assembly_s"] = assembly / it;
  state.counters["solve_s"] = solve / it;
  state.counters["cg_iterations"] = static_cast<double>(r.iterations);
  state.counters["residual"] = r.relative_residual;
  state.counters["DOF_per_s"] = static_cast<double>(r.unknowns) / ((assembly + solve) / it);
  state.counters["Tmax"] = r.max_temperature;
}

void foxi_thermal(benchmark::State& state, LinearSolverKind kind, std::uint32_t n) {
  measure_thermal(state, grid(n), params(kind));
}

void tetgen_thermal(benchmark::State& state, LinearSolverKind kind, const char* which) {
  if (Mesh* m = tetgen_mesh(state, which)) measure_thermal(state, *m, tetgen_params(which, kind));
}

void tetgen_ccx(benchmark::State& state, const char* which) {
  Mesh* m = tetgen_mesh(state, which);
  if (!m) return;
  bench::time_ccx(
      state, "heat",
      [&](const std::filesystem::path& inp) {
        write_calculix_thermal(*m, tetgen_params(which, LinearSolverKind::automatic), inp);
      },
      std::getenv("FOXI_BENCH_CCX") != nullptr,
      "set FOXI_BENCH_CCX=1 (and install calculix-ccx) to time ccx");
  state.counters["tets"] = static_cast<double>(m->tet_count());
}

// The textbook baseline: element matrices into one serial triplet list, Dirichlet rows eliminated,
// Robin faces added, Eigen's setFromTriplets. Returns the free-free matrix and right-hand side.
struct System {
  Eigen::SparseMatrix<double> a;
  Eigen::VectorXd b;
};

System triplet_system(const Mesh& m) {
  const std::size_t nn = m.node_count();
  std::vector<int> dof(nn, 0);
  std::vector<double> fixed_t(nn, 0);
  for (std::size_t f = 0; f < m.bface_count(); ++f)
    if (m.bface_tag[f] == 5)
      for (int i = 0; i < 3; ++i) dof[m.bface[3 * f + i]] = -1, fixed_t[m.bface[3 * f + i]] = 300;
  int free = 0;
  for (auto& d : dof) d = d < 0 ? -1 : free++;
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(16 * m.tet_count());
  Eigen::VectorXd b = Eigen::VectorXd::Zero(free);
  double upper_volume = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const std::uint32_t* v = &m.tet[4 * t];
    Eigen::Matrix4d x;
    for (int a = 0; a < 4; ++a) x.row(a) << 1, m.xyz[3 * v[a]], m.xyz[3 * v[a] + 1], m.xyz[3 * v[a] + 2];
    const double vol = x.determinant() / 6;
    if (m.region_of(t) == 2) upper_volume += vol;
  }
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const std::uint32_t* v = &m.tet[4 * t];
    Eigen::Matrix4d x;
    for (int a = 0; a < 4; ++a) x.row(a) << 1, m.xyz[3 * v[a]], m.xyz[3 * v[a] + 1], m.xyz[3 * v[a] + 2];
    const Eigen::Matrix4d inv = x.inverse();
    const double vol = x.determinant() / 6, k = m.region_of(t) == 2 ? 10.0 : 1.0;
    const Eigen::Matrix<double, 3, 4> g = inv.bottomRows<3>();
    const Eigen::Matrix4d ke = k * vol * g.transpose() * g;
    for (int a = 0; a < 4; ++a) {
      if (dof[v[a]] < 0) continue;
      if (m.region_of(t) == 2) b[dof[v[a]]] += 1000 / upper_volume * vol / 4;
      for (int c = 0; c < 4; ++c) {
        if (dof[v[c]] >= 0)
          trip.emplace_back(dof[v[a]], dof[v[c]], ke(a, c));
        else
          b[dof[v[a]]] -= ke(a, c) * fixed_t[v[c]];
      }
    }
  }
  for (std::size_t f = 0; f < m.bface_count(); ++f) {
    if (m.bface_tag[f] != 6) continue;
    const std::uint32_t* v = &m.bface[3 * f];
    Eigen::Vector3d p[3];
    for (int i = 0; i < 3; ++i)
      p[i] = Eigen::Vector3d(m.xyz[3 * v[i]], m.xyz[3 * v[i] + 1], m.xyz[3 * v[i] + 2]);
    const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    for (int i = 0; i < 3; ++i) {
      b[dof[v[i]]] += 100 * 300 * area / 3;
      for (int j = 0; j < 3; ++j) trip.emplace_back(dof[v[i]], dof[v[j]], 100 * area / 12 * (i == j ? 2 : 1));
    }
  }
  System s;
  s.a.resize(free, free);
  s.a.setFromTriplets(trip.begin(), trip.end());
  s.b = std::move(b);
  return s;
}

void triplet_assembly(benchmark::State& state) {
  Mesh& m = grid(57);
  for (auto _ : state) {
    System s = triplet_system(m);
    benchmark::DoNotOptimize(s.a.valuePtr());
  }
  state.counters["tets"] = static_cast<double>(m.tet_count());
}

void eigen_cg_jacobi(benchmark::State& state) {
  Mesh& m = grid(57);
  const System s = triplet_system(m);
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
  cg.setTolerance(1e-10);
  cg.setMaxIterations(100000);
  Eigen::VectorXd x;
  for (auto _ : state) {
    cg.compute(s.a);
    x = cg.solve(s.b);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["unknowns"] = static_cast<double>(s.b.size());
  state.counters["cg_iterations"] = static_cast<double>(cg.iterations());
  state.counters["residual"] = cg.error();
  state.counters["Tmax"] = x.maxCoeff();
}

void ccx_1M(benchmark::State& state) {
  Mesh& m = grid(57);
  bench::time_ccx(
      state, "heat",
      [&](const std::filesystem::path& inp) {
        write_calculix_thermal(m, params(LinearSolverKind::automatic), inp);
      },
      std::getenv("FOXI_BENCH_CCX") != nullptr,
      "set FOXI_BENCH_CCX=1 (and install calculix-ccx) to time ccx");
  state.counters["tets"] = static_cast<double>(m.tet_count());
}

BENCHMARK_CAPTURE(foxi_thermal, amg_6M, LinearSolverKind::cg_amg, 100u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);
BENCHMARK(ccx_1M)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(foxi_thermal, amg_1M, LinearSolverKind::cg_amg, 57u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);
BENCHMARK_CAPTURE(foxi_thermal, ichol_1M, LinearSolverKind::cg_ichol, 57u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);
BENCHMARK_CAPTURE(foxi_thermal, amg_162k, LinearSolverKind::cg_amg, 30u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(foxi_thermal, direct_162k, LinearSolverKind::direct, 30u)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// TetGen meshes (issue 18): AMG against incomplete Cholesky and CalculiX on the same mesh and problem.
BENCHMARK_CAPTURE(tetgen_ccx, box_948k, "box")->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(tetgen_thermal, amg_box_948k, LinearSolverKind::cg_amg, "box")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);
BENCHMARK_CAPTURE(tetgen_thermal, ichol_box_948k, LinearSolverKind::cg_ichol, "box")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);
BENCHMARK_CAPTURE(tetgen_ccx, board_1M, "board")
    ->UseManualTime()
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(tetgen_thermal, amg_board_1M, LinearSolverKind::cg_amg, "board")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);
BENCHMARK_CAPTURE(tetgen_thermal, ichol_board_1M, LinearSolverKind::cg_ichol, "board")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);
BENCHMARK(triplet_assembly)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(eigen_cg_jacobi)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
