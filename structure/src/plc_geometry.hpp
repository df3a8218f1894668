// Geometry of PLC facets shared by the structure's consumers (surfaces.cpp, diagnostics.cpp).
#pragma once

#include <cmath>
#include <cstdint>

#include "foxi/model/plc.hpp"

namespace foxi {

// Newell's normal of polygon p of `plc` (any planar polygon): its length is twice the area.
inline void polygon_normal(const Plc& plc, std::uint32_t p, double n[3]) {
  n[0] = n[1] = n[2] = 0;
  const std::uint32_t b = plc.polygon_vertex_begin[p], e = plc.polygon_vertex_begin[p + 1];
  for (std::uint32_t i = b; i < e; ++i) {
    const double* u = &plc.points[3 * std::size_t{plc.polygon_vertices[i]}];
    const double* v = &plc.points[3 * std::size_t{plc.polygon_vertices[i + 1 < e ? i + 1 : b]}];
    n[0] += (u[1] - v[1]) * (u[2] + v[2]);
    n[1] += (u[2] - v[2]) * (u[0] + v[0]);
    n[2] += (u[0] - v[0]) * (u[1] + v[1]);
  }
}

}  // namespace foxi
