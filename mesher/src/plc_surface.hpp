// Internal to foxi_mesher: a PLC's facets as triangles, and the cell (connected component of space
// minus the facets) on each side of every triangle. This is what a surface mesher that takes closed or
// two-sided surfaces (CGAL's polyhedral-complex domain) needs and TetGen computes for itself.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "foxi/model/plc.hpp"

namespace foxi::detail {

struct PlcSurface {
  std::vector<double> points;            // 3 per point: the PLC's points, duplicates merged
  std::vector<std::uint32_t> tri;        // 3 per triangle; each facet's triangles share one orientation
  std::vector<std::uint32_t> tri_facet;  // the PLC facet of each triangle
  // The cell on each side of each triangle: side_cell[2 t] on the side its normal (right hand rule)
  // points to, side_cell[2 t + 1] behind it. Cell kOutside is the unbounded one and every cell holding
  // a volume hole point.
  std::vector<std::uint32_t> side_cell;
  std::size_t cell_count = 0;           // cells 0 .. cell_count-1, kOutside included
  std::size_t facets_without_area = 0;  // facets of only segments, points or collinear polygons: left out
  // The region id of each cell (from the first region seed inside it; 0 for an enclosed cell with no
  // seed, and for kOutside).
  std::vector<std::int32_t> cell_region;
  static constexpr std::uint32_t kOutside = 0;
};

// Triangulates every facet (polygons, segments and points inside it are constraints; parts enclosed by
// no polygon and parts reachable from a facet hole point without crossing a constraint are left out),
// after splitting polygon edges at PLC points lying on them (T-junctions between facets), then finds the
// cells. Facets with no area (only segments or points, as the structure builder and TetGen's .poly
// allow, or collinear polygons) are left out and counted. Throws MesherError (code 10) naming the
// facet or seed on a PLC it cannot read: a facet with crossing edges, no facet with an area, a region
// seed outside every closed surface or on a facet.
PlcSurface plc_surface(const Plc& plc);

}  // namespace foxi::detail
