#include "foxi/viz/depth_stop.hpp"

#include <algorithm>
#include <cmath>

namespace foxi {

double tet_depth(const SphereTable& table, const Camera& camera, std::uint32_t t) {
  const double* c = &table.c[3 * std::size_t(t)];
  if (camera.perspective) {
    // Power of the eye (local frame): |p|^2 - 2 c.p + s, with s = |c|^2 - r^2.
    double p2 = 0, cp = 0;
    for (int k = 0; k < 3; ++k) {
      const double p = camera.eye[k] - table.origin[k];
      p2 += p * p;
      cp += c[k] * p;
    }
    return std::sqrt(std::max(0.0, p2 - 2 * cp + table.s[t]));
  }
  double along = 0, len2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = camera.at[k] - camera.eye[k];
    along += (c[k] + table.origin[k] - camera.at[k]) * d;
    len2 += d * d;
  }
  return len2 > 0 ? along / std::sqrt(len2) : 0;
}

std::size_t count_deeper(const SphereTable& table, const Camera& camera, std::span<const std::uint32_t> order,
                         double d) {
  for (std::size_t i = 0; i < order.size(); ++i)
    if (tet_depth(table, camera, order[i]) < d) return i;
  return order.size();
}

}  // namespace foxi
