#include "foxi/viz/movie.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "foxi/model/delaunay.hpp"
#include "foxi/viz/visibility_order.hpp"

namespace foxi {

namespace {

std::size_t prefix(std::size_t n, double fraction) {
  return std::min(n, std::size_t(std::llround(std::clamp(fraction, 0.0, 1.0) * double(n))));
}

}  // namespace

MovieStats make_movie(const Mesh& mesh, const SphereTable& table, const Camera& camera, int width, int height,
                      std::span<const std::uint32_t> subset, const MovieParams& params,
                      const std::function<void(const Framebuffer&)>& frame, const ProgressFn& progress) {
  if (params.frames < 2 || params.cycles < 1)
    throw std::invalid_argument("movie: needs at least 2 frames per cycle and 1 cycle");
  if (!(params.from >= 0 && params.from <= params.to && params.to <= 1))
    throw std::invalid_argument("movie: needs 0 <= from <= to <= 1");
  // The painter's picture of an uncertified mesh may be wrong, and undraw has no depth-buffer mode.
  if (!delaunay_certificate(mesh).delaunay) throw UncertifiedMeshError();
  MovieStats stats;
  const std::size_t total = std::size_t(params.frames) * std::size_t(params.cycles);
  auto emit = [&](const Framebuffer& fb) {
    frame(fb);
    ++stats.frames;
    if (progress && !progress("movie", double(stats.frames) / double(total))) throw MovieCancelled();
  };
  Framebuffer fb(width, height);
  if (params.rotate) {
    for (int c = 0; c < params.cycles; ++c)
      for (int k = 0; k < params.frames; ++k) {
        const Camera cam = orbit(camera, params.turn_deg * k / params.frames, 0);
        const auto order = visibility_order(mesh, table, view_of(cam), subset);
        const std::size_t n = prefix(order.size(), params.to);
        fb.clear();
        TetRasterizer r(mesh, cam, width, height, params.render);
        r.draw(fb, std::span<const std::uint32_t>(order).first(n));
        stats.tets_drawn += n;
        emit(fb);
      }
    return stats;
  }
  const auto order = visibility_order(mesh, table, view_of(camera), subset);
  const std::span<const std::uint32_t> all(order);
  RenderParams rp = params.render;
  rp.undoable = true;
  rp.depth_buffer = false;
  TetRasterizer r(mesh, camera, width, height, rp);
  const int half = params.frames / 2;
  const std::size_t low = prefix(order.size(), params.from);
  r.draw(fb, all.first(low));
  stats.tets_drawn += low;
  for (int c = 0; c < params.cycles; ++c) {
    for (int k = 0; k < params.frames; ++k) {
      // Up for k = 0..half, down for the rest, back to the low point after the last frame.
      const double t =
          k <= half ? double(k) / half : double(params.frames - k) / double(params.frames - half);
      const std::size_t want = prefix(order.size(), params.from + (params.to - params.from) * t);
      const std::size_t have = r.drawn_tets().size();
      if (want > have) {
        r.draw(fb, all.subspan(have, want - have));
        stats.tets_drawn += want - have;
      } else if (want < have) {
        r.undraw(fb, have - want);
        stats.tets_undrawn += have - want;
      }
      stats.max_undo_bytes = std::max(stats.max_undo_bytes, r.undo_bytes());
      emit(fb);
    }
  }
  return stats;
}

}  // namespace foxi
