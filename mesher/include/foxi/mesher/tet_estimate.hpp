// How many tets a mesh will have, estimated before the mesher starts, so that a command can refuse a
// mesh past a limit (README, "Model limits") instead of running for hours or out of memory.
//
// TetGen's Delaunay refinement under a volume bound V fills a region of volume W with about 2 W / V
// tets (a unit cube: 2.8, 2.2 and 2.0 times W / V for edge targets 0.2, 0.1 and 0.05), and a sizing
// function h with about 2 W / (the regular tet's volume at h); without any size bound the count
// follows the boundary, and is taken as 5 tets per PLC point (a Delaunay tetrahedralization has about
// 6.5 per point). Quality refinement near small features adds more: the estimate is a lower bound of
// sorts, good to a factor of about 2 where sizes rule.
#pragma once

#include <cstddef>
#include <span>

#include "foxi/api.hpp"
#include "foxi/mesher/size_field.hpp"  // RefinementBox
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/model/plc.hpp"

namespace foxi {

// The default limit on the estimate (--max-tets raises it): well above the shipped models' meshes.
inline constexpr double kDefaultMaxTets = 4e6;

// The estimated tet count of meshing `plc` with `params` (its max_volume, the seeds' max_volume and its
// size_field). `region_volume[r - 1]` is the volume (m^3) of region id r where known (a model's part
// volumes); empty: the PLC's bounding box stands for the whole domain, under the global bound.
FOXI_API double estimate_tet_count(const Plc& plc, const MeshParams& params,
                                   std::span<const double> region_volume = {});

// The tets refinement boxes add where the mesher takes them as bounds of their own (CGAL's, not a
// TetGen size field, which estimate_tet_count counts): each box's part of the PLC's bounding box at
// the count per bound volume, the regular tet of the box's edge length. Overlapping boxes count
// twice (an upper estimate).
FOXI_API double estimate_box_tet_count(const Plc& plc, std::span<const RefinementBox> boxes);

}  // namespace foxi
