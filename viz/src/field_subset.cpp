#include "foxi/viz/field_subset.hpp"

#include <cmath>
#include <stdexcept>

namespace foxi {

std::vector<std::uint32_t> threshold_tets(std::span<const double> tet_values, double lo, double hi) {
  std::vector<std::uint32_t> out;
  for (std::size_t t = 0; t < tet_values.size(); ++t)
    if (tet_values[t] >= lo && tet_values[t] <= hi) out.push_back(std::uint32_t(t));
  return out;
}

namespace {
void check_plane(const Plane& plane) {
  const double n2 = plane.n[0] * plane.n[0] + plane.n[1] * plane.n[1] + plane.n[2] * plane.n[2];
  if (!(n2 > 0) || !std::isfinite(n2) || !std::isfinite(plane.p[0] + plane.p[1] + plane.p[2]))
    throw std::invalid_argument("plane: the normal must be finite and non-zero, the point finite");
}
}  // namespace

std::vector<std::uint32_t> clip_tets(const Mesh& mesh, const Plane& plane,
                                     std::span<const std::uint32_t> subset) {
  check_plane(plane);
  std::vector<std::uint32_t> out;
  auto keep = [&](std::uint32_t t) {
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j)
        c[j] +=
            0.25 * mesh.xyz[3 * std::size_t(mesh.tet[4 * std::size_t(t) + std::size_t(k)]) + std::size_t(j)];
    if (plane.signed_distance(c) <= 0) out.push_back(t);
  };
  if (subset.empty()) {
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) keep(std::uint32_t(t));
  } else {
    for (std::uint32_t t : subset) keep(t);
  }
  return out;
}

std::vector<double> plane_corner_values(const Mesh& mesh, const Plane& plane) {
  check_plane(plane);
  std::vector<double> out(mesh.tet.size());
  for (std::size_t i = 0; i < mesh.tet.size(); ++i)
    out[i] = plane.signed_distance(&mesh.xyz[3 * std::size_t(mesh.tet[i])]);
  return out;
}

}  // namespace foxi
