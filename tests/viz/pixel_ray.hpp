// The ray-cast references of the painter tests: the camera-frame ray through a pixel's centre.
#pragma once

#include "foxi/viz/camera.hpp"

namespace foxi::test {

// The camera-frame ray of pixel centre (x, y): origin o + s dir (perspective: o = 0).
inline void pixel_ray(const Projector& p, int x, int y, double o[3], double d[3]) {
  // camera_to_pixel is affine in (c0/c2, c1/c2) (perspective) or (c0, c1) (orthographic): invert it
  // from three samples.
  double p0[2], px[2], py[2];
  const double c0[3] = {0, 0, 1}, cx[3] = {1, 0, 1}, cy[3] = {0, 1, 1};
  p.camera_to_pixel(c0, p0);
  p.camera_to_pixel(cx, px);
  p.camera_to_pixel(cy, py);
  const double a11 = px[0] - p0[0], a12 = py[0] - p0[0], a21 = px[1] - p0[1], a22 = py[1] - p0[1];
  const double det = a11 * a22 - a12 * a21, bx = x + 0.5 - p0[0], by = y + 0.5 - p0[1];
  const double a = (bx * a22 - a12 * by) / det, b = (a11 * by - a21 * bx) / det;
  if (p.perspective) {
    o[0] = o[1] = o[2] = 0;
    d[0] = a, d[1] = b, d[2] = 1;
  } else {
    o[0] = a, o[1] = b, o[2] = 0;
    d[0] = d[1] = 0, d[2] = 1;
  }
}

}  // namespace foxi::test
