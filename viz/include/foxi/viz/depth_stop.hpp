// The depth stop of the painter (seed paper, section 6.1: stop drawing at a depth): the depth of a
// tet is its power distance from the eye, sqrt(max(0, |eye - c|^2 - r^2)) for its circumsphere
// (c, r), the quantity the back-to-front power order decreases in (Theorem 1), so the tets deeper
// than d are a prefix of the order. Orthographic views: the distance of c in front of the plane
// through the camera's `at` across the view direction, (c - at).dir / |dir| (may be negative).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "foxi/api.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/spheres.hpp"

namespace foxi {

// The depth of tet t (t < table.tet_count()) seen by camera (world units).
FOXI_API double tet_depth(const SphereTable& table, const Camera& camera, std::uint32_t t);

// How many tets of a back-to-front order come before the first one whose depth is below d: drawing
// that many stops at depth d. The whole order if none is.
FOXI_API std::size_t count_deeper(const SphereTable& table, const Camera& camera,
                                  std::span<const std::uint32_t> order, double d);

}  // namespace foxi
