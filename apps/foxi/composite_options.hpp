// The translucency and volume-rendering options foxi render and foxi movie share (issue 23):
// --region-opacity, --iso-opacity, --volume NAME, --opacity-curve, --opacity-length. Parsed before
// the mesh is read, resolved after the field and the isosurfaces into the painters' parameters
// (translucent.hpp, volume.hpp), so that a movie's frame and foxi render's picture with the same
// options are drawn from the same parameters.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "cli.hpp"
#include "field_options.hpp"
#include "iso_options.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/translucent.hpp"
#include "foxi/viz/volume.hpp"

namespace foxi::cli {

extern const char* const kCompositeOptionsHelp;

struct CompositeOptions {
  std::string region_opacity;  // --region-opacity REGION=a,... (names resolved against the mesh)
  bool has_iso_opacity = false;
  double iso_opacity = 0.5;         // --iso-opacity
  std::string volume;               // --volume NAME[:C]: the field (handed to the field options)
  std::vector<OpacityPoint> curve;  // --opacity-curve, values in display units
  double opacity_length = 0;        // --opacity-length; 0: a tenth of the drawn box's diagonal
  bool translucent() const { return !region_opacity.empty() || has_iso_opacity; }
  bool volume_on() const { return !volume.empty(); }
};

// Takes the options out of args; call it before take_field_options (--volume NAME becomes --field
// NAME there). UsageError for malformed values, --volume with --field, --volume without
// --opacity-curve (or the reverse).
CompositeOptions take_composite_options(Args& args);

// UsageError for the combinations neither command draws: --iso-opacity without --iso, translucency
// with --threshold, --clip, --slice, --shrink or --markers, --volume with translucency or the iso and
// selection options, a field with translucent regions but no --iso. `shrink`: the picture's.
void check_composite_options(const CompositeOptions& options, const FieldOptions& field,
                             const IsoOptions& iso, double shrink);

// The translucent painter's parameters: the regions' opacities (names looked up in the mesh), their
// colours from `render`, the isosurfaces of `iso` with --iso-opacity. Every opacity given is
// multiplied by `scale` (foxi movie --sweep opacity); UsageError where that leaves [0, 1].
TranslucentParams translucent_params(const CompositeOptions& options, const Mesh& mesh,
                                     const RenderParams& render, const IsoPicture& iso, double scale = 1);

// The volume painter's parameters: the field's colour scale, the opacity curve in SI with its
// opacities multiplied by `scale` (UsageError where one reaches 1), the unit length (--opacity-length,
// or a tenth of the diagonal of the box of `subset`, all tets when empty).
VolumeParams volume_params(const CompositeOptions& options, const Mesh& mesh, const FieldPicture& field,
                           std::span<const std::uint32_t> subset, double scale = 1);

}  // namespace foxi::cli
