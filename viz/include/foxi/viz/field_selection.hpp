// The tets a field picture draws when it shows isosurfaces, a slice or a subset by the field (issue 17
// items 3-4): the pruned set of tets the isovalues cross (or reach, for the solid above the lowest
// one), narrowed by a threshold on the tets' values and a crinkle clip, and the IsoPainter's inputs.
// One rule for foxi render, foxi movie and a host's interactive view (foxi::qt's ViewWidget), so
// their pictures of the same choice are the same pixels. All values SI.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/colormap.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/field_subset.hpp"
#include "foxi/viz/isosurface.hpp"

namespace foxi {

struct FieldSelection {
  std::vector<double> iso;  // isovalues, SI (empty: none)
  bool iso_only = false;    // the isosurfaces alone, two-sided; otherwise the solid >= the lowest value
  std::optional<std::pair<double, double>> threshold;  // tets whose centroid value lies in [lo, hi], SI
  // slice: the plane's cut through the tets the threshold, the clip and the base keep; not with iso
  // (both are the polygons drawn).
  std::optional<Plane> clip, slice;
  bool any() const { return !iso.empty() || threshold || clip || slice; }
};

struct TetSelection {
  std::vector<std::uint32_t> subset;  // the tets to order (empty and `empty` set: none)
  bool empty = false;                 // the subset is empty (an empty vector alone means "all tets")
  bool polygons = false;              // draw with an IsoPainter (iso or slice), not the tet painter alone
  // The painter's level values and colouring attribute, 4 per tet (shared with an IsoCache: a sweep's
  // frames do not copy them).
  std::shared_ptr<const std::vector<double>> corner, attr;
  IsoParams params;
  std::vector<double> iso_si;  // the isovalues, SI (the legend's marks)
  std::size_t crossing = 0;    // tets the isovalues cross (or the slice's plane cuts)
  double query_ms = 0;         // answering the query
  double build_ms = 0;         // building the interval tree (0 when an IsoCache had it)
  // draw_picture's (and InteractiveView::set_iso's) iso input, lending corner and attr: the
  // TetSelection must outlive it.
  FOXI_API IsoDrawing drawing() const;
};

// What select_field_tets derives from the field alone (corner and centroid values, the interval
// tree), kept between calls for the same field, step and mesh: a sweep of isovalues or threshold
// ranges, or a slider, then costs each call the query, O(log n + answer), not a pass over the mesh.
struct IsoCache {
  std::shared_ptr<const std::vector<double>> corner;  // tet_corner_values
  std::vector<double> centroid;                       // tet_centroid_values
  std::shared_ptr<const TetIntervals> tree;
};

// The cache for `choice` at `step`, filled: corner and centroid values and the interval tree, O(n log n)
// (a host builds it on a worker thread so that a slider's calls cost only their queries).
FOXI_API IsoCache make_iso_cache(const Mesh& mesh, const FieldChoice& choice, std::size_t step);

// The tets of `base` (all when empty) that `selection` selects, and the painter's inputs; `scale`
// colours the polygons. `cache`: null, or kept by the caller across calls with the same field
// choice, step and mesh. Throws std::invalid_argument for a clip or slice plane with a zero normal,
// and for a slice with isovalues.
FOXI_API TetSelection select_field_tets(const FieldSelection& selection, const Mesh& mesh,
                                        const FieldChoice& choice, std::size_t step, const ColorScale& scale,
                                        std::span<const std::uint32_t> base = {}, IsoCache* cache = nullptr);

}  // namespace foxi
