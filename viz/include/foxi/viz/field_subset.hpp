// Subsets of the tets by a field or a plane (issue 17 item 4), each drawn through the ordering
// engine's subset mode (ProgressiveOrder with the subset, then the tet painter), so they stay
// progressive and undrawable: a threshold (tets whose value lies in a range), a crinkle clip (whole
// tets on one side of a plane), and the level field of a planar slice (drawn by IsoPainter at 0,
// coloured by the field).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

// A plane through p with normal n (any length > 0): "px,py,pz,nx,ny,nz" on the command line.
struct Plane {
  double p[3] = {0, 0, 0};
  double n[3] = {0, 0, 1};
  // n . (x - p): positive on the side n points to.
  double signed_distance(const double x[3]) const {
    return n[0] * (x[0] - p[0]) + n[1] * (x[1] - p[1]) + n[2] * (x[2] - p[2]);
  }
};

// Threshold: the tets whose value (one per tet: tet_centroid_values, a cell field's own value) lies in
// [lo, hi], ascending; NaN values never do.
FOXI_API std::vector<std::uint32_t> threshold_tets(std::span<const double> tet_values, double lo, double hi);

// Crinkle clip: the tets whose centroid lies on the side the normal points away from (n . (c - p) <= 0;
// the normal points to the part cut away, as ParaView's clip keeps the inside), whole, ascending. With
// a subset, only its tets are considered (the clip of a threshold, ...), in its order. Throws
// std::invalid_argument for a zero or non-finite normal.
FOXI_API std::vector<std::uint32_t> clip_tets(const Mesh& mesh, const Plane& plane,
                                              std::span<const std::uint32_t> subset = {});

// The plane's signed distance at each tet corner (4 per tet, tet node order): the level field of the
// slice, whose polygons at 0 (IsoPainter, values {0}, attr the field's corner values, cold_side 1) are
// the slice coloured by the field; TetIntervals or crossing_scan on it gives the tets the plane cuts.
FOXI_API std::vector<double> plane_corner_values(const Mesh& mesh, const Plane& plane);

}  // namespace foxi
