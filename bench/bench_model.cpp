// Derived data on ~1M-tet meshes: face adjacency and the Delaunay certificate, each with a baseline
// in the same run.
//   adjacency   vs  std::sort of 128-bit face keys (three sorted vertices + face id), then pairing
//   certificate vs  the face-local test: for each interior face, the opposite vertex against the
//                   tet's circumsphere (CGAL's filtered exact predicate; one thread). It is cheaper
//                   but proves nothing for non-convex or disconnected meshes.
// Meshes: kuhn_grid_mesh(57) (1.1M tets, jittered grid, not Delaunay) and a TetGen mesh of a 2x1x1
// box (`tetgen -pq1.414a4e-6O0`, 0.97M tets, Delaunay), made in a temp folder in the run.
// Run once: each benchmark is one iteration; times are wall-clock; ratios printed at the end.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/model/adjacency.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/io_tetgen.hpp"

namespace {

using foxi::Mesh;

Mesh& kuhn_mesh() {
  static Mesh m = foxi::bench::kuhn_grid_mesh(57);
  return m;
}

// Null when tetgen is missing or fails. The TetGen files live in a temp folder removed afterwards.
Mesh* tetgen_mesh() {
  static std::unique_ptr<Mesh> m = [] {
    namespace fs = std::filesystem;
    std::unique_ptr<Mesh> out;
    const fs::path dir = fs::temp_directory_path() / ("foxi-bench-" + std::to_string(std::random_device{}()));
    fs::create_directories(dir);
    std::string poly = "8 3 0 0\n";
    for (int i = 0; i < 8; ++i)
      poly +=
          std::to_string(i + 1) + (i & 1 ? " 2" : " 0") + (i & 2 ? " 1" : " 0") + (i & 4 ? " 1\n" : " 0\n");
    poly += "6 0\n1\n4 1 3 7 5\n1\n4 2 4 8 6\n1\n4 1 2 6 5\n1\n4 3 4 8 7\n1\n4 1 2 4 3\n1\n4 5 6 8 7\n0\n0\n";
    {
      std::FILE* f = std::fopen((dir / "box.poly").c_str(), "w");
      if (f) {
        std::fputs(poly.c_str(), f);
        std::fclose(f);
      }
    }
    const std::string cmd =
        "tetgen -pq1.414a0.000004O0Q '" + (dir / "box.poly").string() + "' > /dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) out = std::make_unique<Mesh>(foxi::read_tetgen(dir / "box.1"));
    std::error_code ec;
    fs::remove_all(dir, ec);
    return out;
  }();
  return m.get();
}

Mesh* mesh_by_index(int i) { return i == 0 ? &kuhn_mesh() : tetgen_mesh(); }
const char* mesh_name(int i) { return i == 0 ? "kuhn57" : "tetgen_box"; }

std::map<std::string, double> g_ms, g_cpu;  // "what/mesh" -> wall / CPU milliseconds, for the ratios

// Process CPU time (all threads), ms: on a shared machine wall time includes waiting for a core, so
// cpu_ms / threads used is the better estimate of the wall time on an idle machine.
double process_cpu_ms() {
  rusage r{};
  getrusage(RUSAGE_SELF, &r);
  return static_cast<double>(r.ru_utime.tv_sec + r.ru_stime.tv_sec) * 1e3 +
         static_cast<double>(r.ru_utime.tv_usec + r.ru_stime.tv_usec) / 1e3;
}

double g_last_cpu_ms = 0;

template <class F>
double time_ms(F&& f) {
  const double c0 = process_cpu_ms();
  auto t0 = std::chrono::steady_clock::now();
  f();
  const double wall =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  g_last_cpu_ms = process_cpu_ms() - c0;
  return wall;
}

void report(benchmark::State& state, const std::string& what, const Mesh& m, double ms) {
  state.SetIterationTime(ms / 1000);
  state.counters["ms"] = ms;
  state.counters["cpu_ms"] = g_last_cpu_ms;
  state.counters["ns_per_tet"] = ms * 1e6 / static_cast<double>(m.tet_count());
  state.counters["tets"] = static_cast<double>(m.tet_count());
  g_ms[what + "/" + mesh_name(static_cast<int>(state.range(0)))] = ms;
  g_cpu[what + "/" + mesh_name(static_cast<int>(state.range(0)))] = g_last_cpu_ms;
}

void BM_Adjacency(benchmark::State& state) {
  Mesh* m = mesh_by_index(static_cast<int>(state.range(0)));
  if (!m) return state.SkipWithError("tetgen not available");
  for (auto _ : state) {
    foxi::FaceAdjacency a;
    const double ms = time_ms([&] { a = foxi::compute_face_adjacency(*m); });
    benchmark::DoNotOptimize(a.neighbour.data());
    report(state, "adjacency", *m, ms);
    state.counters["interior_faces"] = static_cast<double>(a.interior_faces);
  }
}

__extension__ typedef unsigned __int128 u128;

// Baseline: one 128-bit key per face (sorted vertices in the high 96 bits, face id in the low 32),
// std::sort, then equal neighbours paired.
void BM_AdjacencySortBaseline(benchmark::State& state) {
  Mesh* m = mesh_by_index(static_cast<int>(state.range(0)));
  if (!m) return state.SkipWithError("tetgen not available");
  for (auto _ : state) {
    std::vector<std::uint32_t> nb;
    std::size_t interior = 0;
    const double ms = time_ms([&] {
      const std::size_t n = m->tet_count();
      std::vector<u128> keys(4 * n);
      for (std::size_t t = 0; t < n; ++t)
        for (std::uint32_t f = 0; f < 4; ++f) {
          std::uint32_t v[3], k = 0;
          for (std::uint32_t j = 0; j < 4; ++j)
            if (j != f) v[k++] = m->tet[4 * t + j];
          std::sort(v, v + 3);
          keys[4 * t + f] = (u128(v[0]) << 96) | (u128(v[1]) << 64) | (u128(v[2]) << 32) | (4 * t + f);
        }
      std::sort(keys.begin(), keys.end());
      nb.assign(4 * n, foxi::kNone);
      for (std::size_t i = 0; i + 1 < keys.size();) {
        if ((keys[i] >> 32) == (keys[i + 1] >> 32) &&
            (i + 2 >= keys.size() || (keys[i + 2] >> 32) != (keys[i] >> 32))) {
          const auto a = static_cast<std::uint32_t>(keys[i]), b = static_cast<std::uint32_t>(keys[i + 1]);
          nb[a] = b;
          nb[b] = a;
          ++interior;
          i += 2;
        } else {
          std::size_t j = i + 1;
          while (j < keys.size() && (keys[j] >> 32) == (keys[i] >> 32)) ++j;
          i = j;
        }
      }
    });
    benchmark::DoNotOptimize(nb.data());
    report(state, "adjacency_sort_baseline", *m, ms);
    state.counters["interior_faces"] = static_cast<double>(interior);
  }
}

void BM_Certificate(benchmark::State& state) {
  Mesh* m = mesh_by_index(static_cast<int>(state.range(0)));
  if (!m) return state.SkipWithError("tetgen not available");
  for (auto _ : state) {
    foxi::DelaunayCertificate c;
    const double ms = time_ms([&] { c = foxi::compute_delaunay_certificate(*m); });
    report(state, "certificate", *m, ms);
    state.counters["violating"] = static_cast<double>(c.violating_tet_count);
    state.counters["delaunay"] = c.delaunay;
  }
}

void BM_FaceLocalBaseline(benchmark::State& state) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using P = K::Point_3;
  Mesh* m = mesh_by_index(static_cast<int>(state.range(0)));
  if (!m) return state.SkipWithError("tetgen not available");
  const foxi::FaceAdjacency adj = foxi::compute_face_adjacency(*m);  // not timed
  for (auto _ : state) {
    std::vector<std::uint8_t> bad;
    const double ms = time_ms([&] {
      const std::size_t n = m->tet_count();
      bad.assign(n, 0);
      auto pt = [&](std::uint32_t v) { return P(m->xyz[3 * v], m->xyz[3 * v + 1], m->xyz[3 * v + 2]); };
      for (std::size_t t = 0; t < n; ++t) {
        const std::uint32_t* v = &m->tet[4 * t];
        const P a = pt(v[0]), b = pt(v[1]), c = pt(v[2]), d = pt(v[3]);
        for (std::uint32_t f = 0; f < 4; ++f) {
          const std::uint32_t u = adj.neighbour[4 * t + f];
          if (u == foxi::kNone || u / 4 < t) continue;  // each interior face once
          const std::uint32_t opp = m->tet[u];          // u = 4*tet + face: the vertex opposite that face
          if (CGAL::side_of_oriented_sphere(a, b, c, d, pt(opp)) == CGAL::ON_POSITIVE_SIDE) bad[t] = 1;
        }
      }
    });
    report(state, "face_local_baseline", *m, ms);
    state.counters["violating"] = static_cast<double>(std::count(bad.begin(), bad.end(), 1));
  }
}

BENCHMARK(BM_Adjacency)->Arg(0)->Arg(1)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AdjacencySortBaseline)
    ->Arg(0)
    ->Arg(1)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Certificate)->Arg(0)->Arg(1)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FaceLocalBaseline)
    ->Arg(0)
    ->Arg(1)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::printf("\nratios, one run (wall ms / process CPU ms; ours uses 2 threads, the baselines 1):\n");
  for (const char* mesh : {"kuhn57", "tetgen_box"}) {
    auto get = [&](const std::map<std::string, double>& t, const std::string& what) {
      auto it = t.find(what + "/" + mesh);
      return it == t.end() ? 0.0 : it->second;
    };
    const double a = get(g_ms, "adjacency"), ab = get(g_ms, "adjacency_sort_baseline");
    const double c = get(g_ms, "certificate"), cb = get(g_ms, "face_local_baseline");
    if (a > 0 && ab > 0)
      std::printf("  %-10s adjacency   %7.1f / %7.1f ms vs sort       %7.1f / %7.1f ms: wall %.2fx faster\n",
                  mesh, a, get(g_cpu, "adjacency"), ab, get(g_cpu, "adjacency_sort_baseline"), ab / a);
    if (c > 0 && cb > 0)
      std::printf(
          "  %-10s certificate %7.1f / %7.1f ms vs face-local %7.1f / %7.1f ms: wall %.2fx the cost\n", mesh,
          c, get(g_cpu, "certificate"), cb, get(g_cpu, "face_local_baseline"), c / cb);
  }
  return 0;
}
