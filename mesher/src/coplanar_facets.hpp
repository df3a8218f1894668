// Internal to the mesher: joining the coplanar pieces of a PLC's facets into one facet each.
//
// A structure built with CGAL's corefinement booleans (a ball grid array: spheres cut by the board
// and the package) comes out as a triangle soup: every plane of the model is tiled by triangles, many
// of them long slivers fanned from the ball footprints to the board's corners. Each triangle is a
// facet, so its three edges are segments TetGen must keep; splitting them for the Delaunay
// certificate then puts points almost on a line, and TetGen 1.5.0's surface recovery fails on them
// (asserts, reports crossing facets, or loops). One facet per plane region, bounded by its outline
// only, lets TetGen triangulate the region as it likes and leaves the slivers' edges out of the PLC.
#pragma once

#include <cstddef>

#include "foxi/model/plc.hpp"

namespace foxi::detail {

struct CoplanarMerge {
  std::size_t facets_before = 0;
  std::size_t facets_after = 0;
  std::size_t groups = 0;          // merged facets made
  std::size_t groups_skipped = 0;  // coplanar groups left as they were (an outline that is not simple loops)
  std::size_t segment_facets_dropped = 0;
};

// Replaces every edge-connected set of single-polygon, hole-free facets that lie in one plane (to
// `relative_tol` of the PLC's extent) and carry one marker by one facet: the set's outline loops (the
// largest the outer boundary, the others holes with a hole point inside each), its inner edges that
// other facets also use (as 2-vertex polygons) and its inner vertices (as 1-vertex polygons). Segment
// facets (only 2-vertex polygons) whose every edge is an edge of some larger polygon are dropped.
// The region the facets cover, and so every boundary tag, is unchanged.
CoplanarMerge merge_coplanar_facets(Plc& plc, double relative_tol = 1e-12);

}  // namespace foxi::detail
