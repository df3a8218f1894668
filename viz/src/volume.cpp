// Direct volume rendering by projected tetrahedra (volume.hpp): each tet's pixels the spans of pixel
// centres in its projection (half-open, a fill rule), the ray's segment through the tet found per pixel from
// the tet's four planes, and the emission-absorption integral of the linear field over it blended back to
// front. This file: the painter's construction, a batch's draw over the screen tiles, the resolve and
// the safe picture; volume_impl.hpp says where the rest lives and how the work is shared.
#include "foxi/viz/volume.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "foxi/model/delaunay.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "volume_impl.hpp"

namespace foxi {

VolumePainter::VolumePainter(const Mesh& mesh, const Camera& camera, int width, int height,
                             std::span<const double> corner, const VolumeParams& params)
    : impl_(std::make_unique<Impl>(mesh, camera, width, height)) {
  Impl& s = *impl_;
  if (corner.size() != mesh.tet.size())
    throw std::invalid_argument("volume: " + std::to_string(corner.size()) + " corner values for a mesh of " +
                                std::to_string(mesh.tet_count()) + " tets (4 per tet expected)");
  if (!(params.unit_length > 0) || !std::isfinite(params.unit_length))
    throw std::invalid_argument("volume: the unit length must be positive");
  for (std::size_t i = 0; i < params.opacity_curve.size(); ++i) {
    const OpacityPoint& p = params.opacity_curve[i];
    if (!(p.opacity >= 0 && p.opacity < 1) || !std::isfinite(p.value))
      throw std::invalid_argument("volume: opacity curve point " + std::to_string(i + 1) +
                                  ": the opacity must be in [0, 1) and the value finite");
    if (i > 0 && !(p.value > params.opacity_curve[i - 1].value))
      throw std::invalid_argument("volume: the opacity curve's values must increase");
  }
  // Its table (TableTransfer) steps across the curve: the span and its 4096th must be doubles.
  if (params.opacity_curve.size() > 1) {
    const double span = params.opacity_curve.back().value - params.opacity_curve.front().value;
    if (!std::isfinite(span) || !std::isfinite(4096 / span))
      throw std::invalid_argument(
          "volume: the opacity curve's values span " + std::to_string(span) +
          ": more than a double holds, or too little to step across (at least 1e-290 and at most 1e308)");
  }
  s.corner = corner;
  s.params = params;
#ifdef FOXI_VOLUME_AVX512
  // Its pixel indices are 32-bit.
  s.vector_rows = volume_avx512() && std::size_t(width) * std::size_t(height) < (std::size_t(1) << 29);
  // It works in float: a curve or colour range beyond 1e30, or under 1e-25 wide, would overflow or
  // underflow there (a field of 1e300 drew nothing); such a picture takes the portable path, in
  // double. (A tet with such corner values does, alone: draw_tet, draw_tets.)
  if (s.vector_rows) {
    double lo = params.scale.lo, hi = params.scale.hi;
    for (const OpacityPoint& p : params.opacity_curve) lo = std::min(lo, p.value), hi = std::max(hi, p.value);
    s.vector_rows = std::abs(lo) <= kFloatSafe && std::abs(hi) <= kFloatSafe && hi - lo >= 1e-25;
  }
#endif
  s.tiles_x = (width + Impl::kTileW - 1) / Impl::kTileW;
  s.tiles_y = (height + Impl::kTileH - 1) / Impl::kTileH;
  if (s.tiles_x > 65535 || s.tiles_y > 65535) throw std::invalid_argument("volume: the picture is too large");
  s.lanes = std::clamp(params.threads, 1, s.tiles_x * s.tiles_y);
  s.transfer = std::make_unique<TableTransfer>(s.params);
  Impl::Rays& rays = s.rays;
  if (s.proj.perspective) {
    rays.d0[0] = (0.5 - s.proj.cx) / s.proj.focal;
    rays.dx = 1 / s.proj.focal;
    rays.d0[1] = -(0.5 - s.proj.cy) / s.proj.focal;
    rays.dy = -1 / s.proj.focal;
  } else {
    rays.o0[0] = (0.5 - s.proj.cx) / s.proj.scale;
    rays.ox = 1 / s.proj.scale;
    rays.o0[1] = -(0.5 - s.proj.cy) / s.proj.scale;
    rays.oy = -1 / s.proj.scale;
  }
  // The nodes in the camera frame and their pixels, on the painter's threads.
  const std::size_t nodes = mesh.node_count();
  s.cam_xyz.resize(mesh.xyz.size());
  s.node_px.resize(2 * nodes);
  run_parts(s.lanes, [&](int lane) {
    const std::size_t k0 = nodes * std::size_t(lane) / std::size_t(s.lanes),
                      k1 = nodes * std::size_t(lane + 1) / std::size_t(s.lanes);
    for (std::size_t k = k0; k < k1; ++k) {
      double* c = &s.cam_xyz[3 * k];
      s.proj.to_camera(&mesh.xyz[3 * k], c);
      double* q = &s.node_px[2 * k];
      if (s.proj.perspective && !(c[2] > std::max(params.near, 0.0) && c[2] > 0))
        q[0] = q[1] = std::numeric_limits<double>::quiet_NaN();
      else
        s.proj.camera_to_pixel(c, q);
    }
  });
  s.lane_samples.assign(std::size_t(s.lanes), 0);
  s.lane_fast.assign(std::size_t(s.lanes), 0);
  // The picture's planes are not cleared here: each tile clears its own pixels when it is first
  // drawn (on the thread that draws it, into its cache), and resolve() gives a tile never drawn the
  // background. Clearing 2M pixels' four planes up front, on one thread, with their pages faulted in
  // there, took some 15 ms of a 0.97M-tet frame's 0.8 s.
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  for (auto& c : s.chan) c.reset(new float[pixels]);
  s.front.reset(new std::uint32_t[pixels]);
  s.tile_ready.assign(std::size_t(s.tiles_x) * std::size_t(s.tiles_y), 0);
  s.tile_drawn.assign(s.tile_ready.size(), 1);
}

void VolumePainter::Impl::clear_tile(const Tile& tile) {
  float bg[3];
  for (int j = 0; j < 3; ++j) bg[j] = float((params.background >> (8 * j)) & 255u);
  for (int y = tile.y0; y <= tile.y1; ++y) {
    const std::size_t row = std::size_t(y) * std::size_t(proj.width) + std::size_t(tile.x0);
    const std::size_t n = std::size_t(tile.x1 - tile.x0 + 1);
    for (int j = 0; j < 3; ++j) std::fill_n(&chan[j][row], n, bg[j]);
    std::fill_n(&front[row], n, kNone);
  }
}

VolumePainter::Impl::Tile VolumePainter::Impl::tile_at(int k) const {
  const int tx = k % tiles_x, ty = k / tiles_x;
  return {tx * kTileW, std::min(proj.width, (tx + 1) * kTileW) - 1, ty * kTileH,
          std::min(proj.height, (ty + 1) * kTileH) - 1};
}

VolumePainter::~VolumePainter() = default;
VolumePainter::VolumePainter(VolumePainter&&) noexcept = default;
VolumePainter& VolumePainter::operator=(VolumePainter&&) noexcept = default;

void VolumePainter::draw(std::span<const std::uint32_t> tets) {
  Impl& s = *impl_;
  for (std::uint32_t t : tets)
    if (t >= s.mesh->tet_count()) throw std::invalid_argument("volume: tet index out of range");
  s.bin(tets);
  // The tiles with tets, the most first (their tet count stands for their work): each thread takes
  // the next, so the last ones taken are short and neither thread waits long for the other at the
  // end (in screen order a thread could take a crowded tile last). Against screen order, alternately
  // in one process (2026-11-28, the 0.97M box at 1920x1080, 2 threads, 8 frames each, twice): the
  // painter's wall time least 501/526 against 534/561 ms, median 540/573 against 569/600 (5-6% less).
  const int n_tiles = s.tiles_x * s.tiles_y;
  std::vector<int> tiles;
  for (int k = 0; k < n_tiles; ++k)
    if (s.tile_start[std::size_t(k)] != s.tile_start[std::size_t(k) + 1]) tiles.push_back(k);
  auto work = [&](int k) { return s.tile_start[std::size_t(k) + 1] - s.tile_start[std::size_t(k)]; };
  std::stable_sort(tiles.begin(), tiles.end(), [&](int a, int b) { return work(a) > work(b); });
  for (int k : tiles) s.tile_drawn[std::size_t(k)] = 1;
  std::atomic<int> next{0};
  const int n_work = int(tiles.size());
  run_parts(s.lanes, [&](int lane) {
    std::size_t count = 0, fast = 0;
    auto scratch = std::make_unique<Impl::Scratch>();
    for (int w; (w = next.fetch_add(1, std::memory_order_relaxed)) < n_work;) {
      const int k = tiles[std::size_t(w)];
      const Impl::Tile tile = s.tile_at(k);
      const std::uint32_t end = s.tile_start[std::size_t(k) + 1];
      if (!s.tile_ready[std::size_t(k)]) {
        s.clear_tile(tile);
        s.tile_ready[std::size_t(k)] = 1;
      }
#ifdef FOXI_VOLUME_AVX512
      if (s.vector_rows) {
        // Eight tets set up at once (draw_tets): 10% less CPU a frame of the 0.97M box than one at
        // a time (the same pictures, pixel for pixel).
        constexpr std::uint32_t kB = TetBatch::kLanes;
        for (std::uint32_t i = s.tile_start[std::size_t(k)]; i < end; i += kB) {
          // Fetched ahead as below, a batch at a time.
          for (std::uint32_t j = i + 2 * kB; j < std::min(end, i + 3 * kB); ++j) {
            __builtin_prefetch(&s.mesh->tet[4 * std::size_t(s.tile_tets[j])]);
            __builtin_prefetch(&s.corner[4 * std::size_t(s.tile_tets[j])]);
          }
          for (std::uint32_t j = i + kB; j < std::min(end, i + 2 * kB); ++j) {
            const std::uint32_t* node = &s.mesh->tet[4 * std::size_t(s.tile_tets[j])];
            for (int c = 0; c < 4; ++c) {
              __builtin_prefetch(&s.cam_xyz[3 * std::size_t(node[c])]);
              __builtin_prefetch(&s.node_px[2 * std::size_t(node[c])]);
            }
          }
          s.draw_tets(&s.tile_tets[i], int(std::min(kB, end - i)), tile, *scratch, count, fast);
        }
        continue;
      }
#endif
      for (std::uint32_t i = s.tile_start[std::size_t(k)]; i < end; ++i) {
        // The order visits tets far apart in memory: their nodes and values are fetched ahead (the
        // node indices 16 tets ahead, the nodes' coordinates and pixels 8 ahead), else draw_tet
        // waits on them (8 and 4 ahead were some 3% slower a frame once the lane groups were
        // pipelined; 32 and 16 no faster; without the pixels' fetch 2% slower).
        if (i + 16 < end) {
          __builtin_prefetch(&s.mesh->tet[4 * std::size_t(s.tile_tets[i + 16])]);
          __builtin_prefetch(&s.corner[4 * std::size_t(s.tile_tets[i + 16])]);
        }
        if (i + 8 < end) {
          const std::uint32_t* node = &s.mesh->tet[4 * std::size_t(s.tile_tets[i + 8])];
          for (int j = 0; j < 4; ++j) {
            __builtin_prefetch(&s.cam_xyz[3 * std::size_t(node[j])]);
            __builtin_prefetch(&s.node_px[2 * std::size_t(node[j])]);
          }
        }
        s.draw_tet(s.tile_tets[i], tile, *scratch, count, fast);
      }
    }
    s.lane_samples[std::size_t(lane)] += count;
    s.lane_fast[std::size_t(lane)] += fast;
  });
}

void VolumePainter::Impl::resolve_tiles(Framebuffer& fb, std::span<const int> tiles) const {
  const Impl& s = *this;
  auto to8 = [](float c) { return std::uint32_t(int(std::clamp(c, 0.0f, 255.0f) + 0.5f)); };
  const std::uint32_t background =
      pack_rgba((s.params.background >> 0) & 255u, (s.params.background >> 8) & 255u,
                (s.params.background >> 16) & 255u);
  const int n = int(tiles.size());
  const int parts = std::min(s.lanes, std::max(n, 1));
  run_parts(parts, [&](int part) {
    for (int i = n * part / parts; i < n * (part + 1) / parts; ++i) {
      const int k = tiles[std::size_t(i)];
      const Tile tile = s.tile_at(k);
      const bool drawn = s.tile_ready[std::size_t(k)] != 0;  // else never cleared: the background
      for (int y = tile.y0; y <= tile.y1; ++y) {
        const std::size_t row = std::size_t(y) * std::size_t(s.proj.width);
        for (std::size_t p = row + std::size_t(tile.x0); p <= row + std::size_t(tile.x1); ++p) {
          fb.rgba[p] =
              drawn ? pack_rgba(to8(s.chan[0][p]), to8(s.chan[1][p]), to8(s.chan[2][p])) : background;
          fb.id[p] = drawn ? s.front[p] : kNone;
          fb.shade[p] = 0;
        }
      }
    }
  });
}

bool VolumePainter::Impl::fits(const Framebuffer& fb) const {
  const std::size_t pixels = std::size_t(proj.width) * std::size_t(proj.height);
  return fb.width == proj.width && fb.height == proj.height && fb.rgba.size() == pixels &&
         fb.id.size() == pixels && fb.shade.size() == pixels;
}

void VolumePainter::resolve(Framebuffer& fb) const {
  const Impl& s = *impl_;
  // Every pixel is written below: a framebuffer of the right size is not cleared first (an
  // interactive view resolves once a shown frame, and at 1920x1080 the clearing cost as much).
  if (!s.fits(fb)) {
    fb.resize(s.proj.width, s.proj.height, false, s.params.background);
  } else {
    fb.depth.clear();
    fb.depth_slope.clear();
  }
  std::vector<int> all(s.tile_ready.size());
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = int(k);
  s.resolve_tiles(fb, all);
}

void VolumePainter::resolve_drawn(Framebuffer& fb, bool whole) {
  Impl& s = *impl_;
  if (whole || !s.fits(fb)) {
    resolve(fb);
    std::fill(s.tile_drawn.begin(), s.tile_drawn.end(), std::uint8_t(0));
    return;
  }
  fb.depth.clear();
  fb.depth_slope.clear();
  std::vector<int> drawn;
  for (std::size_t k = 0; k < s.tile_drawn.size(); ++k)
    if (s.tile_drawn[k]) {
      drawn.push_back(int(k));
      s.tile_drawn[k] = 0;
    }
  s.resolve_tiles(fb, drawn);
}

std::size_t VolumePainter::pre_integrated() const {
  std::size_t n = 0;
  for (std::size_t c : impl_->lane_fast) n += c;
  return n;
}

std::size_t VolumePainter::samples() const {
  std::size_t n = 0;
  for (std::size_t c : impl_->lane_samples) n += c;
  return n;
}

VolumeReport draw_volume_picture(const Mesh& mesh, const SphereTable& table, const Camera& camera,
                                 Framebuffer& fb, std::span<const std::uint32_t> subset,
                                 std::span<const double> corner, const VolumeParams& params) {
  if (fb.width < 1 || fb.height < 1)
    throw std::invalid_argument("draw_volume_picture: the framebuffer is empty");
  if (table.tet_count() != mesh.tet_count())
    throw std::invalid_argument("draw_volume_picture: the sphere table belongs to another mesh");
  auto ms_since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  };
  VolumeReport report;
  auto t0 = std::chrono::steady_clock::now();
  report.delaunay = delaunay_certificate(mesh).delaunay;
  report.certificate_ms = ms_since(t0);
  report.exact_order = report.delaunay;
  t0 = std::chrono::steady_clock::now();
  const std::vector<std::uint32_t> order =
      report.delaunay ? visibility_order(mesh, table, view_of(camera), subset)
                      : mpvo_order(mesh, table, view_of(camera), subset, &report.cycles_broken);
  report.order_ms = ms_since(t0);
  report.tets = order.size();
  t0 = std::chrono::steady_clock::now();
  VolumePainter painter(mesh, camera, fb.width, fb.height, corner, params);
  painter.draw(order);
  painter.resolve(fb);
  report.samples = painter.samples();
  report.draw_ms = ms_since(t0);
  return report;
}

}  // namespace foxi
