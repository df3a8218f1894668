// Movies against fresh pictures: every back-and-forth frame (drawn, then undrawn) equals the
// painter's picture of the prefix of the order that frame should show, drawn from scratch; the
// frames rise to the high point and fall back; rotating frames equal fresh pictures from the turned
// camera; the progress callback cancels.
#include "foxi/viz/movie.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "foxi/viz/visibility_order.hpp"
#include "mesh_factory.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr int kW = 96, kH = 72;

Camera oblique(const Mesh& m, bool perspective) {
  double lo[3], hi[3];
  mesh_bounds(m, lo, hi);
  const double dir[3] = {-1, 0.7, -0.5}, up[3] = {0, 0, 1};
  return fit_camera(lo, hi, dir, up, perspective, 30, double(kW) / kH);
}

TEST(Movie, BackAndForthFramesEqualFreshPrefixes) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 500, 91, 2, 1, 1);
  test::regions_along_x(m, 0.7, 1.3);
  const SphereTable table = compute_spheres(m);
  std::vector<std::uint32_t> subset;  // the middle region and half the rest: non-convex
  for (std::uint32_t t = 0; t < m.tet_count(); ++t)
    if (m.tet_region[t] == 2 || t % 2 == 0) subset.push_back(t);
  for (bool perspective : {true, false}) {
    const Camera cam = oblique(m, perspective);
    const auto order = visibility_order(m, table, view_of(cam), subset);
    MovieParams p;
    p.frames = 9;
    p.cycles = 2;
    p.from = 0.2;
    p.to = 0.9;
    std::vector<Framebuffer> frames;
    const MovieStats s =
        make_movie(m, table, cam, kW, kH, subset, p, [&](const Framebuffer& fb) { frames.push_back(fb); });
    ASSERT_EQ(frames.size(), 18u);
    EXPECT_EQ(s.frames, 18u);
    EXPECT_GT(s.tets_undrawn, 0u);
    EXPECT_GT(s.max_undo_bytes, 0u);
    std::size_t previous = 0;
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const int k = int(i % 9);
      const double t = k <= 4 ? k / 4.0 : (9 - k) / 5.0;
      const std::size_t n = std::size_t(std::llround((0.2 + 0.7 * t) * double(order.size())));
      const Framebuffer fresh = render_tets(m, cam, kW, kH, std::span<const std::uint32_t>(order).first(n));
      EXPECT_EQ(frames[i].rgba, fresh.rgba) << "frame " << i;
      EXPECT_EQ(frames[i].id, fresh.id) << "frame " << i;
      if (k == 4) {
        EXPECT_EQ(n, std::size_t(std::llround(0.9 * double(order.size()))));
      }
      if (k > 0) {
        EXPECT_TRUE(k <= 4 ? n > previous : n < previous) << "frame " << i;
      }
      previous = n;
    }
  }
}

TEST(Movie, RotatingFramesEqualFreshPicturesAndProgressCancels) {
  Mesh m = test::grid_mesh(4, 3, 3, 1, 1, 1, 6);
  const SphereTable table = compute_spheres(m);
  const Camera cam = oblique(m, true);
  MovieParams p;
  p.rotate = true;
  p.frames = 6;
  p.turn_deg = 90;
  std::vector<Framebuffer> frames;
  make_movie(m, table, cam, kW, kH, {}, p, [&](const Framebuffer& fb) { frames.push_back(fb); });
  ASSERT_EQ(frames.size(), 6u);
  for (int k = 0; k < 6; ++k) {
    const Camera turned = orbit(cam, 15.0 * k, 0);
    const auto order = visibility_order(m, table, view_of(turned));
    EXPECT_EQ(frames[std::size_t(k)].rgba, render_tets(m, turned, kW, kH, order).rgba) << "frame " << k;
  }
  EXPECT_NE(frames[0].rgba, frames[5].rgba);
  int calls = 0;
  EXPECT_THROW(make_movie(
                   m, table, cam, kW, kH, {}, p, [](const Framebuffer&) {},
                   [&](std::string_view, double) { return ++calls < 3; }),
               MovieCancelled);
  EXPECT_EQ(calls, 3);
  calls = 0;
  EXPECT_THROW(make_movie(
                   m, table, cam, kW, kH, {}, p, [](const Framebuffer&) {},
                   [&](std::string_view, double) { return ++calls < 3; }),
               Cancelled);  // the one cancellation outcome of every library
  p.frames = 1;
  EXPECT_THROW(make_movie(m, table, cam, kW, kH, {}, p, [](const Framebuffer&) {}), std::invalid_argument);
}

}  // namespace
}  // namespace foxi
