// Isosurfaces (issue 17 item 3): a new isovalue for a new view at 1920x1080 on TetGen's 0.97M-tet box
// with a smooth node field, pruned against the full pass in the same run.
//   iso_pruned/F     find the tets crossing the value(s) (TetIntervals::crossing_any), order only those
//                    (ProgressiveOrder's subset mode, visibility_order), draw their polygons (IsoPainter)
//   iso_full_scan/F  the same picture the brute-force way: scan all tets for the crossing ones
//                    (crossing_scan), order all tets and hand the whole order to IsoPainter (it skips
//                    the tets that cross nothing)
// F = 0, 1, 2: isovalue(s) crossing about 0.1%, 1% and 10% of the tets (one value for the first two,
// evenly spaced values for the third). Counters: crossing (tets crossed), query_ms / order_ms / draw_ms
// (the phases, wall clock, per iteration; clear_ms: clearing the 1920x1080 picture, counted in the
// time but not in the phases or the per-tet figures), ns_per_crossing_tet and ns_per_mesh_tet (the whole
// iteration over the tets crossed, and over all the mesh's tets), build_ms (the interval tree, once).
//   iso_draw/F       the draw phase alone, one view (process CPU time = the drawing thread's)
// iso_pruned also draws the full pass of each view outside its timing: full_ms (its query + order + clear
// + draw), ratio (pruned / full, wall clock, clearing included in both) and differ_px (pixels, colour
// or id, where the two pictures differ; 0 expected). Time columns: wall clock and process CPU time (all
// threads). The camera turns by 7 degrees per iteration, so no frame repeats.
// The outside anchor, VTK's vtkContourFilter on the same mesh, field and isovalues (a full pass that only
// makes the triangles: no order, no picture), is bench/peers/iso_vtk_contour.py, run beside this.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/isosurface.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"

namespace {

using namespace foxi;

constexpr int kWidth = 1920, kHeight = 1080;

struct Case {
  Mesh mesh;
  SphereTable table;
  Camera camera;
  std::vector<double> corner;
  TetIntervals tree;
  double build_ms = 0;
  std::vector<double> values[3];  // per crossing fraction
  std::size_t crossing[3] = {};
  double lo = 0, hi = 1;
};

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

Case& get_case() {
  static std::unique_ptr<Case> c;
  if (!c) {
    c = std::make_unique<Case>();
    c->mesh = bench::tetgen_box_mesh(2, 1, 1, 4e-6);
    c->table = compute_spheres(c->mesh);
    double lo[3], hi[3];
    mesh_bounds(c->mesh, lo, hi);
    const double dir[3] = {-1.0, 1.6, -0.9}, up[3] = {0, 0, 1};
    c->camera = fit_camera(lo, hi, dir, up, true, 30, double(kWidth) / kHeight, 0.95);
    // The smooth field of bench_render (a product of sines plus a ramp).
    std::vector<double> nodal(c->mesh.node_count());
    for (std::size_t n = 0; n < nodal.size(); ++n) {
      const double* p = &c->mesh.xyz[3 * n];
      nodal[n] = std::sin(3 * p[0]) * std::cos(4 * p[1]) + p[2];
    }
    c->lo = *std::min_element(nodal.begin(), nodal.end());
    c->hi = *std::max_element(nodal.begin(), nodal.end());
    c->corner.resize(c->mesh.tet.size());
    for (std::size_t i = 0; i < c->corner.size(); ++i) c->corner[i] = nodal[c->mesh.tet[i]];
    const auto t0 = std::chrono::steady_clock::now();
    c->tree = TetIntervals(c->corner);
    c->build_ms = ms_since(t0);
    // Values: the one of 400 evenly spaced whose crossing count is nearest the target (0.1%, 1%);
    // for 10%, evenly spaced values, as many as it takes.
    const double n = double(c->mesh.tet_count());
    std::vector<std::uint32_t> hits;
    for (int f = 0; f < 2; ++f) {
      const double want = n * (f == 0 ? 0.001 : 0.01);
      double best = 1e300;
      for (int i = 1; i < 400; ++i) {
        const double v = c->lo + (c->hi - c->lo) * i / 400;
        hits.clear();
        c->tree.crossing(v, hits);
        if (std::abs(double(hits.size()) - want) < best) {
          best = std::abs(double(hits.size()) - want);
          c->values[f] = {v};
          c->crossing[f] = hits.size();
        }
      }
    }
    for (int k = 2; k < 200; ++k) {
      std::vector<double> vs;
      for (int i = 0; i < k; ++i) vs.push_back(c->lo + (c->hi - c->lo) * (i + 0.5) / k);
      hits.clear();
      c->tree.crossing_any(vs, hits);
      c->values[2] = vs;
      c->crossing[2] = hits.size();
      if (double(hits.size()) >= 0.1 * n) break;
    }
  }
  return *c;
}

struct Phases {
  double query_ms = 0, order_ms = 0, clear_ms = 0, draw_ms = 0;
  std::size_t polygons = 0;
  double total() const { return query_ms + order_ms + clear_ms + draw_ms; }
};

// One frame of the isovalues `ip` for `cam` into fb, pruned or the full pass; adds its phases' times.
void frame(Case& c, const IsoParams& ip, const Camera& cam, bool pruned, Framebuffer& fb,
           std::vector<std::uint32_t>& subset, std::vector<std::uint32_t>& order, Phases& ph) {
  auto t0 = std::chrono::steady_clock::now();
  subset.clear();
  if (pruned) {
    c.tree.crossing_any(ip.values, subset);
  } else {
    for (double v : ip.values) {
      const std::vector<std::uint32_t> s = crossing_scan(c.corner, v);
      subset.insert(subset.end(), s.begin(), s.end());
    }
  }
  ph.query_ms += ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  if (pruned) {
    visibility_order_into(order, c.mesh, c.table, view_of(cam), subset);
  } else {
    visibility_order_into(order, c.mesh, c.table, view_of(cam));
  }
  ph.order_ms += ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  fb.clear();
  ph.clear_ms += ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  IsoPainter painter(c.mesh, cam, kWidth, kHeight, c.corner, ip);
  painter.draw(fb, order);
  ph.polygons = painter.polygons_drawn();
  benchmark::DoNotOptimize(fb.rgba.data());
  ph.draw_ms += ms_since(t0);
}

// The pruned frame timed; with `baseline`, each iteration also draws the full pass of the same view
// outside the timing (full_ms, ratio = pruned / full wall clock, and differ_px: pixels, colour or id,
// in which the two pictures differ: 0).
void run(benchmark::State& state, bool pruned) {
  Case& c = get_case();
  const int f = int(state.range(0));
  IsoParams ip;
  ip.values = c.values[f];
  ip.scale.lo = c.lo;
  ip.scale.hi = c.hi;
  Framebuffer fb(kWidth, kHeight), full(kWidth, kHeight);
  std::vector<std::uint32_t> subset, order, subset2, order2;
  Phases ph, base;
  std::size_t i = 0, differ = 0;
  for (auto _ : state) {
    const Camera cam = orbit(c.camera, 7.0 * double(i++), 0);
    frame(c, ip, cam, pruned, fb, subset, order, ph);
    if (pruned) {
      state.PauseTiming();
      frame(c, ip, cam, false, full, subset2, order2, base);
      for (std::size_t p = 0; p < fb.rgba.size(); ++p)
        differ += fb.rgba[p] != full.rgba[p] || fb.id[p] != full.id[p];
      state.ResumeTiming();
    }
  }
  const double iters = double(state.iterations());
  state.counters["values"] = double(ip.values.size());
  state.counters["crossing"] = double(c.crossing[f]);
  state.counters["polygons"] = double(ph.polygons);
  state.counters["query_ms"] = ph.query_ms / iters;
  state.counters["order_ms"] = ph.order_ms / iters;
  state.counters["draw_ms"] = ph.draw_ms / iters;
  state.counters["clear_ms"] = ph.clear_ms / iters;
  const double total_ns = (ph.query_ms + ph.order_ms + ph.draw_ms) * 1e6 / iters;
  state.counters["ns_per_crossing_tet"] = total_ns / double(c.crossing[f]);
  state.counters["ns_per_mesh_tet"] = total_ns / double(c.mesh.tet_count());
  state.counters["build_ms"] = c.build_ms;
  if (pruned) {
    state.counters["full_ms"] = base.total() / iters;
    state.counters["ratio"] = ph.total() / base.total();
    state.counters["differ_px"] = double(differ);
  }
  state.SetLabel(f == 0 ? "0.1%" : f == 1 ? "1%" : "10%");
}

// The draw phase alone (one view, its pruned order made once): IsoPainter setup + draw of the crossing
// tets' polygons, the picture cleared outside the timing; counters pixels (pixel writes per frame, from
// the undo record) and ns_per_polygon.
void BM_iso_draw(benchmark::State& state) {
  Case& c = get_case();
  const int f = int(state.range(0));
  IsoParams ip;
  ip.values = c.values[f];
  ip.scale.lo = c.lo;
  ip.scale.hi = c.hi;
  std::vector<std::uint32_t> subset;
  c.tree.crossing_any(ip.values, subset);
  const std::vector<std::uint32_t> order = visibility_order(c.mesh, c.table, view_of(c.camera), subset);
  Framebuffer fb(kWidth, kHeight);
  std::size_t polygons = 0;
  for (auto _ : state) {
    state.PauseTiming();
    fb.clear();
    state.ResumeTiming();
    IsoPainter painter(c.mesh, c.camera, kWidth, kHeight, c.corner, ip);
    painter.draw(fb, order);
    polygons = painter.polygons_drawn();
    benchmark::DoNotOptimize(fb.rgba.data());
  }
  RenderParams rp;
  rp.undoable = true;
  IsoPainter counting(c.mesh, c.camera, kWidth, kHeight, c.corner, ip, rp);
  fb.clear();
  counting.draw(fb, order);
  std::size_t covered = 0;
  for (std::uint32_t id : fb.id) covered += id != kNone;
  state.counters["polygons"] = double(polygons);
  state.counters["covered_px"] = double(covered);
  state.counters["ns_per_polygon"] = benchmark::Counter(
      double(polygons), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetLabel(f == 0 ? "0.1%" : f == 1 ? "1%" : "10%");
}

void BM_iso_pruned(benchmark::State& state) { run(state, true); }
void BM_iso_full_scan(benchmark::State& state) { run(state, false); }

}  // namespace

BENCHMARK(BM_iso_draw)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_iso_pruned)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_iso_full_scan)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

BENCHMARK_MAIN();
