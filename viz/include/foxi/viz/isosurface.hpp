// Isosurfaces of a field over the tets (issue 17 item 3; seed paper, section 6.3: "instead of
// rendering the tetrahedron itself, simply render the behavior of the field over the tetrahedron"):
// marching tetrahedra on the linear interpolation of 4 corner values per tet, an interval structure
// that finds the tets a value crosses in time proportional to their number (plus log n), so only
// those are ordered and drawn, and a painter that draws each tet's iso polygon at that tet's place in
// the visibility order, both sides coloured apart (the hot side in the isovalue's colour, the cold
// side darker, as in the paper's Figure 6).
//
// Crossing rule: corner values >= v are "hot". Tet t crosses v when some corner is hot and some is not:
// min < v <= max over its 4 corners (half-open, so a value equal to a node's value is placed
// consistently). A tet with a NaN corner crosses nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/colormap.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/rasterizer.hpp"

namespace foxi {

// The iso polygon of one tet: 0 (no crossing), 3 or 4 vertices in cyclic order. Each vertex lies on
// an edge of the tet, at the linear interpolation of its two corners' values, computed from the edge's
// lower node index to its higher one so that the tets sharing the edge get the same bits (no cracks).
struct IsoPolygon {
  int count = 0;
  double xyz[4][3] = {};
  double attr[4] = {};  // an attribute interpolated the same way (iso_polygon's attr), else 0
  double hot[3] = {};   // unit normal of the polygon's plane, toward increasing value (0 if degenerate)
};

// corner: the tet's 4 corner values (in the tet's node order); attr: 4 more values to interpolate at the
// polygon's vertices (or null). A tet whose corners are all equal, or with a NaN corner, has none.
FOXI_API IsoPolygon iso_polygon(const MeshView& mesh, std::uint32_t tet, const double corner[4], double v,
                                const double* attr = nullptr);

// Tets a value crosses, answered from a centred interval tree over each tet's (min, max] of its corner
// values (Edelsbrunner's interval tree, flattened): a query visits O(log n) nodes and reads only the
// intervals it reports, plus one per node visited. Build O(n log n); 24 bytes a tet.
class FOXI_API TetIntervals {
 public:
  TetIntervals() = default;
  // corner_values: 4 per tet (tet_corner_values), lent only during construction.
  explicit TetIntervals(std::span<const double> corner_values);

  // Appends to `out` the tets that cross v (min < v <= max), in no particular order.
  void crossing(double v, std::vector<std::uint32_t>& out) const;
  // Appends the tets that cross at least one of `values`, each once, in no particular order.
  void crossing_any(std::span<const double> values, std::vector<std::uint32_t>& out) const;
  // Appends the tets with some corner >= v (max >= v, no NaN corner): the threshold subset T >= v
  // whose cut face is the isosurface at v. From the tets sorted by max: O(log n + answer).
  void reaching(double v, std::vector<std::uint32_t>& out) const;
  std::size_t tet_count() const { return tet_count_; }

 private:
  struct Node {
    double centre;
    std::uint32_t begin, end;   // its intervals in by_min_ / by_max_
    std::uint32_t left, right;  // child node indices, kNone if none
  };
  struct Entry {
    double key;
    std::uint32_t tet;
  };
  std::size_t tet_count_ = 0;
  std::vector<Node> nodes_;
  std::vector<Entry> by_min_;      // per node: its intervals by increasing min
  std::vector<Entry> by_max_;      // per node: the same intervals by decreasing max
  std::vector<Entry> max_sorted_;  // all finite tets by increasing max (reaching())
};

// The tets crossing v by a scan of all tets (the same rule): the oracle and the baseline of TetIntervals.
FOXI_API std::vector<std::uint32_t> crossing_scan(std::span<const double> corner_values, double v);

// How iso polygons are drawn.
struct IsoParams {
  std::vector<double> values;  // the isovalues (SI), any order
  // Each isovalue's colour is scale.color(v); with an attribute (IsoPainter's attr) the polygon is
  // coloured per pixel by the attribute's position on the scale instead (a slice coloured by a field).
  ColorScale scale;
  double shade_min = 0.75;  // Lambert shading keeps the colour's hue, lightness in [shade_min, 1]
  // Two-sided colouring: the side facing increasing values (hot) shows the colour, the other side
  // the colour times cold_side (darker; 1 = both sides alike, as a slice wants).
  double cold_side = 0.55;
  // Cap mode: draw the threshold subset T >= min(values) as a solid, the tets entirely above it whole
  // (through the tet painter, RenderParams as given to IsoPainter) and the tets it cuts as the part
  // of the tet above it: the cut face (the iso polygon in the isovalue's colour, the field's value
  // there) and the tet's faces clipped to it, coloured per pixel by the field on `scale`, their parts
  // of mesh edges darkened as the whole tets' edges are (RenderParams edges, edge_width,
  // edge_darkness; the cut's own outline is no mesh edge). The higher isovalues lie inside the solid
  // and are not drawn.
  bool cap = false;
};

// Draws iso polygons (and in cap mode the solid above the lowest value) tet by tet, in the order given:
// with a visibility order (ProgressiveOrder of the crossing or reaching tets), each polygon is drawn at
// its tet's place, so the picture is right without a depth buffer, and the order may be handed over in
// batches (progressive; stop at any batch). The polygons of one tet are drawn far to near. RenderParams:
// depth_buffer switches to the depth-buffer mode (the test oracle: nearest wins; fb needs a depth
// buffer); the rest is for the whole tets of cap mode. Polygons are drawn on the calling thread. Polygons are
// clipped at the near plane. Each pixel's id is the tet whose polygon it shows. Undoable
// (RenderParams::undoable, painter mode only): undraw(fb, k) takes back the last k tets handed to draw(),
// leaving fb pixel for pixel as it was before they were drawn (fb must not be changed in between); each tet
// drawn here keeps the pixels its polygons overwrote (12 bytes a pixel write), the whole tets of cap mode are
// undrawn by the tet painter's own undo. The mesh and the value spans are lent and must outlive it.
class FOXI_API IsoPainter {
 public:
  // corner: 4 values per tet of the field the isovalues apply to; attr: 4 per tet colouring the
  // polygons instead (empty: by isovalue). Throws std::invalid_argument for sizes that do not match.
  IsoPainter(const MeshView& mesh, const Camera& camera, int width, int height,
             std::span<const double> corner, const IsoParams& params, const RenderParams& tet_params = {},
             std::span<const double> attr = {});
  ~IsoPainter();
  IsoPainter(IsoPainter&&) noexcept;
  IsoPainter& operator=(IsoPainter&&) noexcept;

  void draw(Framebuffer& fb, std::span<const std::uint32_t> tets);
  // Undoable: takes back the last `count` tets handed to draw() (std::logic_error if not undoable,
  // std::out_of_range if more than drawn_tets()).
  void undraw(Framebuffer& fb, std::size_t count);
  std::size_t drawn_tets() const;  // tets handed to draw() and not undrawn
  std::size_t polygons_drawn() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// What draw_picture (picture.hpp) needs to draw iso polygons or a slice instead of whole tets: the
// IsoPainter's inputs (the spans lent).
struct IsoDrawing {
  std::span<const double> corner, attr;
  IsoParams params;
};

}  // namespace foxi
