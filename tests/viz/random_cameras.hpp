// Random cameras for the painter tests: perspective eyes outside the mesh (looking at its centre),
// perspective eyes inside its bounding box (looking in a random direction), orthographic directions.
#pragma once

#include <random>
#include <vector>

#include "foxi/viz/camera.hpp"

namespace foxi::test {

inline std::vector<Camera> random_cameras(const Mesh& m, int n, unsigned seed, double aspect) {
  double lo[3], hi[3];
  mesh_bounds(m, lo, hi);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  std::vector<Camera> cams;
  for (int i = 0; i < n; ++i) {
    double d[3] = {g(rng), g(rng), g(rng)}, up[3] = {g(rng), g(rng), g(rng)};
    if (i % 3 == 2) {
      cams.push_back(fit_camera(lo, hi, d, up, false, 30, aspect, 0.9));
      continue;
    }
    Camera c = fit_camera(lo, hi, d, up, true, 20 + 40 * u(rng), aspect, 0.9);
    if (i % 3 == 1) {  // eye inside the box
      for (int k = 0; k < 3; ++k) {
        c.eye[k] = lo[k] + (0.1 + 0.8 * u(rng)) * (hi[k] - lo[k]);
        c.at[k] = c.eye[k] + d[k];
      }
      c.fov_deg = 70;
    }
    cams.push_back(c);
  }
  return cams;
}

}  // namespace foxi::test
