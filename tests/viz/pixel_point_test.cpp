// pixel_point_in_tet (camera.hpp), what foxi-view's status line reads under the mouse: on a box mesh
// drawn by draw_picture, the point each covered pixel shows of the tet in the id buffer, and the
// field value there (field_value_in_tet), against the ray through the pixel's centre intersected with
// the box analytically (slab method) and a linear field evaluated at that point.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "foxi/viz/camera.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/spheres.hpp"
#include "viz/mesh_factory.hpp"
#include "viz/pixel_ray.hpp"
#include "viz/random_cameras.hpp"

namespace foxi {
namespace {

double linear(const double p[3]) { return 5 + 2 * p[0] + 3 * p[1] - p[2]; }

// The ray through the centre of pixel (x, y) in world coordinates: origin o, direction d.
void world_ray(const Projector& proj, int x, int y, double o[3], double d[3]) {
  double oc[3], dc[3];
  test::pixel_ray(proj, x, y, oc, dc);
  for (int k = 0; k < 3; ++k) {
    o[k] = proj.eye[k] + proj.right[k] * oc[0] + proj.up[k] * oc[1] + proj.forward[k] * oc[2];
    d[k] = proj.right[k] * dc[0] + proj.up[k] * dc[1] + proj.forward[k] * dc[2];
  }
}

TEST(PixelPoint, ThePointAndValueUnderAPixelAreWhereItsRayEntersTheBox) {
  Mesh mesh = test::grid_mesh(4, 3, 2, 1, 1, 1, 6);  // the box [0,4] x [0,3] x [0,2]
  Field t{"t", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < mesh.node_count(); ++n) t.values.push_back(linear(&mesh.xyz[3 * n]));
  mesh.fields = {t};
  const FieldChoice choice = choose_field(mesh, "t");
  const double lo[3] = {0, 0, 0}, hi[3] = {4, 3, 2};
  const SphereTable table = compute_spheres(mesh);
  const int w = 120, h = 90;
  std::size_t checked = 0, inexact = 0;
  const std::vector<Camera> cams = test::random_cameras(mesh, 9, 17, double(w) / h);
  for (std::size_t c = 0; c < cams.size(); ++c) {
    if (c % 3 == 1) continue;  // eyes inside the box: the ray starts inside, no entry to compare
    Framebuffer fb(w, h);
    draw_picture(mesh, table, cams[c], fb);
    const Projector proj(cams[c], w, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::uint32_t tet = fb.id[fb.index(x, y)];
        if (tet == kNone) continue;
        // The oracle: the world ray of the pixel's centre, entering the box at s_in.
        double o[3], d[3];
        world_ray(proj, x, y, o, d);
        double s_in = proj.perspective ? 0 : -std::numeric_limits<double>::infinity();
        double s_out = std::numeric_limits<double>::infinity();
        for (int k = 0; k < 3; ++k) {
          if (d[k] == 0) continue;
          const double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
          s_in = std::max(s_in, std::min(a, b));
          s_out = std::min(s_out, std::max(a, b));
        }
        ASSERT_LE(s_in, s_out + 1e-9)
            << "pixel " << x << "," << y << " shows a tet but its ray misses the box";
        const double want[3] = {o[0] + s_in * d[0], o[1] + s_in * d[1], o[2] + s_in * d[2]};
        double b[4];
        ASSERT_TRUE(pixel_point_in_tet(mesh, cams[c], w, h, tet, x, y, b)) << x << "," << y;
        double got[3] = {0, 0, 0};
        for (int i = 0; i < 4; ++i)
          for (int k = 0; k < 3; ++k)
            got[k] += b[i] * mesh.xyz[3 * std::size_t(mesh.tet[4 * tet + std::size_t(i)]) + std::size_t(k)];
        // Exact to rounding, but for pixel centres the rasterizer (in floats) gives to a tet they lie a
        // hair outside of: clamped onto the tet, within a small part of a pixel (about 0.03 here).
        const double err = std::hypot(got[0] - want[0], got[1] - want[1], got[2] - want[2]);
        EXPECT_LT(err, 3e-3) << "camera " << c << " pixel " << x << "," << y;
        inexact += err > 1e-9;
        const double v = field_value_in_tet(mesh, choice, tet, b);
        EXPECT_NEAR(v, linear(got), 1e-9) << "the value at the point shown";
        if (err <= 1e-9) {
          EXPECT_NEAR(v, linear(want), 1e-8) << "camera " << c;
        }
        ++checked;
      }
  }
  EXPECT_GT(checked, 5000u);
  EXPECT_LT(double(inexact), 0.005 * double(checked)) << inexact << " of " << checked << " clamped";
  // Outside the image, a tet the ray runs away from, a bad tet index: no point.
  double b[4];
  EXPECT_FALSE(pixel_point_in_tet(mesh, cams[0], w, h, std::uint32_t(mesh.tet_count()), 0, 0, b));
}

// With --shrink (issue 17 item 2) a pixel shows a tet scaled about its centroid: the point it shows
// is where the pixel's ray meets the shrunk tet, and the value its colour shows is the field's at the
// true point that maps there. Oracle per covered pixel: the reported point p lies in the tet (its
// barycentric coordinates), p shrunk about the centroid lies on the pixel's ray (test::pixel_ray, to
// rounding), and the value is the linear field's at p. Without the shrink factor the point is off
// the ray for most pixels (what the viewer's status line showed).
TEST(PixelPoint, ShrunkTetsShowTheTruePointUnderAPixel) {
  Mesh mesh = test::grid_mesh(4, 3, 2, 1, 1, 1, 6);
  Field t{"t", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < mesh.node_count(); ++n) t.values.push_back(linear(&mesh.xyz[3 * n]));
  mesh.fields = {t};
  const FieldChoice choice = choose_field(mesh, "t");
  const SphereTable table = compute_spheres(mesh);
  const int w = 120, h = 90;
  const double f = 0.6;
  std::size_t checked = 0, off_ray_unshrunk = 0;
  const std::vector<Camera> cams = test::random_cameras(mesh, 6, 23, double(w) / h);
  for (std::size_t c = 0; c < cams.size(); ++c) {
    if (c % 3 == 1) continue;  // eyes inside the box
    Framebuffer fb(w, h);
    PictureParams pp;
    pp.render.shrink = f;
    draw_picture(mesh, table, cams[c], fb, pp);
    const Projector proj(cams[c], w, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::uint32_t tet = fb.id[fb.index(x, y)];
        if (tet == kNone) continue;
        double o[3], d[3];
        world_ray(proj, x, y, o, d);
        const double dl = std::hypot(d[0], d[1], d[2]);
        const std::uint32_t* n = &mesh.tet[4 * std::size_t(tet)];
        auto off_ray = [&](const double b[4], double shrink) {  // distance of the drawn point from the ray
          double p[3] = {0, 0, 0}, centre[3] = {0, 0, 0};
          for (int i = 0; i < 4; ++i)
            for (int k = 0; k < 3; ++k) {
              p[k] += b[i] * mesh.xyz[3 * std::size_t(n[i]) + std::size_t(k)];
              centre[k] += 0.25 * mesh.xyz[3 * std::size_t(n[i]) + std::size_t(k)];
            }
          double q[3], cr[3];
          for (int k = 0; k < 3; ++k) q[k] = centre[k] + shrink * (p[k] - centre[k]) - o[k];
          cr[0] = q[1] * d[2] - q[2] * d[1];
          cr[1] = q[2] * d[0] - q[0] * d[2];
          cr[2] = q[0] * d[1] - q[1] * d[0];
          return std::hypot(cr[0], cr[1], cr[2]) / dl;
        };
        double b[4];
        ASSERT_TRUE(pixel_point_in_tet(mesh, cams[c], w, h, tet, x, y, b, f)) << x << "," << y;
        double p[3] = {0, 0, 0};
        for (int i = 0; i < 4; ++i) {
          EXPECT_GE(b[i], 0.0);
          for (int k = 0; k < 3; ++k) p[k] += b[i] * mesh.xyz[3 * std::size_t(n[i]) + std::size_t(k)];
        }
        EXPECT_LT(off_ray(b, f), 3e-3) << "camera " << c << " pixel " << x << "," << y;
        EXPECT_NEAR(field_value_in_tet(mesh, choice, tet, b), linear(p), 1e-9);
        double b1[4];
        if (pixel_point_in_tet(mesh, cams[c], w, h, tet, x, y, b1)) off_ray_unshrunk += off_ray(b1, f) > 1e-2;
        ++checked;
      }
  }
  EXPECT_GT(checked, 2000u);
  EXPECT_GT(off_ray_unshrunk, checked / 2) << "the unshrunk entry is not the point the pixel shows";
}

}  // namespace
}  // namespace foxi
