// Internal to the mesher: a refined surface PLC handed back to TetGen as triangles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "foxi/model/plc.hpp"

namespace foxi::detail {

// Rewrites every facet that is not a plain triangle (a triangle with points added on its edges or
// inside, by a refinement round) as triangle facets of the same marker: the constrained Delaunay
// triangulation of its vertices, in the plane of its largest projection, bounded by its polygons.
// TetGen 1.5.0 triangulates a facet's polygon itself and asserts when points split one edge twice
// or lie almost on it; three corners it never gets wrong. Returns the number of triangles written.
std::size_t triangulate_facets(Plc& plc);

}  // namespace foxi::detail
