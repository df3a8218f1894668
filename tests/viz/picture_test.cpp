// draw_picture (picture.hpp) against independent oracles: on a certified mesh the painter's picture
// equals the depth buffer's picture of the same tets drawn in a shuffled order (the order cannot
// matter to a depth buffer), pixel for pixel up to a few depth ties on shared edges; on a mesh that
// fails the certificate the report says MPVO + depth buffer and the picture again equals the
// shuffled depth-buffer picture; the stops draw the prefix the report names; make_movie refuses an
// uncertified mesh before any frame.
#include "foxi/viz/picture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "bench_meshes.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/viz/depth_stop.hpp"
#include "foxi/viz/movie.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "mesh_factory.hpp"
#include "picture_diff.hpp"
#include "random_cameras.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr int kW = 160, kH = 120;

// The depth buffer's picture of `tets` drawn in a shuffled order.
Framebuffer shuffled_depth_picture(const Mesh& m, const Camera& cam, std::vector<std::uint32_t> tets,
                                   unsigned seed) {
  std::shuffle(tets.begin(), tets.end(), std::mt19937(seed));
  RenderParams zp;
  zp.depth_buffer = true;
  return render_tets(m, cam, kW, kH, tets, zp);
}

using Compared = test::PictureDiff;
constexpr auto compare = test::compare_pictures;

std::vector<std::uint32_t> all_tets(const Mesh& m) {
  std::vector<std::uint32_t> v(m.tet_count());
  std::iota(v.begin(), v.end(), 0u);
  return v;
}

TEST(Picture, CertifiedMeshIsDrawnByThePainterAndEqualsTheDepthBuffer) {
  test::TempDir dir;
  const Mesh m = test::random_delaunay(dir, 800, 11);
  ASSERT_TRUE(compute_delaunay_certificate(m).delaunay);
  const SphereTable table = compute_spheres(m);
  Compared total;
  unsigned seed = 0;
  for (const Camera& cam : test::random_cameras(m, 12, 3, double(kW) / kH)) {
    Framebuffer fb(kW, kH);
    const PictureReport r = draw_picture(m, table, cam, fb);
    EXPECT_TRUE(r.delaunay);
    EXPECT_EQ(r.method, OrderMethod::power);
    EXPECT_FALSE(r.depth_buffer);
    EXPECT_TRUE(fb.depth.empty()) << "the painter needs no depth buffer";
    EXPECT_EQ(r.tets_ordered, m.tet_count());
    EXPECT_EQ(r.tets_drawn, m.tet_count());
    EXPECT_EQ(r.cycles_broken, 0u);
    const Compared c = compare(fb, shuffled_depth_picture(m, cam, all_tets(m), ++seed));
    total.differing += c.differing;
    total.shown += c.shown;
  }
  EXPECT_GT(total.shown, 12u * kW * kH / 20) << "the views should show the mesh";
  // Only depth ties on shared edges may differ (rasterizer_test classifies them one by one).
  EXPECT_LE(total.differing, total.shown / 2000 + 10);

  // Asked for, the depth buffer is used on a certified mesh too (power order, depth test).
  const Camera cam = test::random_cameras(m, 1, 5, double(kW) / kH)[0];
  Framebuffer fb(kW, kH);
  PictureParams p;
  p.render.depth_buffer = true;
  const PictureReport r = draw_picture(m, table, cam, fb, p);
  EXPECT_TRUE(r.depth_buffer);
  EXPECT_EQ(r.method, OrderMethod::power);
  EXPECT_EQ(fb.depth.size(), fb.rgba.size());
}

TEST(Picture, UncertifiedMeshIsDrawnInMpvoOrderWithTheDepthBuffer) {
  // A jittered Kuhn grid: its cubes' diagonals no longer meet the empty-sphere condition.
  const Mesh m = bench::kuhn_grid_mesh(5, 0.15, 7);
  const ValidationReport valid = validate(m);
  ASSERT_EQ(valid.inverted + valid.zero_volume, 0u) << "a usable mesh, only not Delaunay";
  ASSERT_FALSE(compute_delaunay_certificate(m).delaunay);
  const SphereTable table = compute_spheres(m);
  Compared total;
  std::size_t painter_differing = 0;
  unsigned seed = 0;
  for (const Camera& cam : test::random_cameras(m, 12, 4, double(kW) / kH)) {
    Framebuffer fb(kW, kH);
    const PictureReport r = draw_picture(m, table, cam, fb);
    EXPECT_FALSE(r.delaunay);
    EXPECT_EQ(r.method, OrderMethod::mpvo);
    EXPECT_TRUE(r.depth_buffer);
    EXPECT_EQ(fb.depth.size(), fb.rgba.size());
    EXPECT_EQ(r.tets_drawn, m.tet_count());
    const Framebuffer oracle = shuffled_depth_picture(m, cam, all_tets(m), ++seed);
    const Compared c = compare(fb, oracle);
    total.differing += c.differing;
    total.shown += c.shown;
    // What the rule prevents: the painter in the power order (no depth buffer) on this mesh.
    const auto power = visibility_order(m, table, view_of(cam));
    painter_differing += compare(render_tets(m, cam, kW, kH, power), oracle).differing;
  }
  EXPECT_GT(total.shown, 12u * kW * kH / 20);
  EXPECT_LE(total.differing, total.shown / 2000 + 10);
  EXPECT_GT(painter_differing, 10 * (total.differing + 10)) << "this mesh should need the depth buffer";
  std::printf(
      "uncertified grid: %zu pixels differ from the shuffled depth buffer (safe picture), %zu for the "
      "painter in the power order\n",
      total.differing, painter_differing);
}

TEST(Picture, StopsDrawThePrefixTheReportNames) {
  test::TempDir dir;
  const Mesh m = test::random_delaunay(dir, 600, 13);
  const SphereTable table = compute_spheres(m);
  const Camera cam = test::random_cameras(m, 1, 9, double(kW) / kH)[0];
  const auto order = visibility_order(m, table, view_of(cam));

  PictureParams p;
  p.stop_fraction = 0.4;
  Framebuffer fb(kW, kH);
  PictureReport r = draw_picture(m, table, cam, fb, p);
  const std::size_t n = std::size_t(std::floor(0.4 * double(order.size()) + 1e-9));
  EXPECT_EQ(r.tets_drawn, n);
  EXPECT_EQ(r.last_drawn, order[n - 1]);
  const Framebuffer prefix = render_tets(m, cam, kW, kH, std::span<const std::uint32_t>(order).first(n));
  EXPECT_EQ(fb.rgba, prefix.rgba);
  EXPECT_EQ(fb.id, prefix.id);

  // A depth stop: every tet drawn is at least that deep, the next one in the order is not.
  const double d = tet_depth(table, cam, order[order.size() / 2]);
  p.stop_fraction = 1;
  p.stop_depth = d;
  r = draw_picture(m, table, cam, fb, p);
  ASSERT_GT(r.tets_drawn, 0u);
  ASSERT_LT(r.tets_drawn, order.size());
  for (std::size_t i = 0; i < r.tets_drawn; ++i) EXPECT_GE(tet_depth(table, cam, order[i]), d);
  EXPECT_LT(tet_depth(table, cam, order[r.tets_drawn]), d);

  // A subset: only its tets are drawn and counted.
  std::vector<std::uint32_t> subset;
  for (std::uint32_t t = 0; t < m.tet_count(); t += 3) subset.push_back(t);
  PictureParams s;
  s.subset = subset;
  r = draw_picture(m, table, cam, fb, s);
  EXPECT_EQ(r.tets_ordered, subset.size());
  for (std::uint32_t id : fb.id) EXPECT_TRUE(id == kNone || id % 3 == 0);

  PictureParams bad;
  bad.stop_fraction = 1.5;
  EXPECT_THROW(draw_picture(m, table, cam, fb, bad), std::invalid_argument);
  bad.stop_fraction = 1;
  bad.stop_depth = std::nan("");
  EXPECT_THROW(draw_picture(m, table, cam, fb, bad), std::invalid_argument);
  Framebuffer empty;
  EXPECT_THROW(draw_picture(m, table, cam, empty), std::invalid_argument);
}

TEST(Picture, MovieRefusesAnUncertifiedMesh) {
  const Mesh m = bench::kuhn_grid_mesh(3, 0.15, 7);
  ASSERT_FALSE(compute_delaunay_certificate(m).delaunay);
  const SphereTable table = compute_spheres(m);
  const Camera cam = test::random_cameras(m, 1, 2, double(kW) / kH)[0];
  std::size_t frames = 0;
  EXPECT_THROW(make_movie(m, table, cam, kW, kH, {}, MovieParams{}, [&](const Framebuffer&) { ++frames; }),
               UncertifiedMeshError);
  EXPECT_EQ(frames, 0u);
  // The same grid unjittered is Delaunay: the movie is made.
  const Mesh g = bench::kuhn_grid_mesh(3, 0.0);
  MovieParams mp;
  mp.frames = 4;
  make_movie(g, compute_spheres(g), cam, kW, kH, {}, mp, [&](const Framebuffer&) { ++frames; });
  EXPECT_EQ(frames, 4u);
}

}  // namespace
}  // namespace foxi
