#include "foxi/viz/movie.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
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

namespace {

// One of the two compositing painters, for the back-and-forth movie.
struct Compositor {
  std::unique_ptr<TranslucentPainter> translucent;
  std::unique_ptr<VolumePainter> volume;
  void draw(std::span<const std::uint32_t> tets) {
    if (translucent)
      translucent->draw(tets);
    else
      volume->draw(tets);
  }
  void resolve(Framebuffer& fb) {
    if (translucent)
      translucent->resolve(fb);
    else
      volume->resolve(fb);
  }
  std::size_t fragments() const { return translucent ? translucent->fragment_count() : volume->samples(); }
};

}  // namespace

CompositeMovieStats make_composite_movie(const Mesh& mesh, const SphereTable& table, const Camera& camera,
                                         int width, int height, std::span<const std::uint32_t> subset,
                                         const CompositeMovieParams& params,
                                         const std::function<void(const Framebuffer&)>& frame,
                                         const ProgressFn& progress) {
  const MovieParams& mp = params.movie;
  if (mp.frames < 2 || mp.cycles < 1)
    throw std::invalid_argument("movie: needs at least 2 frames per cycle and 1 cycle");
  if (!(mp.from >= 0 && mp.from <= mp.to && mp.to <= 1))
    throw std::invalid_argument("movie: needs 0 <= from <= to <= 1");
  if (params.translucent.has_value() == params.volume.has_value())
    throw std::invalid_argument("composite movie: give translucent or volume parameters, one of them");
  const bool volume = params.volume.has_value();
  CompositeMovieStats st;
  const std::size_t total = std::size_t(mp.frames) * std::size_t(mp.cycles);
  auto emit = [&](const Framebuffer& fb) {
    frame(fb);
    ++st.frames;
    if (progress && !progress("movie", double(st.frames) / double(total))) throw MovieCancelled();
  };
  if (mp.rotate) {
    for (int c = 0; c < mp.cycles; ++c)
      for (int k = 0; k < mp.frames; ++k) {
        Framebuffer fb(width, height);
        const Camera cam = orbit(camera, mp.turn_deg * k / mp.frames, 0);
        if (volume) {
          const VolumeReport r =
              draw_volume_picture(mesh, table, cam, fb, subset, params.corner, *params.volume);
          st.exact = st.exact && r.exact_order;
          st.composited += r.tets;
          st.fragments += r.samples;
        } else {
          const TranslucentReport r =
              draw_translucent_picture(mesh, table, cam, fb, subset, *params.translucent);
          st.exact = st.exact && r.exact_order;
          st.composited += r.tets_ordered;
          st.fragments += r.fragments;
        }
        emit(fb);
      }
    return st;
  }
  // Back and forth: the far part of the power order of the tets that own something to draw.
  if (!delaunay_certificate(mesh).delaunay) throw UncertifiedMeshError();
  TranslucentSurfaces surfaces;
  std::span<const std::uint32_t> tets = subset;
  if (!volume) {
    surfaces = translucent_surfaces(mesh, subset, *params.translucent);
    tets = surfaces.tets;
  }
  std::vector<std::uint32_t> order;
  if (volume || !tets.empty()) order = visibility_order(mesh, table, view_of(camera), tets);
  const std::span<const std::uint32_t> all(order);
  auto fresh = [&] {
    Compositor c;
    if (volume)
      c.volume = std::make_unique<VolumePainter>(mesh, camera, width, height, params.corner, *params.volume);
    else
      c.translucent =
          std::make_unique<TranslucentPainter>(mesh, camera, width, height, surfaces, *params.translucent);
    return c;
  };
  Compositor painter = fresh();
  std::size_t fragments_before = 0;  // of the painters replaced
  std::size_t have = prefix(order.size(), mp.from);
  painter.draw(all.first(have));
  st.composited += have;
  const int half = mp.frames / 2;
  Framebuffer fb(width, height);
  for (int c = 0; c < mp.cycles; ++c)
    for (int k = 0; k < mp.frames; ++k) {
      const double t = k <= half ? double(k) / half : double(mp.frames - k) / double(mp.frames - half);
      const std::size_t want = prefix(order.size(), mp.from + (mp.to - mp.from) * t);
      if (want > have) {
        painter.draw(all.subspan(have, want - have));
        st.composited += want - have;
      } else if (want < have) {
        fragments_before += painter.fragments();
        painter = fresh();
        painter.draw(all.first(want));
        st.composited += want;
        st.recomposited += want;
      }
      have = want;
      painter.resolve(fb);
      st.fragments = fragments_before + painter.fragments();
      emit(fb);
    }
  return st;
}

}  // namespace foxi
