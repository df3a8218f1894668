// The depth stop against an independent computation: circumspheres solved here from the tets'
// corners (a 3x3 linear system, not the sphere table), power distances from the eye, and the
// position of the first tet nearer than d in the visibility order; the order decreases in depth.
#include "foxi/viz/depth_stop.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "foxi/viz/visibility_order.hpp"
#include "mesh_factory.hpp"
#include "random_cameras.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

// Circumcentre and squared radius of tet t by Cramer's rule on 2 (p_i - p_0).x = |p_i|^2 - |p_0|^2.
void circumsphere(const Mesh& m, std::size_t t, double c[3], double* r2) {
  const double* p[4];
  for (int k = 0; k < 4; ++k) p[k] = &m.xyz[3 * std::size_t(m.tet[4 * t + std::size_t(k)])];
  double a[3][3], b[3];
  for (int i = 0; i < 3; ++i) {
    double s = 0;
    for (int k = 0; k < 3; ++k) {
      const double e = p[i + 1][k] - p[0][k];
      a[i][k] = 2 * e;
      s += e * e;
    }
    b[i] = s;  // relative to p0: 2 e.x' = |e|^2 with x' = x - p0
  }
  auto det = [](const double m3[3][3]) {
    return m3[0][0] * (m3[1][1] * m3[2][2] - m3[1][2] * m3[2][1]) -
           m3[0][1] * (m3[1][0] * m3[2][2] - m3[1][2] * m3[2][0]) +
           m3[0][2] * (m3[1][0] * m3[2][1] - m3[1][1] * m3[2][0]);
  };
  const double d = det(a);
  double x[3];
  for (int k = 0; k < 3; ++k) {
    double ak[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ak[i][j] = j == k ? b[i] : a[i][j];
    x[k] = det(ak) / d;
  }
  *r2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
  for (int k = 0; k < 3; ++k) c[k] = p[0][k] + x[k];
}

TEST(DepthStop, PowerDistanceMatchesCircumspheresAndOrderDecreasesInIt) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 700, 83);
  const SphereTable table = compute_spheres(m);
  for (const Camera& cam : test::random_cameras(m, 9, 89, 4.0 / 3)) {
    const auto order = visibility_order(m, table, view_of(cam));
    std::vector<double> depth(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      double c[3], r2;
      circumsphere(m, order[i], c, &r2);
      double v;
      if (cam.perspective) {
        double pw = -r2;
        for (int k = 0; k < 3; ++k) pw += (cam.eye[k] - c[k]) * (cam.eye[k] - c[k]);
        v = std::sqrt(std::max(0.0, pw));
      } else {
        double dir3[3], len = 0, along = 0;
        for (int k = 0; k < 3; ++k) {
          dir3[k] = cam.at[k] - cam.eye[k];
          len += dir3[k] * dir3[k];
        }
        for (int k = 0; k < 3; ++k) along += (c[k] - cam.at[k]) * dir3[k];
        v = along / std::sqrt(len);
      }
      depth[i] = v;
      EXPECT_NEAR(tet_depth(table, cam, order[i]), v, 1e-6 * (1 + std::abs(v)));
      if (i > 0) {
        EXPECT_LE(depth[i], depth[i - 1] + 1e-6) << "the order must not get deeper";
      }
    }
    // Stops at depths across the range: the first tet nearer than d, from the independent depths.
    std::vector<double> sorted = depth;
    std::sort(sorted.begin(), sorted.end());
    for (double q : {0.1, 0.5, 0.9}) {
      const double d = sorted[std::size_t(q * double(sorted.size()))] + 1e-7;
      const std::size_t expect = std::size_t(
          std::find_if(depth.begin(), depth.end(), [&](double v) { return v < d; }) - depth.begin());
      const std::size_t got = count_deeper(table, cam, order, d);
      EXPECT_NEAR(double(got), double(expect), 1.0);
      EXPECT_GT(got, 0u);
      EXPECT_LT(got, order.size());
    }
    EXPECT_EQ(count_deeper(table, cam, order, -1e300), order.size());
    EXPECT_EQ(count_deeper(table, cam, order, 1e300), 0u);
  }
}

}  // namespace
}  // namespace foxi
