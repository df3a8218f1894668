// Translucent regions (issue 23 item 1) against the opaque frame, in the same run: TetGen's 0.97M-tet
// box at 1920x1080, a new view per iteration (the camera turns by 7 degrees), wall clock per frame.
//   opaque_frame          the whole mesh ordered (visibility_order_into) and drawn by the tet painter
//                         (TetRasterizer, front faces, no blending): the picture foxi render draws
//   translucent_frame/S   the tets owning a face to draw ordered (visibility_order_into of
//                         TranslucentSurfaces::tets) and composited by TranslucentPainter, the picture
//                         resolved to 8 bits; the surfaces themselves (view-independent) are found once
//                         per mesh, outside the timing (surfaces_ms)
//   volume_frame          the whole mesh ordered and volume-rendered (VolumePainter: a smooth node field,
//                         the integral along every pixel's ray through every tet), counters order_ms,
//                         draw_ms, draw_cpu_ms (the painter's CPU time, all threads: what a loaded
//                         machine does not inflate much), ns_per_segment (draw_cpu_ms per segment),
//                         segments (pixel-tet segments integrated), pre_integrated (of those, the ones
//                         in closed form), opaque_ms and ratio. The outside anchor, VTK's projected
//                         tetrahedra on the same mesh and view: bench/peers/volume_vtk.py.
//                         FOXI_BENCH_BOX_VOLUME=4e-5 (a maximum tet volume): a smaller box, to profile.
//                         FOXI_BENCH_VOLUME_REPEAT=N: each frame drawn N times more (outside the timing),
//                         counters least_cpu_ms and least_ns_per_segment the least CPU time of a frame
//                         (a shared machine's load inflates even the CPU time by 10 to 20%, the least of
//                         a few draws much less: what A/B comparisons of the painter should use).
// Figures (2-core Xeon with AVX-512, shared: load 9 to 12 from other builds; 2026-11-27, "before":
// the code at the start of that day's vol4 changes, run alternately with "after" from copies of both
// binaries). 0.97M tets: after 2.4 to 2.9 s of CPU a frame (29 to 35 ns a segment, 82.6M segments),
// before 2.7 to 3.0 s (33 to 36 ns); wall 4.2 to 7.5 s a frame (order 37 to 106 ms). VTK's projected
// tetrahedra (volume_vtk.py, Mesa llvmpipe under Xvfb, 3 frames) in the same sitting: 15.7, 20.4,
// 36.5 s a frame (an earlier sitting under more load: 38.5, 40.7, 46.6 s against foxi's 8.3 to 8.8 s):
// foxi 3 to 5 times faster in wall time, not the 10. FOXI_BENCH_BOX_VOLUME=4e-5 (0.1M tets,
// 40M segments), 4 repetitions twice: after 20.7 to 23.5 ns a segment, before 22.9 to 29.3 ns. Far
// from the 150 ms (about 0.3 s of CPU on 2 cores, 3.6 ns a segment). Where the painter's
// time goes (perf, after): 57% the pixel kernel (volume_avx512.cpp; its hottest spots wait on the
// division of the optical depth and on the first load of the pixels), 19% listing the pixels
// (raster_triangle; 24% before), 10% the per-tet set-up, 9% fetching the tets (tile loop), 3% binning.
// Later that day (vol5, same machine, load 3 to 7, least of 3 to 5 draws a frame, the painter
// unchanged): 0.97M tets 2.37 to 2.71 s of CPU a frame (28.7 to 32.8 ns a segment), wall 3.6 to 5.2 s;
// 0.1M tets 18.0 to 20.4 ns a segment. Of the painter's time at 0.97M (perf): 63% the kernel, 17%
// listing the pixels, 10% the set-up (llround 1%), 8% the tile loop, 2% binning. A group of 8 lanes
// runs some 400 to 500 instructions (counted from the code: 6 divisions and a square root, 16 row
// loads and about 60 shuffles for the table, 8 loads and inserts and 8 branchy stores for the
// pixels); 7.6 of 8 lanes live on average;
// no segment takes the scalar composite() at 0.97M (416 of 78M at 0.1M); 12.7% are "thin" (under 2
// grid cells: the gathers of the midpoint path, in 2/3 of the groups). Tried, each measured against
// this code alternately and none faster beyond the noise (so not kept): 4 plane divisions -> 1 by
// cross-multiplication and the pre-integration's 2 -> 1 (slower: 18.7 to 20.5 against 18.0 to 18.6
// ns, 0.1M); two groups of 8 interleaved (0.1M 16.4 to 19.6 against 19.1 to 20.1 ns, 0.97M 32.7 to
// 33.2 against 28.7 to 32.8); thin segments from the table's cell (no gathers; 0.97M 29.7 to 32.9
// against 29.9 to 31.2); tiles of 64x64 and 64x32 pixels; a pre-integration table 4 times smaller
// (kG 2048, 64 KiB: 19.6 to 24.8 against 19.8 to 24.3 ns, 0.1M; the table's misses are not it).
// The kernel is bound by its instruction count, not by one unit: the 3.6 ns needs its
// redesign (rows evaluated directly, 16 float lanes, the pixels of a row contiguous), not trims.
// The redesign (vol6, same day, viz/src/volume_avx512.cpp): no rasterizer on the AVX-512 path (per
// row the span of pixel centres in the corners' projection, eight rows at a time), the runs packed
// into groups of 16 float lanes, reciprocals in place of divisions, the table in float, the picture in
// one plane per channel. Steps, each against the one before alternately (0.97M, least of 3, load 3 to
// 5): packed float lanes 21.0 against 26.7 ns (a lane group per row instead: 8 of 16 lanes live at
// 0.1M, 19.7 against 21.8); the spans in place of raster_triangle 19.5-20.2 against 29.8-30.7; the
// spans vectorized (their scalar ceil and floor were SSE2 emulations) 14.5-16.0 against 17.2; the
// lane group inlined (GCC had made it a call) 13.0-14.0 against 15.0-15.4. Final, alternately with
// the code before it (load 4.8 to 5.0): 0.97M 15.7 to 20.9 ns a segment (1.30 to 1.72 s CPU a frame)
// against 31.8 to 35.8 (2.63 to 2.96 s), 1.7 to 2.1 times; 0.1M 9.6 to 10.3 against 20.5 to 21.6.
// Profile after (0.97M): about 55% the spans and lane groups, 10% the per-tet set-up, 7% the tile
// loop. Still about 5 times the 3.6 ns. VTK (volume_vtk.py, 3 frames) right before: 11.8,
// 13.2, 14.8 s a frame against 1.76 s (after) and 3.16 s (before) wall a frame: 6.7 to 8.4 times VTK.
// After the spans were made half-open (the fill rule; a correctness fix), load 3.8 to 4.5: 20.0 and
// 21.4 ns a segment against 32.7 and 36.2 before the redesign, alternately.
// Where the one-call frame's CPU goes (2026-11-27, 0.97M, quiet; the painter cut short by a switch
// at each stage, least of 3): about 170 ms the fixed costs (painter, binning, tile loop, resolve),
// 290 ms the per-tet set-up (draw_tet, double), 240 ms the rows' spans and RowSetup, 1160 ms the lane
// groups, of about 1860 ms. Tried that day and no faster beyond the noise (so not kept): the
// pre-integration grid 4 times coarser (kG 2048: 32 KiB in float, in L1), a fixed 3, 4 or 6 pieces a
// lane group (masked loads and stores with no data-dependent loop).
// 2026-11-28: the lane groups pipelined (a group's first half, then the second half of the group
// before it), tiles cleared when first drawn, the tile loop's fetches 16 and 8 tets ahead. Measured
// with the painter's CPU per frame alternated frame by frame in one process between two variants
// (a temporary switch; separate runs do not resolve changes under 10% on this machine): pipelining
// 1233 against 1351 ms and 1167 against 1284 (least of 10), tiles cleared when drawn 1 to 3% of the
// wall, the fetches further ahead about 3% (32 and 16 no better). Tried and not kept: the colour
// planes loaded at a group's start (no faster), the table rows prefetched in the first half (10%
// slower), the two halves pipelined across tets (within the noise), gathers for the table rows in
// place of loads and transposes (no faster), |d| by rsqrt14 (2% at best, not kept). Later that day:
// tiles of 256 x 128 pixels (were 128 x 64; about 10% of the wall, 256 x 256 no better). At the end,
// alternately with the code from before that day's changes: 14.6 to 16.6 ns a segment against 17.2 to
// 20.2 (least of 3 draws), frame 0.65 to 0.78 s against 0.75 to 0.94 s wall; VTK 4.9 to 6.3 s a
// frame (medians 5.1, 5.7, 5.4 s) in the same sitting: 6.6 to 8.7 times.
//   volume_view_frame     the same frames in an InteractiveView, as foxi-view and the workbench draw them
//                         (steps of 40 ms, the picture asked for after each), against the one-call
//                         frame of the same views in the same iterations: one_call_ms, ratio, shown
//                         (pictures shown a frame). Quiet machine, 2026-11-27: before the view resolved
//                         lazily 3.7 to 5.0 s a frame (ratio 4.4 to 5.7), after 1.28 to 1.57 s (1.4 to
//                         1.6). The one-call frame the same day, quiet: 0.86 to 1.05 s wall (18.9 to
//                         24.6 ns a segment); VTK (volume_vtk.py, 3 frames, quiet) 6.0, 6.2, 7.2 s.
// S = 0: a package: the box translucent (0.3), an opaque block inside and 8 balls at 0.8 (their
//        surfaces, the box's boundary); S = 1: ten slabs along x with ten opacities (nine jagged
//        interfaces through the mesh). Counters: surface_tets, fragments, order_ms, draw_ms (blend +
//        resolve), and on translucent_frame opaque_ms (the opaque frame of the same views, timed in the
//        same iterations) and ratio (translucent / opaque).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <ctime>
#include <memory>

#include "bench_meshes.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/interactive_view.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/translucent.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "foxi/viz/volume.hpp"

namespace {

using namespace foxi;

constexpr int kWidth = 1920, kHeight = 1080;

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The process's CPU time (all threads), ms: on a shared machine the wall clock counts the other
// users' time too, the CPU time only ours.
double cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

struct Case {
  Mesh mesh[2];
  SphereTable table;
  Camera camera;
  TranslucentParams params[2];
  TranslucentSurfaces surfaces[2];
  double surfaces_ms[2] = {};
  std::vector<double> corner;  // the smooth field of bench_render, 4 per tet
  VolumeParams volume;
};

Case& get_case() {
  static std::unique_ptr<Case> c;
  if (c) return *c;
  c = std::make_unique<Case>();
  // FOXI_BENCH_BOX_VOLUME: another maximum tet volume (a smaller mesh, for profiling).
  const char* env = std::getenv("FOXI_BENCH_BOX_VOLUME");
  Mesh box = bench::tetgen_box_mesh(2, 1, 1, env ? std::atof(env) : 4e-6);
  c->table = compute_spheres(box);
  double lo[3], hi[3];
  mesh_bounds(box, lo, hi);
  const double dir[3] = {-1.0, 1.6, -0.9}, up[3] = {0, 0, 1};
  c->camera = fit_camera(lo, hi, dir, up, true, 30, double(kWidth) / kHeight, 0.95);
  const std::size_t n = box.tet_count();
  {
    std::vector<double> nodal(box.node_count());
    for (std::size_t k = 0; k < nodal.size(); ++k) {
      const double* p = &box.xyz[3 * k];
      nodal[k] = std::sin(3 * p[0]) * std::cos(4 * p[1]) + p[2];
    }
    c->corner.resize(box.tet.size());
    for (std::size_t i = 0; i < c->corner.size(); ++i) c->corner[i] = nodal[box.tet[i]];
    c->volume.scale.lo = -1;
    c->volume.scale.hi = 2;
    c->volume.opacity_curve = {{-1, 0.02}, {0.5, 0.1}, {2, 0.6}};
    c->volume.unit_length = 0.25;
  }
  for (int s = 0; s < 2; ++s) {
    c->mesh[s] = box;
    Mesh& m = c->mesh[s];
    m.tet_region.assign(n, 1);
    for (std::size_t t = 0; t < n; ++t) {
      double x[3] = {0, 0, 0};
      for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 3; ++j)
          x[j] += 0.25 * m.xyz[3 * std::size_t(m.tet[4 * t + std::size_t(k)]) + std::size_t(j)];
      if (s == 0) {
        if (std::abs(x[0] - 1) < 0.35 && std::abs(x[1] - 0.5) < 0.25 && std::abs(x[2] - 0.5) < 0.08)
          m.tet_region[t] = 2;
        for (int b = 0; b < 8; ++b) {
          const double bx = 0.3 + 0.2 * b, by = b % 2 ? 0.2 : 0.8, bz = 0.25;
          if ((x[0] - bx) * (x[0] - bx) + (x[1] - by) * (x[1] - by) + (x[2] - bz) * (x[2] - bz) < 0.01)
            m.tet_region[t] = 3;
        }
      } else {
        m.tet_region[t] = 1 + std::min(9, int(x[0] * 5));
      }
    }
    TranslucentParams& p = c->params[s];
    if (s == 0) {
      p.region_opacity = {{1, 0.3}, {2, 1.0}, {3, 0.8}};
    } else {
      for (int r = 1; r <= 10; ++r) p.region_opacity.push_back({r, 0.05 + 0.09 * r});
    }
    const auto t0 = std::chrono::steady_clock::now();
    c->surfaces[s] = translucent_surfaces(m, {}, p);
    c->surfaces_ms[s] = ms_since(t0);
  }
  return *c;
}

struct Timing {
  double order_ms = 0, draw_ms = 0;
  double total() const { return order_ms + draw_ms; }
};

void opaque_frame(Case& c, const Camera& cam, Framebuffer& fb, std::vector<std::uint32_t>& order, Timing& t) {
  auto t0 = std::chrono::steady_clock::now();
  visibility_order_into(order, c.mesh[0], c.table, view_of(cam));
  t.order_ms += ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  fb.clear();
  TetRasterizer raster(c.mesh[0], cam, kWidth, kHeight);
  raster.draw(fb, order);
  t.draw_ms += ms_since(t0);
}

std::size_t translucent_frame(Case& c, int s, const Camera& cam, Framebuffer& fb,
                              std::vector<std::uint32_t>& order, Timing& t) {
  auto t0 = std::chrono::steady_clock::now();
  visibility_order_into(order, c.mesh[s], c.table, view_of(cam), c.surfaces[s].tets);
  t.order_ms += ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  TranslucentPainter painter(c.mesh[s], cam, kWidth, kHeight, c.surfaces[s], c.params[s]);
  painter.draw(order);
  painter.resolve(fb);
  t.draw_ms += ms_since(t0);
  return painter.fragment_count();
}

void BM_opaque_frame(benchmark::State& state) {
  Case& c = get_case();
  Framebuffer fb(kWidth, kHeight);
  std::vector<std::uint32_t> order;
  Timing t;
  int i = 0;
  for (auto _ : state) opaque_frame(c, orbit(c.camera, 7.0 * i++, 0), fb, order, t);
  const double iters = double(state.iterations());
  state.counters["order_ms"] = t.order_ms / iters;
  state.counters["draw_ms"] = t.draw_ms / iters;
  state.counters["tets"] = double(c.mesh[0].tet_count());
}

void BM_translucent_frame(benchmark::State& state) {
  Case& c = get_case();
  const int s = int(state.range(0));
  Framebuffer fb(kWidth, kHeight), opaque(kWidth, kHeight);
  std::vector<std::uint32_t> order;
  Timing t, base;
  std::size_t fragments = 0;
  int i = 0;
  for (auto _ : state) {
    const Camera cam = orbit(c.camera, 7.0 * i++, 0);
    fragments += translucent_frame(c, s, cam, fb, order, t);
    state.PauseTiming();
    opaque_frame(c, cam, opaque, order, base);
    state.ResumeTiming();
  }
  const double iters = double(state.iterations());
  state.counters["surface_tets"] = double(c.surfaces[s].tets.size());
  state.counters["surfaces_ms"] = c.surfaces_ms[s];
  state.counters["fragments"] = double(fragments) / iters;
  state.counters["order_ms"] = t.order_ms / iters;
  state.counters["draw_ms"] = t.draw_ms / iters;
  state.counters["opaque_ms"] = base.total() / iters;
  state.counters["ratio"] = t.total() / base.total();
  state.SetLabel(s == 0 ? "package" : "10 slabs");
}

void BM_volume_frame(benchmark::State& state) {
  Case& c = get_case();
  Framebuffer fb(kWidth, kHeight), opaque(kWidth, kHeight);
  std::vector<std::uint32_t> order;
  Timing t, base;
  std::size_t segments = 0, pre_integrated = 0;
  double draw_cpu_ms = 0, least_cpu_ms = 0, least_segments = 0;
  // FOXI_BENCH_VOLUME_REPEAT: each frame drawn that many times, for the least CPU time.
  const char* repeat_env = std::getenv("FOXI_BENCH_VOLUME_REPEAT");
  const int repeat = std::max(1, repeat_env ? std::atoi(repeat_env) : 1);
  int i = 0;
  for (auto _ : state) {
    const Camera cam = orbit(c.camera, 7.0 * i++, 0);
    auto t0 = std::chrono::steady_clock::now();
    visibility_order_into(order, c.mesh[0], c.table, view_of(cam));
    t.order_ms += ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    double cpu0 = cpu_ms();
    VolumePainter painter(c.mesh[0], cam, kWidth, kHeight, c.corner, c.volume);
    painter.draw(order);
    painter.resolve(fb);
    double cpu = cpu_ms() - cpu0;
    draw_cpu_ms += cpu;
    segments += painter.samples();
    pre_integrated += painter.pre_integrated();
    t.draw_ms += ms_since(t0);
    // The same frame drawn again `repeat` times, outside the timing: the least CPU time of a frame
    // (what a shared machine's load inflates least).
    double least = cpu;
    state.PauseTiming();
    for (int k = 1; k < repeat; ++k) {
      cpu0 = cpu_ms();
      VolumePainter again(c.mesh[0], cam, kWidth, kHeight, c.corner, c.volume);
      again.draw(order);
      again.resolve(fb);
      least = std::min(least, cpu_ms() - cpu0);
    }
    least_cpu_ms += least;
    least_segments += double(painter.samples());
    state.ResumeTiming();
    state.PauseTiming();
    opaque_frame(c, cam, opaque, order, base);
    state.ResumeTiming();
  }
  const double iters = double(state.iterations());
  state.counters["segments"] = double(segments) / iters;
  state.counters["pre_integrated"] = double(pre_integrated) / iters;
  state.counters["order_ms"] = t.order_ms / iters;
  state.counters["draw_ms"] = t.draw_ms / iters;
  state.counters["draw_cpu_ms"] = draw_cpu_ms / iters;
  state.counters["ns_per_segment"] = draw_cpu_ms * 1e6 / double(segments);
  state.counters["least_cpu_ms"] = least_cpu_ms / iters;
  state.counters["least_ns_per_segment"] = least_cpu_ms * 1e6 / least_segments;
  state.counters["opaque_ms"] = base.total() / iters;
  state.counters["ratio"] = t.total() / base.total();
}

// The same frames in an interactive view (InteractiveView::set_volume, restart, steps of 40 ms as
// foxi-view and the workbench take them, the picture asked for after each step as they show it):
// the progressive order's batches, one resolve per shown picture. Counter one_call_ms: the one-call
// frame (order + VolumePainter over the whole order) of the same views in the same iterations, and
// ratio (view / one call).
void BM_volume_view_frame(benchmark::State& state) {
  Case& c = get_case();
  InteractiveView view(c.mesh[0], c.camera, kWidth, kHeight);
  view.set_volume(c.corner, &c.volume);
  Framebuffer fb(kWidth, kHeight);
  std::vector<std::uint32_t> order;
  double one_call_ms = 0, view_ms = 0;
  std::size_t shown = 0;
  int i = 0;
  for (auto _ : state) {
    const Camera cam = orbit(c.camera, 7.0 * i++, 0);
    auto t0 = std::chrono::steady_clock::now();
    view.set_camera(cam);
    view.set_running(true);
    while (view.running()) {
      view.step(std::chrono::milliseconds(40));
      benchmark::DoNotOptimize(view.framebuffer().rgba.data());
      ++shown;
    }
    view_ms += ms_since(t0);
    state.PauseTiming();
    t0 = std::chrono::steady_clock::now();
    visibility_order_into(order, c.mesh[0], c.table, view_of(cam));
    VolumePainter painter(c.mesh[0], cam, kWidth, kHeight, c.corner, c.volume);
    painter.draw(order);
    painter.resolve(fb);
    one_call_ms += ms_since(t0);
    state.ResumeTiming();
  }
  const double iters = double(state.iterations());
  state.counters["shown"] = double(shown) / iters;
  state.counters["one_call_ms"] = one_call_ms / iters;
  state.counters["ratio"] = view_ms / one_call_ms;
  state.SetLabel("volume in an InteractiveView");
}

BENCHMARK(BM_opaque_frame)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_translucent_frame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_volume_frame)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK(BM_volume_view_frame)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

}  // namespace

BENCHMARK_MAIN();
