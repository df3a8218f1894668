// Full frames of the software painter (issue 4) at 1920x1080, flat-shaded with edges, all tets
// drawn (the whole mesh's interior layers), with the depth-buffer mode as the baseline in the same run.
//   painter_draw      rasterizer setup (project the nodes) + clear + draw all tets in visibility order
//   zbuffer_draw      the same with the depth test (draw order irrelevant; the test oracle)
//   painter_frame     painter_draw plus computing the visibility order for the view
//   painter_shrink    painter_draw with every tet shrunk to 0.8 (all faces of all tets visible somewhere)
//   painter_draw_1thread  painter_draw on one thread (the threading baseline)
//   painter_draw_undoable painter_draw recording what undraw needs (saved pixels of unshared back
//                     faces); counter undo_MB = memory held for undraw after the whole mesh is drawn
//   painter_draw_undoable_lattice  undoable drawing of a Kuhn grid seen from its own planes (below)
//   undraw_front10    (after an untimed undoable draw of all tets) undraw the front 10% of the order
//                     in 10 frames of 1%, back to back, each frame presented as a display would (the
//                     rectangles it changed, changed_rects, copied into the displayed image); counters
//                     ms_per_frame, tets_per_s (tets undrawn), undo_MB, and the issue 4 target
//                     (undrawing the 10 frames in at most a fifth of a full redraw): redraw_ms, a
//                     painter_draw of the same view in the same iteration (outside the timing), and
//                     ratio = undraw time / redraw time, wall clock (cpu_ratio: process CPU time).
//                     The first view's frames are replayed untimed to count px_per_frame (pixels a
//                     frame changes, colour or id: the work a frame must do), rect_px_per_frame (the
//                     rectangles presented; union_px_per_frame: changed_rect's area) and
//                     shown_wrong_px (displayed pixels unlike the frame: 0).
//   field_flat_draw   painter_draw with the tets coloured by a smooth node field, flat (centroid values)
//   field_graded_draw painter_draw with graded facets of the same field (each pixel's colour from the
//                     face's interpolated scale position, perspective-correct); counters plain_ms (a
//                     painter_draw of the same view in the same iteration, outside the timing) and
//                     ratio = graded time / plain time, wall clock (issue 17 target: at most 1.5);
//                     cpu_ratio the same in process CPU time
//   field_recolor     (after an untimed draw of all tets with field_flat_draw's paint) recolour the
//                     picture by another field (flat, coolwarm) through the id and shade buffers
//                     (TetRasterizer::recolor; issue 17 target: at most 10 ms); counters redraw_ms (a
//                     full painter_draw with the other field's paint, the same view and iteration,
//                     outside the timing), ratio = recolour / redraw wall clock, shown_tets (the tets
//                     the picture shows) and differ_px (pixels, colour or id, unlike the redraw: 0)
//   picture_into_image draw_picture into a host's RGBA image of 1920x1080 with rows 4 x 1920 + 64
//                     bytes apart (a std::vector the host owns; no large-page advice), the order
//                     included: /0 drawn into a framebuffer and copied (draw_picture into fb, then
//                     copy_rgba: the path before drawing in place), /1 drawn in place (draw_picture
//                     with the RgbaImage); counter paint_ms = the picture's clear, draw and copy alone
// Times are process CPU time (all threads) and real time.
// Meshes: TetGen's -O0 mesh of a 2x1x1 box at a4e-5 (~100k tets) and a4e-6 (~0.97M tets). The camera
// is fitted to the box from an oblique direction (the mesh fills about 90% of the image height) and
// turns by 7 degrees per iteration, so no frame repeats.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "bench_meshes.hpp"
#include "foxi/model/adjacency.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"

namespace {

using namespace foxi;

double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

constexpr int kWidth = 1920, kHeight = 1080;

struct Case {
  Mesh mesh;
  SphereTable table;
  Camera camera;
  std::shared_ptr<const FieldPaint> flat, graded;  // a smooth field's paints (field_paint)
  std::shared_ptr<const FieldPaint> other;         // another field, flat, coolwarm (field_recolor)
};

// A smooth node field over the box (a few periods of a product of sines), flat and graded paints.
void add_field(Case& c) {
  Field f{"f", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < c.mesh.node_count(); ++n) {
    const double* p = &c.mesh.xyz[3 * n];
    f.values.push_back(std::sin(3 * p[0]) * std::cos(4 * p[1]) + p[2]);
  }
  Field g{"g", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < c.mesh.node_count(); ++n) {
    const double* p = &c.mesh.xyz[3 * n];
    g.values.push_back(std::cos(5 * p[0]) + p[1] * p[2]);
  }
  c.mesh.fields = {f, g};
  const FieldChoice choice = choose_field(c.mesh, "f");
  ColorScale scale;
  std::tie(scale.lo, scale.hi) = finite_range(c.mesh.fields[0].values);
  c.flat = std::make_shared<const FieldPaint>(flat_field_paint(tet_centroid_values(c.mesh, choice), scale));
  c.graded = std::make_shared<const FieldPaint>(graded_field_paint(tet_corner_values(c.mesh, choice), scale));
  ColorScale other;
  other.map = ColorMapId::coolwarm;
  std::tie(other.lo, other.hi) = finite_range(c.mesh.fields[1].values);
  c.other = std::make_shared<const FieldPaint>(
      flat_field_paint(tet_centroid_values(c.mesh, choose_field(c.mesh, "g")), other));
}

Case& get_case(int which) {
  static std::unique_ptr<Case> cases[2];
  if (!cases[which]) {
    auto c = std::make_unique<Case>();
    c->mesh = bench::tetgen_box_mesh(2, 1, 1, which == 0 ? 4e-5 : 4e-6);
    face_adjacency(c->mesh);
    c->table = compute_spheres(c->mesh);
    double lo[3], hi[3];
    mesh_bounds(c->mesh, lo, hi);
    const double dir[3] = {-1.0, 1.6, -0.9}, up[3] = {0, 0, 1};
    c->camera = fit_camera(lo, hi, dir, up, true, 30, double(kWidth) / kHeight, 0.95);
    add_field(*c);
    cases[which] = std::move(c);
  }
  return *cases[which];
}

void counters(benchmark::State& state, const Case& c) {
  const double tets = double(c.mesh.tet_count());
  state.counters["tets"] = tets;
  state.counters["tets_per_s"] = benchmark::Counter(tets, benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(state.range(0) == 0 ? "box_100k" : "box_1M");
}

void run(benchmark::State& state, bool depth, bool with_order, double shrink, int threads = 2) {
  Case& c = get_case(int(state.range(0)));
  RenderParams params;
  params.depth_buffer = depth;
  params.shrink = shrink;
  params.threads = threads;
  Framebuffer fb(kWidth, kHeight, depth);
  std::size_t i = 0;
  std::vector<std::uint32_t> order;
  for (auto _ : state) {
    const Camera cam = orbit(c.camera, 7.0 * double(i++), 0);
    if (with_order) {
      order = visibility_order(c.mesh, c.table, view_of(cam));
    } else {
      state.PauseTiming();
      order = visibility_order(c.mesh, c.table, view_of(cam));
      state.ResumeTiming();
    }
    fb.clear();
    TetRasterizer r(c.mesh, cam, kWidth, kHeight, params);
    r.draw(fb, order);
    benchmark::DoNotOptimize(fb.rgba.data());
  }
  counters(state, c);
}

// A display's update after a frame: the rectangles of fb the last call changed, copied into `shown`
// (what the display holds) row by row, as XPutImage of sub-images would.
void present(const Framebuffer& fb, std::span<const PixelRect> rects, Framebuffer& shown) {
  for (const PixelRect& rect : rects)
    for (int y = rect.y0; y <= rect.y1; ++y)
      std::copy_n(fb.rgba.begin() + std::ptrdiff_t(fb.index(rect.x0, y)), rect.x1 - rect.x0 + 1,
                  shown.rgba.begin() + std::ptrdiff_t(shown.index(rect.x0, y)));
}

// The whole order drawn undoably (timed or not), then (undraw) the front 10% undrawn in 10 frames.
void run_undo(benchmark::State& state, bool undraw) {
  Case& c = get_case(int(state.range(0)));
  RenderParams params;
  params.undoable = true;
  Framebuffer fb(kWidth, kHeight), shown(kWidth, kHeight), before(kWidth, kHeight);
  std::size_t i = 0, undo_bytes = 0, changed = 0, mismatch = 0, presented = 0, union_px = 0;
  double undraw_ms = 0, undraw_cpu_ms = 0, redraw_ms = 0, redraw_cpu_ms = 0;
  std::vector<std::uint32_t> order;
  constexpr int kFrames = 10;
  for (auto _ : state) {
    state.PauseTiming();
    const Camera cam = orbit(c.camera, 7.0 * double(i++), 0);
    order = visibility_order(c.mesh, c.table, view_of(cam));
    fb.clear();
    if (undraw) {
      {  // the baseline: a full redraw of the same view (as painter_draw)
        const auto w0 = std::chrono::steady_clock::now();
        const double c0 = process_cpu_ms();
        shown.clear();
        TetRasterizer plain(c.mesh, cam, kWidth, kHeight);
        plain.draw(shown, order);
        benchmark::DoNotOptimize(shown.rgba.data());
        redraw_cpu_ms += process_cpu_ms() - c0;
        redraw_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count();
      }
      const std::size_t step = order.size() / 100;
      // The frames back to back, timed, as a viewer shows them; then, in the first iteration only and
      // untimed, the same frames again to count what each changed and check what was shown (a pass
      // over the whole image between timed frames would evict what the next frame uses).
      for (int pass = 0; pass < (i == 1 ? 2 : 1); ++pass) {
        const bool timed = pass == 0;
        fb.clear();
        auto r = std::make_unique<TetRasterizer>(c.mesh, cam, kWidth, kHeight, params);
        r->draw(fb, order);
        undo_bytes = r->undo_bytes();
        shown.rgba = fb.rgba;  // on the display
        before.id = fb.id;
        before.rgba = fb.rgba;
        if (timed) state.ResumeTiming();
        const auto t0 = std::chrono::steady_clock::now();
        const double c0 = process_cpu_ms();
        for (int f = 0; f < kFrames; ++f) {
          r->undraw(fb, step);
          present(fb, r->changed_rects(), shown);  // the frame shown
          if (timed) continue;
          for (const PixelRect& rect : r->changed_rects())
            presented += std::size_t(rect.x1 - rect.x0 + 1) * std::size_t(rect.y1 - rect.y0 + 1);
          const PixelRect all = r->changed_rect();
          if (all.x0 <= all.x1)
            union_px += std::size_t(all.x1 - all.x0 + 1) * std::size_t(all.y1 - all.y0 + 1);
          for (std::size_t p = 0; p < fb.id.size(); ++p) {
            changed += fb.id[p] != before.id[p] || fb.rgba[p] != before.rgba[p];
            mismatch += fb.rgba[p] != shown.rgba[p];
          }
          before.id = fb.id;
          before.rgba = fb.rgba;
        }
        if (timed) {
          undraw_cpu_ms += process_cpu_ms() - c0;
          undraw_ms +=
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
          benchmark::DoNotOptimize(shown.rgba.data());
          state.PauseTiming();
        }
        r.reset();  // freeing the saved pixels is not part of undrawing
      }
      state.ResumeTiming();
    } else {
      state.ResumeTiming();
      TetRasterizer r(c.mesh, cam, kWidth, kHeight, params);
      r.draw(fb, order);
      undo_bytes = r.undo_bytes();
      benchmark::DoNotOptimize(fb.rgba.data());
    }
  }
  counters(state, c);
  state.counters["undo_MB"] = double(undo_bytes) / 1e6;
  if (undraw) {
    const double undrawn = double(kFrames * (order.size() / 100));
    state.counters["tets"] = undrawn;
    state.counters["tets_per_s"] = benchmark::Counter(undrawn, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["ms_per_frame"] = undraw_ms / double(state.iterations() * kFrames);
    state.counters["px_per_frame"] = double(changed) / kFrames;
    state.counters["redraw_ms"] = redraw_ms / double(state.iterations());
    state.counters["ratio"] = undraw_ms / redraw_ms;
    state.counters["cpu_ratio"] = undraw_cpu_ms / redraw_cpu_ms;
    state.counters["rect_px_per_frame"] = double(presented) / kFrames;
    state.counters["union_px_per_frame"] = double(union_px) / kFrames;
    state.counters["shown_wrong_px"] = double(mismatch);  // displayed pixels unlike fb: must be 0
  }
}

// painter_draw with field colours (graded: and a plain painter_draw of each view as the baseline).
void run_field(benchmark::State& state, bool graded) {
  Case& c = get_case(int(state.range(0)));
  RenderParams params, plain;
  params.field = graded ? c.graded : c.flat;
  Framebuffer fb(kWidth, kHeight);
  std::size_t i = 0;
  double field_ms = 0, plain_ms = 0, field_cpu_ms = 0, plain_cpu_ms = 0;
  std::vector<std::uint32_t> order;
  for (auto _ : state) {
    state.PauseTiming();
    const Camera cam = orbit(c.camera, 7.0 * double(i++), 0);
    order = visibility_order(c.mesh, c.table, view_of(cam));
    if (graded) {  // the baseline: the same view, region colours
      const auto w0 = std::chrono::steady_clock::now();
      const double c0 = process_cpu_ms();
      fb.clear();
      TetRasterizer r(c.mesh, cam, kWidth, kHeight, plain);
      r.draw(fb, order);
      benchmark::DoNotOptimize(fb.rgba.data());
      plain_cpu_ms += process_cpu_ms() - c0;
      plain_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count();
    }
    state.ResumeTiming();
    const auto w0 = std::chrono::steady_clock::now();
    const double c0 = process_cpu_ms();
    fb.clear();
    TetRasterizer r(c.mesh, cam, kWidth, kHeight, params);
    r.draw(fb, order);
    benchmark::DoNotOptimize(fb.rgba.data());
    field_cpu_ms += process_cpu_ms() - c0;
    field_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count();
  }
  counters(state, c);
  if (graded) {
    state.counters["plain_ms"] = plain_ms / double(state.iterations());
    state.counters["ratio"] = field_ms / plain_ms;
    state.counters["cpu_ratio"] = field_cpu_ms / plain_cpu_ms;  // process CPU time: less noisy when shared
  }
}

// The picture drawn with the flat paint (untimed), recoloured by the other field; the baseline is a
// full redraw with the other paint.
void run_recolor(benchmark::State& state) {
  Case& c = get_case(int(state.range(0)));
  RenderParams params, other;
  params.field = c.flat;
  other.field = c.other;
  Framebuffer fb(kWidth, kHeight), redrawn(kWidth, kHeight);
  std::size_t i = 0, differ = 0, shown = 0;
  double recolor_ms = 0, redraw_ms = 0;
  std::vector<std::uint32_t> order;
  for (auto _ : state) {
    state.PauseTiming();
    const Camera cam = orbit(c.camera, 7.0 * double(i++), 0);
    order = visibility_order(c.mesh, c.table, view_of(cam));
    {  // the baseline: a full redraw of the same view in the other field's colours
      const auto w0 = std::chrono::steady_clock::now();
      redrawn.clear();
      TetRasterizer r(c.mesh, cam, kWidth, kHeight, other);
      r.draw(redrawn, order);
      benchmark::DoNotOptimize(redrawn.rgba.data());
      redraw_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count();
    }
    fb.clear();
    TetRasterizer r(c.mesh, cam, kWidth, kHeight, params);
    r.draw(fb, order);
    state.ResumeTiming();
    const auto w0 = std::chrono::steady_clock::now();
    r.recolor(fb, c.other);
    benchmark::DoNotOptimize(fb.rgba.data());
    recolor_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count();
    state.PauseTiming();
    std::vector<bool> seen(c.mesh.tet_count());
    for (std::size_t p = 0; p < fb.rgba.size(); ++p) {
      differ += fb.rgba[p] != redrawn.rgba[p] || fb.id[p] != redrawn.id[p];
      if (fb.id[p] != kNone && !seen[fb.id[p]]) {
        seen[fb.id[p]] = true;
        ++shown;
      }
    }
    state.ResumeTiming();
  }
  counters(state, c);
  const double iters = double(state.iterations());
  state.counters["redraw_ms"] = redraw_ms / iters;
  state.counters["ratio"] = recolor_ms / redraw_ms;
  state.counters["shown_tets"] = double(shown) / iters;
  state.counters["differ_px"] = double(differ);
}

void run_picture(benchmark::State& state) {
  Case& c = get_case(int(state.range(0)));
  const bool in_place = state.range(1) == 1;
  constexpr std::size_t kStride = 4 * kWidth + 64;
  std::vector<std::uint8_t> host(kStride * kHeight, 0);
  const RgbaImage image{host.data(), kWidth, kHeight, kStride};
  Framebuffer fb(kWidth, kHeight);
  delaunay_certificate(c.mesh);  // cached on the mesh: neither variant pays it
  double paint_ms = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const Camera cam = orbit(c.camera, 7.0 * double(i++), 0);
    if (in_place) {
      paint_ms += draw_picture(c.mesh, c.table, cam, image, fb).draw_ms;
    } else {
      fb.width = kWidth;
      fb.height = kHeight;
      const PictureReport r = draw_picture(c.mesh, c.table, cam, fb);
      const auto t0 = std::chrono::steady_clock::now();
      copy_rgba(fb, image);
      paint_ms += r.draw_ms +
                  std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
    benchmark::DoNotOptimize(host.data());
  }
  counters(state, c);
  state.counters["paint_ms"] = paint_ms / double(std::max<std::size_t>(i, 1));
  state.SetLabel(std::string(state.range(0) == 0 ? "box_100k" : "box_1M") +
                 (in_place ? " in place" : " copied"));
}

// An unjittered Kuhn grid of 50^3 cubes (750k tets) seen from its own planes, where faces are seen
// exactly edge on and undoable drawing saves the pixels near them (kNearEdge, raster_impl.hpp):
// /0 orthographic along z (the edge-on faces' corners snap onto common lines: nothing saved for
// them), /1 in perspective from an eye in the plane y = z (their snapped corners off those lines).
// Timed: the undoable draw of the whole order; baseline, the same iteration outside the timing: the
// plain painter draw of the same view, ratio = undoable / plain (wall); undo_MB as above, saved_px
// the pixels held for undraw.
void BM_painter_draw_undoable_lattice(benchmark::State& state) {
  static const Mesh mesh = [] {
    Mesh m = bench::kuhn_grid_mesh(50, 0.0);
    face_adjacency(m);
    return m;
  }();
  static const SphereTable table = compute_spheres(mesh);
  double lo[3], hi[3];
  mesh_bounds(mesh, lo, hi);
  const bool along_z = state.range(0) == 0;
  const double eye[3] = {2.3, 0.35, 0.35}, dir[3] = {0, 0, -1};
  const Camera cam = camera_from_options(lo, hi, double(kWidth) / kHeight, along_z ? nullptr : eye, nullptr,
                                         nullptr, 30, along_z ? dir : nullptr);
  const auto order = visibility_order(mesh, table, view_of(cam));
  RenderParams params;
  params.undoable = true;
  Framebuffer fb(kWidth, kHeight);
  double undoable_ms = 0, plain_ms = 0;
  std::size_t undo_bytes = 0, saved = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    fb.clear();
    TetRasterizer r(mesh, cam, kWidth, kHeight, params);
    r.draw(fb, order);
    benchmark::DoNotOptimize(fb.rgba.data());
    undoable_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    undo_bytes = r.undo_bytes();
    saved = r.saved_pixels();
    state.PauseTiming();
    const auto t1 = std::chrono::steady_clock::now();
    fb.clear();
    TetRasterizer plain(mesh, cam, kWidth, kHeight);
    plain.draw(fb, order);
    benchmark::DoNotOptimize(fb.rgba.data());
    plain_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
    state.ResumeTiming();
  }
  state.counters["tets"] = double(mesh.tet_count());
  state.counters["ratio"] = undoable_ms / std::max(plain_ms, 1e-9);
  state.counters["plain_ms"] = plain_ms / double(state.iterations());
  state.counters["undo_MB"] = double(undo_bytes) / 1e6;
  state.counters["saved_px"] = double(saved);
  state.SetLabel(along_z ? "kuhn_50 along z" : "kuhn_50 eye in y = z");
}

void BM_painter_draw(benchmark::State& state) { run(state, false, false, 1); }
void BM_picture_into_image(benchmark::State& state) { run_picture(state); }
void BM_field_recolor(benchmark::State& state) { run_recolor(state); }
void BM_field_flat_draw(benchmark::State& state) { run_field(state, false); }
void BM_field_graded_draw(benchmark::State& state) { run_field(state, true); }
void BM_painter_draw_undoable(benchmark::State& state) { run_undo(state, false); }
void BM_undraw_front10(benchmark::State& state) { run_undo(state, true); }
void BM_zbuffer_draw(benchmark::State& state) { run(state, true, false, 1); }
void BM_painter_frame(benchmark::State& state) { run(state, false, true, 1); }
void BM_painter_shrink(benchmark::State& state) { run(state, false, false, 0.8); }
void BM_painter_draw_1thread(benchmark::State& state) { run(state, false, false, 1, 1); }

}  // namespace

BENCHMARK(BM_painter_draw)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_zbuffer_draw)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_painter_frame)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_painter_shrink)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_painter_draw_1thread)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_painter_draw_undoable)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_painter_draw_undoable_lattice)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_field_flat_draw)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_field_graded_draw)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_field_recolor)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_undraw_front10)
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_picture_into_image)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

BENCHMARK_MAIN();
