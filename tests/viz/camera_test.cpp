// The camera against hand computations: projections of chosen points, fit-to-bounds, orbit, pan, zoom.
#include "foxi/viz/camera.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace foxi {
namespace {

Camera make(bool perspective, double ex, double ey, double ez, double ux, double uy, double uz) {
  Camera c;
  c.perspective = perspective;
  c.eye[0] = ex;
  c.eye[1] = ey;
  c.eye[2] = ez;
  c.at[0] = c.at[1] = c.at[2] = 0;
  c.up[0] = ux;
  c.up[1] = uy;
  c.up[2] = uz;
  return c;
}

TEST(Camera, PerspectiveProjectionByHand) {
  // Eye on -y looking at the origin, z up, 90 degrees vertical: focal = (100 / 2) / tan(45) = 50.
  Camera c = make(true, 0, -10, 0, 0, 0, 1);
  c.fov_deg = 90;
  Projector p(c, 200, 100);
  EXPECT_NEAR(p.focal, 50, 1e-12);
  const double q[3] = {1, 0, 2};  // right 1, up 2, depth 10
  double px[2], depth = 0;
  ASSERT_TRUE(p.project(q, px, &depth));
  EXPECT_NEAR(depth, 10, 1e-12);
  EXPECT_NEAR(px[0], 100 + 50 * 1.0 / 10, 1e-9);
  EXPECT_NEAR(px[1], 50 - 50 * 2.0 / 10, 1e-9);
  // The point looked at is the image centre; a point behind the eye does not project.
  const double o[3] = {0, 0, 0}, behind[3] = {0, -11, 0};
  ASSERT_TRUE(p.project(o, px));
  EXPECT_NEAR(px[0], 100, 1e-12);
  EXPECT_NEAR(px[1], 50, 1e-12);
  EXPECT_FALSE(p.project(behind, px, &depth));
  EXPECT_NEAR(depth, -1, 1e-12);
}

TEST(Camera, OrthographicProjectionByHand) {
  // Looking down -z with y up: right = +x. Height 4 on 100 pixels: 25 pixels per unit.
  Camera c = make(false, 0, 0, 10, 0, 1, 0);
  c.ortho_height = 4;
  Projector p(c, 100, 100);
  const double q[3] = {1, 1, -3};
  double px[2];
  ASSERT_TRUE(p.project(q, px));
  EXPECT_NEAR(px[0], 75, 1e-12);
  EXPECT_NEAR(px[1], 25, 1e-12);
  View v = view_of(c);
  EXPECT_FALSE(v.perspective);
  EXPECT_DOUBLE_EQ(v.dir[2], -10);
  View w = view_of(make(true, 1, 2, 3, 0, 0, 1));
  EXPECT_TRUE(w.perspective);
  EXPECT_DOUBLE_EQ(w.eye[0], 1);
  EXPECT_DOUBLE_EQ(w.eye[1], 2);
  EXPECT_DOUBLE_EQ(w.eye[2], 3);
}

TEST(Camera, FitPutsEveryCornerInsideTheImage) {
  const double lo[3] = {-1, 2, 0.5}, hi[3] = {3, 2.5, 1.5};
  const double dirs[3][3] = {{-1, 1.6, -0.9}, {0, 0, -1}, {1, 0, 0}};
  const double up[3] = {0, 0, 1};
  for (bool persp : {true, false})
    for (const auto& d : dirs)
      for (int w : {150, 300, 533}) {
        const int h = 300;
        const double aspect = double(w) / h;
        Camera c = fit_camera(lo, hi, d, up, persp, 40, aspect, 0.9);
        Projector p(c, w, h);
        double reach = 0;
        for (int corner = 0; corner < 8; ++corner) {
          double q[3], px[2];
          for (int k = 0; k < 3; ++k) q[k] = (corner >> k) & 1 ? hi[k] : lo[k];
          ASSERT_TRUE(p.project(q, px));
          EXPECT_GE(px[0], 0);
          EXPECT_LE(px[0], w);
          EXPECT_GE(px[1], 0);
          EXPECT_LE(px[1], h);
          reach =
              std::max({reach, std::abs(px[0] - 0.5 * w) / (0.5 * w), std::abs(px[1] - 0.5 * h) / (0.5 * h)});
        }
        EXPECT_GT(reach, 0.85);  // fills the image (0.9 asked; the eye-outside rule may add a little)
        EXPECT_LE(reach, 0.9 + 1e-9);
      }
}

TEST(Camera, OrbitPanZoom) {
  Camera c = make(true, 0, -10, 0, 0, 0, 1);
  Camera o = orbit(c, 90, 0);  // about +z: (0, -10, 0) -> (10, 0, 0)
  EXPECT_NEAR(o.eye[0], 10, 1e-12);
  EXPECT_NEAR(o.eye[1], 0, 1e-12);
  EXPECT_NEAR(o.eye[2], 0, 1e-12);
  Camera p = orbit(c, 0, 30);  // pitch: eye rises on the sphere of radius 10
  EXPECT_NEAR(std::hypot(p.eye[0], p.eye[1], p.eye[2]), 10, 1e-12);
  EXPECT_NEAR(std::abs(p.eye[2]), 10 * std::sin(30 * M_PI / 180), 1e-9);
  Camera back = orbit(orbit(c, 123, 0), 237, 0);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(back.eye[k], c.eye[k], 1e-9);
  Camera z = zoom(c, 2);
  EXPECT_NEAR(z.eye[1], -5, 1e-12);
  Camera oc = make(false, 0, -10, 0, 0, 0, 1);
  oc.ortho_height = 6;
  EXPECT_NEAR(zoom(oc, 3).ortho_height, 2, 1e-12);
  // Pan by half the visible height to the right: visible height at distance 10 with 90 degrees is 20.
  c.fov_deg = 90;
  Camera q = pan(c, 0.5, 0);
  EXPECT_NEAR(q.at[0], 10, 1e-9);
  EXPECT_NEAR(q.eye[0], 10, 1e-9);
  EXPECT_NEAR(q.eye[1], -10, 1e-9);
}

TEST(Camera, DegenerateCamerasAreRejected) {
  Camera c = make(true, 0, 0, 0, 0, 0, 1);  // eye == at
  EXPECT_THROW(Projector(c, 10, 10), std::invalid_argument);
  Camera d = make(true, 0, 0, 5, 0, 0, 1);  // up parallel to the view direction
  EXPECT_THROW(Projector(d, 10, 10), std::invalid_argument);
  Camera e = make(true, 0, -5, 0, 0, 0, 1);
  e.fov_deg = 180;
  EXPECT_THROW(Projector(e, 10, 10), std::invalid_argument);
  EXPECT_THROW(Projector(make(true, 0, -5, 0, 0, 0, 1), 0, 10), std::invalid_argument);
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, zero[3] = {0, 0, 0}, up[3] = {0, 0, 1};
  EXPECT_THROW(fit_camera(lo, hi, zero, up), std::invalid_argument);
}

// Looking straight down (eye above the target) with no --up given: the default +z would be parallel
// to the line of sight, so another axis is taken and the point below the eye projects to the centre;
// an up the user gave is kept and refused by the projector.
TEST(Camera, StraightDownWithoutAnUpIsNotDegenerate) {
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, eye[3] = {0.5, 0.5, 3}, at[3] = {0.5, 0.5, 0.2};
  const Camera c = camera_from_options(lo, hi, 1.0, eye, at, nullptr, 30, nullptr);
  const Projector p(c, 100, 100);
  double s[2];
  const double below[3] = {0.5, 0.5, 0.5};
  ASSERT_TRUE(p.project(below, s));
  EXPECT_NEAR(s[0], 50, 1e-9);
  EXPECT_NEAR(s[1], 50, 1e-9);
  const double up[3] = {0, 0, 1};
  EXPECT_THROW(Projector(camera_from_options(lo, hi, 1.0, eye, at, up, 30, nullptr), 100, 100),
               std::invalid_argument);
}

}  // namespace
}  // namespace foxi
