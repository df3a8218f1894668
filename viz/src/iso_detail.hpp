// Internal to the isosurface files (isosurface.cpp, iso_paint.cpp).
#pragma once

#include <cstdint>

#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"

namespace foxi::iso_detail {

// The point where the linear interpolation of corner values crosses v on the edge between local
// corners i and j of `tet` (one of them >= v, the other not), interpolated from the edge's lower node
// index to its higher one, so every tet sharing the edge gets the same bits; attr (4 values or null)
// interpolated the same way into *attr_out.
void edge_point(const MeshView& mesh, std::uint32_t tet, const double corner[4], double v, int i, int j,
                const double* attr, double xyz[3], double* attr_out);

}  // namespace foxi::iso_detail
