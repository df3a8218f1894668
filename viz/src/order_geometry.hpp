// Internal to the visibility orders (visibility_order.cpp, mpvo_order.cpp, order_check.cpp): the
// orientation of a face as seen from the eye, and the two-core split of a loop.
#pragma once

#include <algorithm>
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

// Whether a ray from the eye (orthographic: along the view) meets the interiors of both tets x and
// y, which have disjoint interiors: not when a plane through the eye (parallel to the view) has x on
// one side and y on the other. Such a plane, where there is one, can be taken through the eye and
// two vertices of x and y (the separating planes through the eye form a polyhedral cone whose
// extreme rays are tight at two vertices). Exact. Used for the few pairs of a cut cluster's tets
// that share no face (add_separating_planes in spheres.cpp): a separating plane of x and y orders
// them only where some ray meets both.
inline bool rays_meet_both(const View& view, const MeshView& m, std::uint32_t x, std::uint32_t y) {
  const std::uint32_t* tx = m.tet.data() + 4 * std::size_t(x);
  const std::uint32_t* ty = m.tet.data() + 4 * std::size_t(y);
  std::uint32_t u[8];
  int nu = 0;
  for (int c = 0; c < 4; ++c) u[nu++] = tx[c];
  for (int c = 0; c < 4; ++c)
    if (std::find(u, u + nu, ty[c]) == u + nu) u[nu++] = ty[c];
  auto side = [&](std::uint32_t p, std::uint32_t q, std::uint32_t w) {
    if (w == p || w == q) return 0;
    if (view.perspective) return fast_orientation(view.eye, node(m, p), node(m, q), node(m, w));
    return -exact::orientation_at_infinity(node(m, p), node(m, q), node(m, w), view.dir);
  };
  for (int i = 0; i < nu; ++i)
    for (int j = i + 1; j < nu; ++j) {
      int lo_x = 1, hi_x = -1, lo_y = 1, hi_y = -1;
      for (int c = 0; c < 4; ++c) {
        const int sx = side(u[i], u[j], tx[c]), sy = side(u[i], u[j], ty[c]);
        lo_x = std::min(lo_x, sx), hi_x = std::max(hi_x, sx);
        lo_y = std::min(lo_y, sy), hi_y = std::max(hi_y, sy);
      }
      if ((lo_x >= 0 && hi_y <= 0 && (hi_x > 0 || lo_y < 0)) ||
          (hi_x <= 0 && lo_y >= 0 && (lo_x < 0 || hi_y > 0)))
        return false;
    }
  return true;
}

}  // namespace foxi::order_detail
