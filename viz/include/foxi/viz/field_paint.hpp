// Colouring tets by a field (issue 17): which scalar of a field is drawn (a component, a vector's
// magnitude, a tensor's von Mises stress), its values per tet (flat: at the centroid) or per tet
// corner (graded facets), display units, and the FieldPaint the rasterizer reads
// (RenderParams::field).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"
#include "foxi/viz/colormap.hpp"

namespace foxi {

// Bad field selection (unknown field or component, step out of range): the message says which,
// and what there is.
struct FOXI_API FieldSelectError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// Which scalar of a field: a component index, or a derived quantity.
struct FieldScalar {
  enum class Kind : std::uint8_t { component, magnitude, von_mises, principal } kind = Kind::component;
  std::uint32_t component =
      0;  // Kind::component: the index; Kind::principal: 0 largest, 1 middle, 2 smallest
};

// "NAME" or "NAME:COMPONENT" against the field's component count. COMPONENT: an index 0..n-1;
// x y z (vectors, 3 components); mag (vectors); xx yy zz xy yz xz (symmetric tensors, 6, or full
// ones, 9); vm / von_mises (tensors); p1 p2 p3 (tensors: the principal values, largest first, of the
// symmetric part). Without one: the value of a scalar, the magnitude of a vector,
// the von Mises stress of a tensor. Throws FieldSelectError naming the fields or components there are.
struct FieldChoice {
  const Field* field = nullptr;
  FieldScalar scalar;
  std::string label;  // "temperature", "displacement, magnitude", "stress, von Mises", "stress xy", ...
};
FOXI_API FieldChoice choose_field(const Mesh& mesh, std::string_view spec);

// The scalar at each of the field's entities (nodes or tets) in step `step` (FieldSelectError if
// out of range): SI, NaN where the field has NaN.
FOXI_API std::vector<double> field_scalar_values(const Mesh& mesh, const FieldChoice& choice,
                                                 std::size_t step = 0);

// The scalar at each tet's centroid: a node field's components interpolated linearly (the mean of
// the 4 corners) before taking the scalar; a cell field's own value. Here and below an infinite
// value is NaN (no value: grey, no isosurface, nothing integrated).
FOXI_API std::vector<double> tet_centroid_values(const Mesh& mesh, const FieldChoice& choice,
                                                 std::size_t step = 0);

// The scalar at each tet's 4 corners (4 per tet, in the tet's node order): a node field's value at
// the node; a cell field averaged to the node over the tets of the SAME region only (volume-weighted
// components, then the scalar), so values never blend across a material interface.
FOXI_API std::vector<double> tet_corner_values(const Mesh& mesh, const FieldChoice& choice,
                                               std::size_t step = 0);

// The same for a host's own scalar field (its solver's arrays, no foxi::Field): corner values, 4 per
// tet in the tet's node order, for graded_field_paint, TetIntervals and the IsoPainter.
//   node_corner_values: node_values has 1 value per node; each corner takes its node's value.
//   cell_corner_values: cell_values has 1 value per tet; each corner takes the volume-weighted mean
//   of the tets of the SAME region at its node (as tet_corner_values for a cell field).
// Throws std::invalid_argument when the count does not match the view. (A per-tet colouring needs no
// helper: flat_field_paint takes the host's cell values as they are.)
FOXI_API std::vector<double> node_corner_values(const MeshView& mesh, std::span<const double> node_values);
FOXI_API std::vector<double> cell_corner_values(const MeshView& mesh, std::span<const double> cell_values);
// The scalar at one point of tet `t` with barycentric coordinates bary[0..4) (its corners in the
// tet's node order; foxi::locate_points gives them): a node field's components interpolated linearly
// before taking the scalar (exact for a component of a field linear over the tet), a cell field the
// tet's own value. NaN where a value it uses is NaN. For probes and line plots.
FOXI_API double field_value_in_tet(const Mesh& mesh, const FieldChoice& choice, std::size_t t,
                                   const double bary[4], std::size_t step = 0);

// The deformed shape: moves each node of `mesh` by scale x the 3-component node field `name` (a
// displacement) in step `step` (-1: the last), and drops the mesh's derived data, its certificate
// among them (a deformed mesh is in general no longer Delaunay). Returns the largest distance a node
// moved. Throws FieldSelectError for no such field, one that is not a 3-component node field, a step
// out of range, a non-finite scale or a NaN value (that node would have no place).
FOXI_API double deform_by_field(Mesh& mesh, std::string_view name, double scale, long step = -1);

// Display units: value_display = (value_SI - offset) * factor. "degC" / "°C" from K, "MPa" / "kPa" /
// "GPa" from Pa, "mm" / "um" / "µm" / "nm" from m, "mV" / "kV" from V, "mW" from W; the SI unit
// itself (factor 1). Nothing if `display` does not apply to `si_unit`.
struct DisplayUnit {
  std::string symbol;  // as shown ("°C", "MPa", ...); the SI symbol when no conversion
  double factor = 1, offset = 0;
  double to_display(double si) const { return (si - offset) * factor; }
  double to_si(double shown) const { return shown / factor + offset; }
};
FOXI_API std::optional<DisplayUnit> display_unit(std::string_view si_unit, std::string_view display);
// The unit an engineer reads a field in by default: °C for K, MPa for Pa, µm for m, mV for V (below 1 V
// in magnitude, else V); other units as they are. max_abs: the largest magnitude shown.
FOXI_API DisplayUnit default_display_unit(std::string_view si_unit, double max_abs);

// What the rasterizer needs to colour tets by a field (RenderParams::field). Shading multiplies
// each channel of the colour-map colour by s in [shade_min, 1] (Lambert on the face's normal), so
// hue stays and a pixel's colour, divided by s, is its colour-map entry; mesh edges darken further.
struct FieldPaint {
  ColorScale scale;
  bool graded = false;
  std::vector<std::uint32_t> tet_color;  // flat: each tet's colour (size tet_count)
  // Graded: each tet corner's position on the scale (ColorScale::position, NaN for no value), 4 per
  // tet in the tet's node order; faces interpolate it linearly (perspective-correct) and pick the entry.
  std::vector<float> corner_position;
  double shade_min = 0.75;
};

// Flat: the colour of each tet's value (tet_centroid_values) on `scale`.
FOXI_API FieldPaint flat_field_paint(std::span<const double> tet_values, const ColorScale& scale);
// Graded: corner values (tet_corner_values) placed on `scale`.
FOXI_API FieldPaint graded_field_paint(std::span<const double> corner_values, const ColorScale& scale);

// The finite range of values (min, max); NaN, NaN if none is finite. Log: only positive values.
FOXI_API std::pair<double, double> finite_range(std::span<const double> values, bool positive_only = false);

// The automatic scale of `values` on `map` (foxi render without --range, and the workbench): their
// finite range (log: positive values only); a constant widened around it (1 %, log 50 %, 1 about
// zero) so it shows mid-map; coolwarm over values of both signs made symmetric about 0 (its white
// centre at 0). Nothing when no value qualifies. widened / centred say which rule applied.
struct AutoScale {
  ColorScale scale;
  bool widened = false, centred = false;
};
FOXI_API std::optional<AutoScale> automatic_scale(std::span<const double> values, ColorMapId map,
                                                  bool log = false);

}  // namespace foxi
