// foxi movie with translucency or volume rendering (issue 23 item 3): the movie modes with
// --region-opacity, --iso-opacity or --volume, and --sweep opacity:a,b. Each frame is composited by
// the painters foxi render uses, from the same parameters (composite_options.hpp):
//   rotate     frame k the picture foxi render draws with the camera turned by turn k / N;
//   backforth  the far part of the power order growing from --from to --to and shrinking back. Going
//              back cannot take "over" back: frame k composites the remaining prefix again from the
//              back, so it equals a fresh draw of that prefix (the frames going up and coming down
//              through the same prefix are the same picture);
//   --sweep opacity:a,b  frame k every opacity given (the region opacities, --iso-opacity, the
//              opacity curve's) multiplied by s_k = a + (b - a) k / (N - 1): foxi render with the
//              scaled opacities.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "composite_options.hpp"
#include "field_options.hpp"
#include "iso_options.hpp"
#include "movie_sweep.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/movie.hpp"
#include "foxi/viz/spheres.hpp"

namespace foxi::cli {

// "opacity:a,b" (a, b >= 0, different), or nothing for any other text (parse_sweep's forms).
std::optional<Sweep> parse_opacity_sweep(const std::string& text);

// UsageError for what a translucent or volume movie does not combine with: another kind of sweep,
// --threshold, --clip, --slice (check_composite_options), --from/--to with rotate; and an opacity
// sweep without translucency or volume.
void check_composite_movie(const CompositeOptions& composite, const std::optional<Sweep>& opacity_sweep,
                           const Sweep& sweep, const FieldOptions& field, const IsoOptions& iso,
                           double shrink, bool rotate, bool from_to_given);

struct CompositeMovieInputs {
  const Mesh& mesh;
  const SphereTable& table;
  const Camera& camera;
  int width, height;                      // the scene, without the legend's panel
  std::span<const std::uint32_t> subset;  // --regions (empty: all)
  const CompositeOptions& options;
  const RenderParams& render;
  const FieldPicture& field;  // volume: its field; translucent: the isosurfaces' (none without --iso)
  const IsoOptions& iso_options;
  const MovieParams& movie;            // rotate, frames, cycles, from, to, turn
  std::optional<Sweep> opacity_sweep;  // --sweep opacity:a,b (N = movie.frames)
  const std::string& path;
};

// The library's counts (viz/movie.hpp), and an opacity sweep's factors.
struct CompositeMovieStats : foxi::CompositeMovieStats {
  std::vector<double> scales;  // --sweep opacity: each frame's factor
};

// Draws the frames in order and hands each, with the field picture its legend shows, to `frame`.
// InputError for a back-and-forth movie of a mesh without the Delaunay certificate.
CompositeMovieStats run_composite_movie(
    const CompositeMovieInputs& in,
    const std::function<void(const Framebuffer&, const FieldPicture&)>& frame);

// The movie's lines of the report.
void print_composite_movie(const CompositeMovieStats& stats, const CompositeMovieInputs& in);

}  // namespace foxi::cli
