// The per-view visibility order (issue 3), with its baselines in the same run.
//   power_order       whole back-to-front order, ties resolved (foxi::visibility_order)
//   power_order_into  the same into an output kept from view to view (foxi::visibility_order_into)
//   first_batch       time until the first batch of the progressive order is handed out (manual
//                     time: the order's destruction, which stops its worker, is left out)
//   precompute        spheres + cospherical clusters (face adjacency computed before, cached)
//   keys_only         computing the float keys alone: the bandwidth-bound floor
//   std_sort          std::sort of (float key, uint32 index) pairs (the naive order)
//   centroid_order    a centroid-depth sort (what VTK's vtkCellCenterDepthSort does)
// Meshes: TetGen's -O0 mesh of a 2x1x1 box at a4e-6 (0.97M tets, Delaunay) and a 55^3 cube grid
// split into 6 tets per cube (1.0M tets, one cospherical cluster per cube); with FOXI_BENCH_LARGE=1
// also the box at a1e-6 (~3.9M tets), with FOXI_BENCH_LARGE=2 the box at a4e-7 (~9.7M tets) too.
// Every iteration takes a new perspective eye point outside the mesh (a fixed sequence), so nothing
// is reused between views.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <random>

#include "bench_meshes.hpp"
#include "foxi/model/adjacency.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"

namespace {

using namespace foxi;

struct Case {
  Mesh mesh;
  SphereTable table;
};

Case& get_case(int which) {
  static std::unique_ptr<Case> cases[4];
  if (!cases[which]) {
    auto c = std::make_unique<Case>();
    if (which == 0) c->mesh = bench::tetgen_box_mesh(2, 1, 1, 4e-6);
    if (which == 1) c->mesh = bench::cube_grid_mesh(55);
    if (which == 2) c->mesh = bench::tetgen_box_mesh(2, 1, 1, 1e-6);
    if (which == 3) c->mesh = bench::tetgen_box_mesh(2, 1, 1, 4e-7);
    face_adjacency(c->mesh);
    c->table = compute_spheres(c->mesh);
    cases[which] = std::move(c);
  }
  return *cases[which];
}

const char* case_name(int which) {
  return which == 0 ? "box_972k" : which == 1 ? "grid_1M" : which == 2 ? "box_3.9M" : "box_9.7M";
}

View eye_for(std::size_t i) {
  std::mt19937 rng(static_cast<unsigned>(1000 + i));
  std::normal_distribution<double> g(0, 1);
  double d[3] = {g(rng), g(rng), g(rng)};
  double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  return View::at(1 + 3 * d[0] / len, 0.5 + 3 * d[1] / len, 0.5 + 3 * d[2] / len);
}

bool skip(benchmark::State& state, int which) {
  const char* large = std::getenv("FOXI_BENCH_LARGE");
  if (which >= 2 && (large == nullptr || std::atoi(large) < which - 1)) {
    state.SkipWithError("set FOXI_BENCH_LARGE=1 for the 3.9M-tet mesh, 2 for the 9.7M one too");
    return true;
  }
  return false;
}

void per_tet(benchmark::State& state, std::size_t tets) {
  state.counters["tets"] = double(tets);
  state.counters["ns_per_tet"] = benchmark::Counter(
      double(tets), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetLabel(case_name(static_cast<int>(state.range(0))));
}

void BM_power_order(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  if (skip(state, which)) return;
  Case& c = get_case(which);
  std::size_t i = 0, runs = 0;
  for (auto _ : state) {
    OrderStats stats;
    auto order = visibility_order(c.mesh, c.table, eye_for(i++), {}, false, &stats);
    runs += stats.near_tie_runs;
    benchmark::DoNotOptimize(order.data());
  }
  state.counters["near_tie_runs"] = double(runs) / double(std::max<std::size_t>(i, 1));
  per_tet(state, c.mesh.tet_count());
}

// The same with the output kept from view to view (a viewer's frame loop): no allocation per view.
void BM_power_order_into(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  if (skip(state, which)) return;
  Case& c = get_case(which);
  std::size_t i = 0, runs = 0;
  std::vector<std::uint32_t> order;
  double phase[3] = {0, 0, 0};
  const std::clock_t cpu0 = std::clock();
  for (auto _ : state) {
    OrderStats stats;
    visibility_order_into(order, c.mesh, c.table, eye_for(i++), {}, false, &stats);
    runs += stats.near_tie_runs;
    phase[0] += stats.keys_seconds;
    phase[1] += stats.scatter_seconds;
    phase[2] += stats.sort_seconds;
    benchmark::DoNotOptimize(order.data());
  }
  const double views = double(std::max<std::size_t>(i, 1));
  state.counters["near_tie_runs"] = double(runs) / views;
  // The breakdown (mean ms per view): keys + histogram, first-level scatter, bucket sorts + emit.
  state.counters["keys_ms"] = 1e3 * phase[0] / views;
  state.counters["scatter_ms"] = 1e3 * phase[1] / views;
  state.counters["sort_ms"] = 1e3 * phase[2] / views;
  // CPU time of the whole process (both cores) per view: steadier than wall time on a loaded machine.
  state.counters["cpu_ms"] = 1e3 * double(std::clock() - cpu0) / CLOCKS_PER_SEC / views;
  // The mesh's cospherical clusters, their tets, and whether they are split (SphereTable::clusters_split).
  state.counters["clusters"] = double(c.table.cluster_count());
  state.counters["cluster_tets"] = double(c.table.cluster_tets.size());
  state.counters["split"] = c.table.clusters_split ? 1 : 0;
  per_tet(state, c.mesh.tet_count());
}

void BM_first_batch(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  if (skip(state, which)) return;
  Case& c = get_case(which);
  std::size_t i = 0, first_tets = 0, first_keys = 0;
  for (auto _ : state) {
    // Timed from the view's start to the first batch in hand; stopping the sorting ahead when the
    // order is dropped (its destructor) is not part of the wait.
    const auto t0 = std::chrono::steady_clock::now();
    ProgressiveOrder order(c.mesh, c.table, eye_for(i++));
    auto batch = order.next();
    benchmark::DoNotOptimize(batch.data());
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    first_tets += batch.size();
    first_keys += order.stats().first_batch_keys;
  }
  // Tets in the first batch, and the keys computed before it (mean per view).
  state.counters["first_tets"] = double(first_tets) / double(std::max<std::size_t>(i, 1));
  state.counters["first_keys"] = double(first_keys) / double(std::max<std::size_t>(i, 1));
  state.SetLabel(case_name(which));
}

void BM_precompute(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  if (skip(state, which)) return;
  Case& c = get_case(which);
  for (auto _ : state) {
    SphereTable t = compute_spheres(c.mesh);
    benchmark::DoNotOptimize(t.s.data());
  }
  per_tet(state, c.mesh.tet_count());
}

void BM_keys_only(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  if (skip(state, which)) return;
  Case& c = get_case(which);
  const std::size_t n = c.mesh.tet_count();
  std::vector<float> keys(n);
  std::size_t i = 0;
  for (auto _ : state) {
    View v = eye_for(i++);
    double p[3] = {2 * (v.eye[0] - c.table.origin[0]), 2 * (v.eye[1] - c.table.origin[1]),
                   2 * (v.eye[2] - c.table.origin[2])};
    const double* C = c.table.c.data();
    const double* S = c.table.s.data();
    for (std::size_t t = 0; t < n; ++t)
      keys[t] = static_cast<float>(S[t] - (C[3 * t] * p[0] + C[3 * t + 1] * p[1] + C[3 * t + 2] * p[2]));
    benchmark::DoNotOptimize(keys.data());
  }
  per_tet(state, n);
}

void BM_std_sort(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  if (skip(state, which)) return;
  Case& c = get_case(which);
  const std::size_t n = c.mesh.tet_count();
  std::vector<std::pair<float, std::uint32_t>> pairs(n);
  std::size_t i = 0;
  for (auto _ : state) {
    View v = eye_for(i++);
    double p[3] = {2 * (v.eye[0] - c.table.origin[0]), 2 * (v.eye[1] - c.table.origin[1]),
                   2 * (v.eye[2] - c.table.origin[2])};
    const double* C = c.table.c.data();
    const double* S = c.table.s.data();
    for (std::size_t t = 0; t < n; ++t)
      pairs[t] = {static_cast<float>(S[t] - (C[3 * t] * p[0] + C[3 * t + 1] * p[1] + C[3 * t + 2] * p[2])),
                  static_cast<std::uint32_t>(t)};
    std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    benchmark::DoNotOptimize(pairs.data());
  }
  per_tet(state, n);
}

void BM_centroid_order(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  if (skip(state, which)) return;
  Case& c = get_case(which);
  std::size_t i = 0;
  for (auto _ : state) {
    auto order = centroid_order(c.mesh, eye_for(i++));
    benchmark::DoNotOptimize(order.data());
  }
  per_tet(state, c.mesh.tet_count());
}

}  // namespace

BENCHMARK(BM_power_order)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_power_order_into)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_first_batch)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseManualTime();
BENCHMARK(BM_keys_only)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_std_sort)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_centroid_order)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);
BENCHMARK(BM_precompute)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

BENCHMARK_MAIN();
