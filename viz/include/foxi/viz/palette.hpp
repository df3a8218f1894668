// Colours and arrangements for pictures of multi-material structures: familiar colours for the
// material library's materials, and an exploded view in which every part shows whole.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

// RGBA (pack_rgba) of a material: familiar colours for the library's materials (copper, silicon,
// solder, FR-4, ...), else region_color(index), entry `index` of the fixed palette.
FOXI_API std::uint32_t material_color(std::string_view name, std::size_t index);

// The mesh with every region's nodes copied and lifted by (region id - 1) * gap in z (region ids
// below 1 stay put), so that stacked parts separate; regions are kept, boundaries and fields are not.
// Not a Delaunay mesh as a whole: draw it with draw_picture (picture.hpp), which uses the depth buffer.
FOXI_API Mesh exploded_mesh(const Mesh& mesh, double gap);

}  // namespace foxi
