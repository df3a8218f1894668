// Exact depth ties (issue 17): where two faces meet exactly at a pixel centre (a shared edge or vertex;
// on a structured grid seen along an axis with pixel centres on the grid lines, whole pixel columns),
// the depth buffer must show the face the painter shows. Painter in a visibility order against the
// depth buffer in a shuffled order, pixel for pixel (colour and id), with no tolerance: on cube grids
// (5 and 6 tets a cell) seen orthographically along the three axes (both ways) and a few degrees off,
// scaled so that grid lines fall on pixel centres or pixel edges, with region colours, flat and graded
// field colours, isosurfaces and caps; and once on a random Delaunay mesh from random cameras. Before
// the tie rule (depth_tie.hpp) the depth buffer kept whichever tied face came first or rounded nearer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "foxi/viz/camera.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/isosurface.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "mesh_factory.hpp"
#include "picture_diff.hpp"
#include "random_cameras.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr int kW = 160, kH = 120;
constexpr double kPixelsPerUnit = 16;  // grid spacing 1 (and 1.25: 20 pixels)

// Orthographic along axis `axis` (sign s), the grid's centre shifted so that grid lines fall on pixel
// centres (half = true) or on pixel edges, optionally turned yaw/pitch degrees away.
// `ppu` pixels per unit, `step` the grid spacing (a whole number of pixels).
Camera axis_camera(const Mesh& m, int axis, double s, bool half, double yaw = 0, double pitch = 0,
                   double ppu = kPixelsPerUnit, double step = 1) {
  double lo[3], hi[3];
  mesh_bounds(m, lo, hi);
  Camera c;
  c.perspective = false;
  c.ortho_height = kH / ppu;
  const int right = (axis + 1) % 3, up = (axis + 2) % 3;
  for (int k = 0; k < 3; ++k) {
    c.at[k] = step * std::round(0.5 * (lo[k] + hi[k]) / step);  // a grid node: lines at whole pixels
    c.up[k] = k == up ? 1 : 0;
  }
  if (half) {  // half a pixel: pixel x = cx + scale (p - at).right, y = cy - scale (p - at).up
    c.at[right] -= s * 0.5 / ppu;
    c.at[up] += 0.5 / ppu;
  }
  for (int k = 0; k < 3; ++k) c.eye[k] = c.at[k] - (k == axis ? s * 10 : 0);
  if (yaw != 0 || pitch != 0) c = orbit(c, yaw, pitch);
  return c;
}

using Count = test::PictureDiff;
constexpr auto compare = test::compare_pictures;

// Painter in the visibility order against the depth buffer in a shuffled one (so that ties are not
// decided by the order), for whole tets drawn with `params`.
Count painter_vs_depth(const Mesh& m, const SphereTable& table, const Camera& cam, const RenderParams& params,
                       unsigned seed) {
  const std::vector<std::uint32_t> order = visibility_order(m, table, view_of(cam));
  RenderParams zp = params;
  zp.depth_buffer = true;
  std::vector<std::uint32_t> shuffled = order;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(seed));
  return compare(render_tets(m, cam, kW, kH, order, params), render_tets(m, cam, kW, kH, shuffled, zp));
}

// The same for isosurfaces (or their caps) of the corner values `corner` at `values`.
Count iso_painter_vs_depth(const Mesh& m, const SphereTable& table, const Camera& cam,
                           const std::vector<double>& corner, const IsoParams& ip, unsigned seed) {
  const TetIntervals tree(corner);
  std::vector<std::uint32_t> tets;
  if (ip.cap) {
    for (std::uint32_t t = 0; t < m.tet_count(); ++t)
      if (*std::max_element(&corner[4 * t], &corner[4 * t] + 4) >= ip.values[0]) tets.push_back(t);
  } else {
    tree.crossing_any(ip.values, tets);
  }
  const std::vector<std::uint32_t> order = visibility_order(m, table, view_of(cam), tets);
  RenderParams rp;
  Framebuffer a(kW, kH);
  IsoPainter(m, cam, kW, kH, corner, ip, rp).draw(a, order);
  rp.depth_buffer = true;
  Framebuffer b(kW, kH, true);
  std::vector<std::uint32_t> shuffled = order;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(seed));
  IsoPainter(m, cam, kW, kH, corner, ip, rp).draw(b, shuffled);
  return compare(a, b);
}

// The views: each axis both ways, grid lines on pixel centres and on pixel edges, then 2-3 degrees off.
std::vector<std::pair<std::string, Camera>> axis_views(const Mesh& m, double ppu = kPixelsPerUnit,
                                                       double step = 1) {
  std::vector<std::pair<std::string, Camera>> views;
  for (int axis = 0; axis < 3; ++axis)
    for (double s : {1.0, -1.0})
      for (bool half : {true, false}) {
        const std::string name =
            std::string(s > 0 ? "+" : "-") + "xyz"[axis] + (half ? " centres" : " edges");
        views.emplace_back(name, axis_camera(m, axis, s, half, 0, 0, ppu, step));
        views.emplace_back(name + ", 2.5 deg off", axis_camera(m, axis, s, half, 2.5, 0, ppu, step));
        views.emplace_back(name + ", 2 and 3 deg off", axis_camera(m, axis, s, half, 2, -3, ppu, step));
      }
  return views;
}

double smooth(const double* p) { return std::sin(0.9 * p[0]) + std::cos(0.7 * p[1]) + 0.3 * p[2] * p[0]; }

std::vector<double> corners_of(const Mesh& m, double (*f)(const double*)) {
  std::vector<double> c(m.tet.size());
  for (std::size_t i = 0; i < c.size(); ++i) c[i] = f(&m.xyz[3 * m.tet[i]]);
  return c;
}

TEST(DepthTie, PainterEqualsDepthBufferOnAxisAlignedGrids) {
  std::size_t shown = 0;
  for (int tets_per_cell : {6, 5})
    for (double hy : {1.0, 1.25}) {
      const Mesh m = test::grid_mesh(6, 5, 4, 1.0, hy, 1.0, tets_per_cell);
      const SphereTable table = compute_spheres(m);
      unsigned seed = 0;
      for (const auto& [name, cam] : axis_views(m))
        for (bool edges : {true, false}) {
          RenderParams p;
          p.edges = edges;
          const Count n = painter_vs_depth(m, table, cam, p, ++seed);
          EXPECT_EQ(n.differing, 0u) << tets_per_cell << " tets a cell, hy " << hy << ", view " << name
                                     << (edges ? ", edges" : "");
          shown += n.shown;
        }
    }
  EXPECT_GT(shown, 2u * 2 * 36 * 2 * 3000);  // the mesh fills a good part of every view
}

TEST(DepthTie, PainterEqualsDepthBufferWithFieldColoursOnGrids) {
  Mesh m = test::grid_mesh(6, 5, 4, 1.0, 1.0, 1.0, 6);
  const SphereTable table = compute_spheres(m);
  Field cell{"c", FieldLocation::cell, 1, "", {}, {}};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (std::size_t t = 0; t < m.tet_count(); ++t) cell.values.push_back(u(rng));
  Field node{"n", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n) node.values.push_back(smooth(&m.xyz[3 * n]));
  m.fields = {cell, node};
  unsigned seed = 0;
  for (const char* field : {"c", "n"})
    for (bool graded : {false, true}) {
      const FieldChoice choice = choose_field(m, field);
      const std::vector<double> values =
          graded ? tet_corner_values(m, choice) : tet_centroid_values(m, choice);
      ColorScale s;
      std::tie(s.lo, s.hi) = finite_range(values);
      RenderParams p;
      p.field =
          std::make_shared<FieldPaint>(graded ? graded_field_paint(values, s) : flat_field_paint(values, s));
      for (const auto& [name, cam] : axis_views(m)) {
        const Count n = painter_vs_depth(m, table, cam, p, ++seed);
        EXPECT_EQ(n.differing, 0u) << field << (graded ? " graded" : " flat") << ", view " << name;
      }
    }
}

TEST(DepthTie, IsosurfacesAndCapsEqualDepthBufferOnGrids) {
  const Mesh m = test::grid_mesh(6, 5, 4, 1.0, 1.0, 1.0, 6);
  const SphereTable table = compute_spheres(m);
  const std::vector<double> corner = corners_of(m, smooth);
  unsigned seed = 0;
  std::size_t shown = 0;
  for (bool cap : {false, true}) {
    IsoParams ip;
    ip.values = {0.5, 1.0, 1.5};
    ip.scale.lo = -1;
    ip.scale.hi = 3;
    ip.cap = cap;
    for (const auto& [name, cam] : axis_views(m)) {
      const Count n = iso_painter_vs_depth(m, table, cam, corner, ip, ++seed);
      EXPECT_EQ(n.differing, 0u) << (cap ? "cap" : "isosurfaces") << ", view " << name;
      shown += n.shown;
    }
  }
  EXPECT_GT(shown, 36u * 2 * 1000);
}

// TetGen's Delaunay mesh of random points of a lattice (spacing 1/8, the cube's corners among them): an
// unstructured mesh whose edges still run through pixel centres when seen along an axis at 12 pixels
// a lattice step; then from random cameras too (where exact ties are rare).
TEST(DepthTie, PainterEqualsDepthBufferOnRandomDelaunay) {
  test::TempDir dir;
  std::mt19937 rng(17);
  std::string text;
  int count = 0;
  for (int k = 0; k <= 8; ++k)
    for (int j = 0; j <= 8; ++j)
      for (int i = 0; i <= 8; ++i) {
        const bool corner = (i % 8 == 0) && (j % 8 == 0) && (k % 8 == 0);
        if (!corner && rng() % 3 != 0) continue;
        text += std::to_string(++count) + " " + std::to_string(i / 8.0) + " " + std::to_string(j / 8.0) +
                " " + std::to_string(k / 8.0) + "\n";
      }
  test::write_text(dir / "lattice.node", std::to_string(count) + " 3 0 0\n" + text);
  test::run("cd '" + dir.path().string() + "' && tetgen -Q lattice.node", dir / "tetgen.log");
  const Mesh m = read_tetgen(dir / "lattice.1");
  ASSERT_GT(m.tet_count(), 500u);
  const SphereTable table = compute_spheres(m);
  std::size_t differing = 0, shown = 0;
  unsigned seed = 0;
  for (const auto& [name, cam] : axis_views(m, 96, 1.0 / 8)) {
    const Count n = painter_vs_depth(m, table, cam, RenderParams{}, ++seed);
    EXPECT_EQ(n.differing, 0u) << "view " << name;
    shown += n.shown;
  }
  for (const Camera& cam : test::random_cameras(m, 30, 3, double(kW) / kH)) {
    const Count n = painter_vs_depth(m, table, cam, RenderParams{}, ++seed);
    differing += n.differing;
    shown += n.shown;
  }
  EXPECT_EQ(differing, 0u) << "random cameras";
  EXPECT_GT(shown, 66u * kW * kH / 10);
}

}  // namespace
}  // namespace foxi
