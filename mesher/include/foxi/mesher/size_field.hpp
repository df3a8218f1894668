// Size control (issue 6, item 4): a target edge length everywhere, per region, in refinement boxes,
// and from the error of a solved field.
//
// TetGen takes sizes two ways, and foxi uses both: a maximum tet volume per region (-a with region
// attributes; edge h -> the regular tet's volume h^3 / (6 sqrt 2)), and a sizing function sampled at
// the nodes of a background tet mesh (-m; TetGen interpolates linearly inside the background tets and
// refines until edges are about that long). Boxes and solved fields become background meshes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/plc.hpp"

namespace foxi {

// A sizing function: target edge length (m) at the nodes of a tet mesh, linear inside each tet.
struct SizeField {
  std::vector<double> xyz;         // 3 per node
  std::vector<std::uint32_t> tet;  // 4 per tet
  std::vector<double> size;        // 1 per node, > 0
  bool empty() const { return size.empty(); }
};

struct RefinementBox {
  double lo[3] = {0, 0, 0};
  double hi[3] = {0, 0, 0};
  double size = 0;  // target edge length inside (m)
};

struct SizeControls {
  double max_size = 0;                   // global target edge length (m); 0: none
  std::vector<std::int32_t> region_ids;  // per-region target edge lengths: region_ids[i] gets
  std::vector<double> region_sizes;      //   region_sizes[i] (m)
  std::vector<RefinementBox> boxes;
};

// The volume of the regular tet with edge h: what TetGen's -a needs for a target edge length.
FOXI_API double regular_tet_volume(double edge);
// The circumradius of the regular tet of volume v (CGAL bounds cell sizes by circumradius):
// edge a = (6 sqrt2 v)^(1/3), R = a sqrt6 / 4.
FOXI_API double regular_tet_circumradius(double volume);

// `plc` with each region seed's max_volume set from controls.region_sizes (the smaller of its own and
// the control). Throws MesherError(10) naming a region id that has no seed in the PLC.
FOXI_API Plc with_region_sizes(const Plc& plc, const SizeControls& controls);

// Samples the box sizes (and the global size) at the nodes of `background`: a node at distance d from
// a box (0 inside it) takes that box's size + d, and the smallest of those and the global size. So
// the size grows by one length unit per unit of distance from a box, and the nodes around a box
// narrower than the background's tets still lower the sizes there. With no global size, the
// background's largest edge length bounds the sizes.
FOXI_API SizeField size_field_from_boxes(const Mesh& background, const SizeControls& controls);

struct MeshParams;

// The boxes (and the global size) as a sizing function over the PLC's domain: meshes `plc` with
// `params` (no size field), samples the sizes at its nodes, and repeats with that field `passes - 1`
// more times, and more (8 meshes at most) until every box holds a node of the mesh: a box smaller
// than the first mesh's tets gets nodes inside, and its size there.
FOXI_API SizeField box_size_field(const Plc& plc, const MeshParams& params, const SizeControls& controls,
                                  int passes = 2);

// A Zienkiewicz-Zhu error indicator of a P1 node field (scalar, first component, step 0): the
// recovered gradient at each node is the volume-weighted mean of the gradients of the tets around it;
// a tet's error is the L2 norm over the tet of (recovered gradient, linear) - (tet gradient,
// constant), estimated from the recovered gradient at the tet's centroid: |G*(c) - grad_T| sqrt(|T|).
// A tet with a node of no value (NaN, e.g. an imported field outside its source mesh) is left out
// of the recovery and the norms; its error is NaN, and counted.
struct ErrorIndicator {
  std::vector<double> tet_error;  // 1 per tet (NaN: no value)
  double total_error = 0;         // sqrt of the sum of squares
  double gradient_norm = 0;       // || grad u ||_L2 over the mesh
  std::size_t tets_without_value = 0;
  double relative_error() const { return gradient_norm > 0 ? total_error / gradient_norm : 0; }
};
FOXI_API ErrorIndicator zz_error_indicator(const Mesh& mesh, const Field& field);

// Target sizes for a relative error `target_error` (total_error / gradient_norm), spread evenly over
// the tets (each gets target_error * gradient_norm / sqrt(tet count)): a tet's size h (its longest
// edge) becomes h * (target / error)^(1/1), for P1 elements (the gradient error goes as h), clamped
// to [h / 4, 2 h] and to [min_size, max_size] when those are > 0; a tet without a value keeps h; a
// node takes the smallest size among its tets. The mesh itself is the background mesh. Throws
// MesherError(10) if the field is not a node field of this mesh, has no value on any tet, or
// target_error <= 0.
FOXI_API SizeField size_field_from_error(const Mesh& mesh, const Field& field, double target_error,
                                         double min_size = 0, double max_size = 0);

}  // namespace foxi
