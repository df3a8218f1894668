// The field subset and isosurface options of foxi render (--iso, --iso-only, --threshold, --clip,
// --slice; issue 17 items 3-4): parsed before the mesh is read, resolved after the field into the
// tets to order (the pruned crossing set, the threshold, the clip) and, for iso polygons and slices,
// the IsoPainter's inputs.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "field_options.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/field_selection.hpp"
#include "foxi/viz/field_subset.hpp"
#include "foxi/viz/isosurface.hpp"

namespace foxi::cli {

extern const char* const kIsoOptionsHelp;

struct IsoOptions {
  std::vector<double> iso;  // --iso, display units
  bool iso_only = false;
  bool has_threshold = false;
  double threshold[2] = {0, 0};  // --threshold a,b, display units
  std::optional<Plane> clip, slice;
  bool any() const { return !iso.empty() || has_threshold || clip || slice; }
};

// Takes the options out of args; UsageError for malformed ones or combinations foxi does not draw.
IsoOptions take_iso_options(Args& args, const FieldOptions& field);

// The tets to order and the painter's inputs (field_selection.hpp: the library's rule, SI).
using IsoPicture = TetSelection;
using foxi::IsoCache;

// The tets of `base` (all when empty) that the options select, and the painter's inputs. The field's
// scale colours the polygons; isovalues and the threshold are converted from the display unit.
// `cache`: null, or kept by the caller across calls with the same field choice and step.
IsoPicture resolve_iso(const IsoOptions& options, const Mesh& mesh, const FieldPicture& field,
                       std::span<const std::uint32_t> base, IsoCache* cache = nullptr);

// The isovalues of `iso` (SI) outside the range of the values its isosurfaces are found in (the tets'
// corner values: a node field's node values, a cell field's per-region averages), which therefore
// have no isosurface; returns that range (SI), or nullopt when the field has no finite value.
std::optional<std::pair<double, double>> iso_values_outside(const IsoPicture& iso,
                                                            std::vector<double>& outside);

// Prints a warning line naming the isovalues outside the field's range, and the range, in the field's
// display unit (nothing when all lie inside).
void warn_iso_outside(const IsoPicture& iso, const FieldPicture& field);

}  // namespace foxi::cli
