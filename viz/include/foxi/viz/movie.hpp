// Movies of the painter (seed paper, section 6.1): back-and-forth (draw the tets back to front, then
// undraw them front to back, over and over, with intermediate frames) and a rotating view (the
// camera turned about its up axis through `at`, the order recomputed per frame). Frames are handed
// to a callback; writing them (PNG frames, APNG, GIF, MP4) is the caller's business (animation.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/progress.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/translucent.hpp"
#include "foxi/viz/volume.hpp"

namespace foxi {

struct MovieParams {
  bool rotate = false;    // false: back-and-forth; true: rotating view
  int frames = 48;        // frames per cycle (>= 2); back-and-forth: half drawing, half undrawing
  int cycles = 1;         // cycles (>= 1)
  double from = 0;        // back-and-forth: fraction of the order drawn at the low turning point
  double to = 1;          // fraction drawn at the high turning point (rotate: drawn in every frame)
  double turn_deg = 360;  // rotate: total yaw over one cycle
  RenderParams render;    // painter settings (undoable is set for back-and-forth)
};

struct MovieStats {
  std::size_t frames = 0;
  std::size_t tets_drawn = 0;  // tets drawn over the whole movie (redraws counted again)
  std::size_t tets_undrawn = 0;
  std::size_t max_undo_bytes = 0;  // largest memory held for undraw
};

// Thrown when the progress callback returns false.
struct FOXI_API MovieCancelled : std::runtime_error, Cancelled {
  MovieCancelled() : std::runtime_error("movie cancelled") {}
};

// Thrown by make_movie for a mesh that fails the Delaunay certificate: the painter has no
// visibility order to draw it in, and undrawing needs the painter (picture.hpp draws such a mesh
// with the depth buffer instead).
struct FOXI_API UncertifiedMeshError : std::invalid_argument {
  UncertifiedMeshError()
      : std::invalid_argument(
            "the mesh fails the Delaunay certificate: it has no visibility order to make a movie with") {}
};

// Calls frame(fb) for each frame, in order. Back-and-forth frame k of a cycle of F frames shows the
// first round(n (from + (to - from) k / h)) tets of the order for k <= h = F / 2, then undraws
// back (the undrawn picture equals drawing that prefix afresh, see TetRasterizer::undraw): a cycle
// starts and ends at `from`, so it loops seamlessly. Rotate frame k turns the camera by
// turn_deg k / F. subset: tets to show (empty = all). Throws UncertifiedMeshError before any frame for a mesh
// without the visibility-order guarantee (delaunay.hpp's cached certificate), std::invalid_argument
// for bad parameters, MovieCancelled when progress returns false.
FOXI_API MovieStats make_movie(const Mesh& mesh, const SphereTable& table, const Camera& camera, int width,
                               int height, std::span<const std::uint32_t> subset, const MovieParams& params,
                               const std::function<void(const Framebuffer&)>& frame,
                               const ProgressFn& progress = {});

// Movies of translucent regions and isosurfaces or of a volume rendering (issue 23): one of
// `translucent` and `volume` (its corner values lent, 4 per tet), each frame composited as
// draw_translucent_picture or draw_volume_picture composites it.
struct CompositeMovieParams {
  MovieParams movie;  // rotate, frames, cycles, from and to (back-and-forth), turn_deg; render unused
  std::optional<TranslucentParams> translucent;
  std::optional<VolumeParams> volume;
  std::span<const double> corner;  // volume: the field's corner values
};

struct CompositeMovieStats {
  std::size_t frames = 0;
  bool exact = true;             // every frame composited in the power order
  std::size_t composited = 0;    // tets composited over the movie (recomposited ones again)
  std::size_t recomposited = 0;  // of those, composited again to go back (back-and-forth)
  std::size_t fragments = 0;     // translucent: fragments blended; volume: pixel segments integrated
};

// Calls frame(fb) for each frame, in order, of `subset` (empty: all tets). Rotate: frame k is the
// one-call picture with the camera turned by turn_deg k / frames (a mesh without the certificate is
// composited as those functions do it without one, not exactly, and stats.exact says so).
// Back-and-forth (make_movie's frame counts): the far part of the power order of the tets that own
// something to draw growing from `from` to `to` and shrinking back; "over" cannot be taken back, so a
// shrinking frame composites the remaining far part again from the back (exactly the picture of
// that far part drawn afresh). Throws UncertifiedMeshError for back-and-forth without the
// certificate, std::invalid_argument for bad parameters (neither or both of translucent and volume),
// MovieCancelled when progress returns false.
FOXI_API CompositeMovieStats make_composite_movie(const Mesh& mesh, const SphereTable& table,
                                                  const Camera& camera, int width, int height,
                                                  std::span<const std::uint32_t> subset,
                                                  const CompositeMovieParams& params,
                                                  const std::function<void(const Framebuffer&)>& frame,
                                                  const ProgressFn& progress = {});

}  // namespace foxi
