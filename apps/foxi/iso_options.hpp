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
#include <vector>

#include "cli.hpp"
#include "field_options.hpp"
#include "foxi/model/mesh.hpp"
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

struct IsoPicture {
  std::vector<std::uint32_t> subset;  // the tets to order (empty and `empty` set: none)
  bool empty = false;                 // the subset is empty (an empty vector alone means "all tets")
  bool polygons = false;              // draw with an IsoPainter (iso or slice), not the tet painter alone
  // The painter's level values and colouring attribute, 4 per tet (shared with an IsoCache: a sweep's
  // frames do not copy them).
  std::shared_ptr<const std::vector<double>> corner, attr;
  IsoParams params;
  std::vector<double> iso_si;         // the isovalues, SI (the legend's marks)
  std::size_t crossing = 0;           // tets the isovalues cross (or the slice's plane cuts)
  double query_ms = 0;                // answering the query
  double build_ms = 0;                // building the interval tree (0 when an IsoCache had it)
  // draw_picture's iso input, lending corner and attr (the IsoPicture must outlive it).
  IsoDrawing drawing() const;
};

// What resolve_iso derives from the field alone (corner and centroid values, the interval tree),
// kept between calls for the same field, step and mesh: a sweep of isovalues or threshold ranges
// then costs each frame the query, O(log n + answer), not a pass over the mesh.
struct IsoCache {
  std::shared_ptr<const std::vector<double>> corner;  // tet_corner_values
  std::vector<double> centroid;                       // tet_centroid_values
  std::unique_ptr<TetIntervals> tree;
};

// The tets of `base` (all when empty) that the options select, and the painter's inputs. The field's
// scale colours the polygons; isovalues and the threshold are converted from the display unit.
// `cache`: null, or kept by the caller across calls with the same field choice and step.
IsoPicture resolve_iso(const IsoOptions& options, const Mesh& mesh, const FieldPicture& field,
                       std::span<const std::uint32_t> base, IsoCache* cache = nullptr);

}  // namespace foxi::cli
