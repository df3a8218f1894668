// Internal to the visibility orders (visibility_order.cpp, mpvo_order.cpp, order_check.cpp): the
// orientation of a face as seen from the eye, and the two-core split of a loop.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "exact.hpp"
#include "foxi/model/parallel.hpp"
#include "foxi/viz/visibility_order.hpp"

namespace foxi::order_detail {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Face f of a positively oriented tet, listed so that the tet's own vertex f is on its negative side.
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// f(begin, end, part) on the two halves of [0, n), one per core (serial below 50000 items).
template <class F>
void parallel_for(std::size_t n, F f) {
  detail::parallel_for(n, 2, f, 50000);
}

inline const double* node(const MeshView& m, std::uint32_t v) { return m.xyz.data() + 3 * std::size_t(v); }

// +1: the eye is on the positive side of triangle (a, b, c); -1 negative; 0 on its plane.
// orient3d(a, b, c, p) in double with Shewchuk's error bound; the exact predicate when in doubt.
inline int fast_orientation(const double* a, const double* b, const double* c, const double* p) {
  const double adx = a[0] - p[0], bdx = b[0] - p[0], cdx = c[0] - p[0];
  const double ady = a[1] - p[1], bdy = b[1] - p[1], cdy = c[1] - p[1];
  const double adz = a[2] - p[2], bdz = b[2] - p[2], cdz = c[2] - p[2];
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * std::abs(adz) +
                           (std::abs(cdxady) + std::abs(adxcdy)) * std::abs(bdz) +
                           (std::abs(adxbdy) + std::abs(bdxady)) * std::abs(cdz);
  const double bound = (7.0 * kEps / 2 + 56.0 * kEps * kEps / 4) * permanent;  // o3derrboundA
  // Shewchuk's orient3d is positive when p is below (a, b, c); ours is det[b-a, c-a, p-a].
  if (det > bound) return -1;
  if (-det > bound) return 1;
  return exact::orientation(a, b, c, p);
}

inline int eye_side(const View& view, const double* a, const double* b, const double* c) {
  if (view.perspective) return fast_orientation(a, b, c, view.eye);
  const double back[3] = {-view.dir[0], -view.dir[1], -view.dir[2]};
  return exact::orientation_at_infinity(a, b, c, back);
}

}  // namespace foxi::order_detail
