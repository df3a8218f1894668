// The depth buffer's rule for a pixel where two faces are at the same depth (issue 17's exact depth
// ties): the painter and the depth buffer must show the same face there.
//
// The rasterizer's top-left fill rule gives a pixel whose centre lies exactly on an edge (or at a
// vertex) to the triangles that cover the point an infinitesimal step right and a smaller one down,
// (x + e, y + e^2) in pixels (y down): it is that sample point the painter shows, and a painter
// drawing in a visibility order leaves there the face nearest at that point. Where two faces meet at
// a pixel centre (a shared edge or vertex: on a structured grid seen along an axis whole pixel
// columns are such), their depths there are equal and "nearest wins" alone leaves the choice to
// rounding or to the draw order. So a tie (equal nearness within rounding) is decided by the
// nearness at the same sample point: the larger x-slope wins, and for equal x-slopes (an edge level
// on the screen) the larger y-slope. The depth buffer keeps each pixel's slopes beside its depth
// (Framebuffer::depth_slope). Used by the tet rasterizer and the isosurface painter.
#pragma once

#include <cmath>
#include <cstddef>

#include "foxi/viz/framebuffer.hpp"

namespace foxi {
namespace raster_detail {

// Nearness values closer than this (relative to the size of the terms that computed them) are equal:
// a plane evaluated at a pixel from different corners is off by a few units of the last place.
constexpr double kDepthTie = 1e-10;

// Gives fb.depth_slope its room (zeros) when the depth buffer lacks it: the depth is what matters
// first, and a pixel's slopes are read only when its depth ties, after a face wrote both.
inline void ensure_depth_slopes(Framebuffer& fb) {
  if (fb.depth_slope.size() != 2 * fb.depth.size()) fb.depth_slope.assign(2 * fb.depth.size(), 0.0);
}

// Depth test of a face at pixel p: nearness z there, slopes za (per pixel in x) and zb (in y), and
// `size` the magnitude of the terms z was summed from (its rounding scale). Writes z and the slopes and
// returns true if the face shows in front of what the pixel holds (see above).
inline bool depth_test(Framebuffer& fb, std::size_t p, double z, double za, double zb, double size) {
  const double held = fb.depth[p];
  const double tol = kDepthTie * size;
  double* slope = &fb.depth_slope[2 * p];
  if (!(z > held + tol)) {
    if (z < held - tol || std::isnan(z)) return false;
    // A tie: the nearer at (x + e, y + e^2).
    const double stol = kDepthTie * (std::abs(za) + std::abs(zb) + std::abs(slope[0]) + std::abs(slope[1]));
    if (za < slope[0] - stol) return false;
    if (!(za > slope[0] + stol) && !(zb > slope[1] + stol)) return false;
  }
  fb.depth[p] = z;
  slope[0] = za;
  slope[1] = zb;
  return true;
}

}  // namespace raster_detail
}  // namespace foxi
