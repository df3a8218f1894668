// InteractiveView (interactive_view.hpp), driven by events as a host window would, against
// independent pictures: its finished progressive draw equals draw_picture's one-call picture (and,
// on an uncertified mesh, the depth buffer's); after an undraw the picture equals the remaining
// tets drawn afresh; the damage rectangles hold every pixel a step changed; step(budget) returns
// within a budget and picks report the framebuffer's tet.
#include "foxi/viz/interactive_view.hpp"

#include <gtest/gtest.h>

#include <chrono>

#include "bench_meshes.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/translucent.hpp"
#include "foxi/viz/volume.hpp"
#include "random_cameras.hpp"

namespace foxi {
namespace {

constexpr int kW = 200, kH = 150;

std::size_t differing(const Framebuffer& a, const Framebuffer& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.rgba.size(); ++i) n += a.rgba[i] != b.rgba[i] || a.id[i] != b.id[i];
  return n;
}

TEST(InteractiveView, FinishedDrawEqualsTheOneCallPicture) {
  for (const double jitter : {0.0, 0.15}) {  // certified, then not
    const Mesh m = bench::kuhn_grid_mesh(12, jitter, 3);
    const SphereTable table = compute_spheres(m);
    for (const Camera& cam : test::random_cameras(m, 4, 21, double(kW) / kH)) {
      InteractiveView view(m, cam, kW, kH);
      view.restart();
      view.finish();
      Framebuffer ref(kW, kH);
      const PictureReport r = draw_picture(m, table, cam, ref);
      EXPECT_EQ(view.delaunay(), r.delaunay);
      EXPECT_EQ(view.drawn().size(), m.tet_count());
      EXPECT_EQ(differing(view.framebuffer(), ref), 0u) << "jitter " << jitter;
    }
  }
}

TEST(InteractiveView, EventsDamageUndrawAndPick) {
  const Mesh m = bench::kuhn_grid_mesh(16, 0.0);  // 24576 tets, certified
  const Camera cam = test::random_cameras(m, 1, 5, double(kW) / kH)[0];
  RenderParams params;
  params.undoable = true;
  InteractiveView view(m, cam, kW, kH, params);
  ASSERT_TRUE(view.delaunay());
  view.restart();
  // Step by step: every pixel a step changes lies in one of the damage rectangles it reports.
  (void)view.take_damage();
  for (int s = 0; s < 8 && !view.done(); ++s) {
    const Framebuffer before = view.framebuffer();
    ASSERT_TRUE(view.step());
    const std::vector<PixelRect> damage = view.take_damage();
    const Framebuffer& after = view.framebuffer();
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const std::size_t i = after.index(x, y);
        if (after.rgba[i] == before.rgba[i] && after.id[i] == before.id[i]) continue;
        bool inside = false;
        for (const PixelRect& r : damage)
          inside = inside || (x >= r.x0 && x <= r.x1 && y >= r.y0 && y <= r.y1);
        ASSERT_TRUE(inside) << "pixel " << x << "," << y << " changed outside the damage";
      }
  }
  // A time slice: returns, having drawn, and leaves the rest for later slices.
  const std::size_t before = view.drawn().size();
  EXPECT_TRUE(view.step(std::chrono::microseconds(1)));
  EXPECT_GT(view.drawn().size(), before);
  while (view.step(std::chrono::milliseconds(5))) {
  }
  EXPECT_TRUE(view.done());
  // Undraw a third: the picture equals the remaining prefix drawn from scratch.
  ASSERT_TRUE(view.set_undrawing(true));
  const std::size_t n = view.drawn().size();
  EXPECT_EQ(view.undraw(n / 3), n / 3);
  const Framebuffer fresh = render_tets(m, cam, kW, kH, view.drawn());
  EXPECT_EQ(differing(view.framebuffer(), fresh), 0u);
  // Pick: the framebuffer's tet at the pixel; outside the image, none.
  std::size_t picked = 0;
  for (int y = 0; y < kH; y += 7)
    for (int x = 0; x < kW; x += 7) {
      const std::uint32_t t = view.pick(x, y);
      EXPECT_EQ(t, fresh.id[fresh.index(x, y)]);
      picked += t != kNone;
    }
  EXPECT_GT(picked, 0u);
  EXPECT_EQ(view.pick(-1, 0), kNone);
  EXPECT_EQ(view.pick(kW, 0), kNone);
  // Region of interest: the drawn tets become the displayed set; pop goes back to the whole mesh.
  ASSERT_TRUE(view.push_region());
  EXPECT_EQ(view.total(), n - n / 3);
  view.finish();
  // The same tets in their own order: the same picture up to depth ties on shared edges.
  EXPECT_LE(differing(view.framebuffer(), fresh), 20u) << "the region drawn alone is the same picture";
  ASSERT_TRUE(view.pop_region());
  EXPECT_EQ(view.total(), m.tet_count());
  // Resize: the framebuffer follows, damaged whole.
  view.resize(64, 48);
  EXPECT_EQ(view.framebuffer().width, 64);
  const std::vector<PixelRect> all = view.take_damage();
  ASSERT_FALSE(all.empty());
  EXPECT_EQ(all.front().y0, 0);
  EXPECT_EQ(all.back().y1, 47);
}

// Translucency and volume rendering in the view (issue 23 item 3): the finished progressive draw equals
// the one-call picture (draw_translucent_picture, draw_volume_picture: the static power order, not the
// progressive one); after drawing n tets in batches and undrawing k in steps, the picture equals a
// fresh painter compositing the remaining n - k from the back, pixel for pixel, and those n - k are the
// first n - k drawn; drawing on after the undraw reaches the one-call picture again.
std::vector<double> corner_values(const Mesh& m) {  // a linear field 3x - 2y + z at the corners
  std::vector<double> c;
  for (std::uint32_t node : m.tet) {
    const double* p = &m.xyz[3 * std::size_t(node)];
    c.push_back(3 * p[0] - 2 * p[1] + p[2]);
  }
  return c;
}

template <class Fresh>
void check_composite_undraw(InteractiveView& view, const Framebuffer& whole, const Fresh& fresh) {
  view.restart();
  ASSERT_GT(view.total(), 64u);
  view.finish();
  EXPECT_EQ(view.drawn().size(), view.total());
  EXPECT_EQ(differing(view.framebuffer(), whole), 0u) << "the progressive draw is the one-call picture";
  const std::vector<std::uint32_t> all = view.drawn();
  ASSERT_TRUE(view.set_undrawing(true));
  const std::size_t n = all.size();
  // Undraw in a few uneven steps: a third with u:N, then two key steps (1/64 each).
  EXPECT_EQ(view.undraw(n / 3), n / 3);
  ASSERT_TRUE(view.step());
  ASSERT_TRUE(view.step());
  const std::size_t left = view.drawn().size();
  ASSERT_LT(left, n - n / 3);
  EXPECT_TRUE(std::equal(view.drawn().begin(), view.drawn().end(), all.begin())) << "a prefix of the draw";
  const Framebuffer ref = fresh(std::span<const std::uint32_t>(all).first(left));
  EXPECT_EQ(differing(view.framebuffer(), ref), 0u) << "undrawn to " << left << " of " << n;
  EXPECT_GT(differing(ref, whole), 0u) << "the undraw changed the picture";
  EXPECT_TRUE(view.status().rfind("undrawing", 0) == 0) << view.status();
  // Draw on: the whole picture again.
  ASSERT_TRUE(view.set_undrawing(false));
  view.finish();
  EXPECT_EQ(differing(view.framebuffer(), whole), 0u);
  // Everything undrawn: the background.
  ASSERT_TRUE(view.set_undrawing(true));
  EXPECT_EQ(view.undraw(n), n);
  EXPECT_EQ(differing(view.framebuffer(), Framebuffer(kW, kH)), 0u);
}

TEST(InteractiveView, TranslucentUndrawEqualsAFreshCompositeOfTheRest) {
  const Mesh m = bench::kuhn_grid_mesh(10, 0.0);  // regions 1 (lower half) and 2
  const SphereTable table = compute_spheres(m);
  const std::vector<double> corner = corner_values(m);
  TranslucentParams tp;
  tp.region_opacity = {{1, 0.35}, {2, 0.6}};
  tp.corner = corner;
  tp.iso.values = {0.5, 2.0, 4.0};
  tp.iso.scale = ColorScale{ColorMapId::viridis, -2, 6};
  tp.iso_opacity = 0.4;
  for (const Camera& cam : test::random_cameras(m, 2, 31, double(kW) / kH)) {
    InteractiveView view(m, cam, kW, kH);
    view.set_translucent(&tp);
    EXPECT_TRUE(view.translucent());
    EXPECT_NE(view.status().find("x-ray composited exactly"), std::string::npos) << view.status();
    EXPECT_FALSE(view.push_region()) << "no region of interest from surface tets";
    Framebuffer whole(kW, kH);
    const TranslucentReport r = draw_translucent_picture(m, table, cam, whole, {}, tp);
    ASSERT_TRUE(r.exact_order);
    const TranslucentSurfaces surfaces = translucent_surfaces(m, {}, tp);
    check_composite_undraw(view, whole, [&](std::span<const std::uint32_t> tets) {
      TranslucentPainter painter(m, cam, kW, kH, surfaces, tp);
      painter.draw(tets);
      Framebuffer fb(kW, kH);
      painter.resolve(fb);
      return fb;
    });
    view.set_translucent(nullptr);  // opaque again: the painter's picture
    view.finish();
    Framebuffer opaque(kW, kH);
    draw_picture(m, table, cam, opaque);
    EXPECT_EQ(differing(view.framebuffer(), opaque), 0u);
  }
}

TEST(InteractiveView, VolumeUndrawEqualsAFreshCompositeOfTheRest) {
  const Mesh m = bench::kuhn_grid_mesh(10, 0.0);  // certified (a jittered grid is not)
  const SphereTable table = compute_spheres(m);
  const std::vector<double> corner = corner_values(m);
  VolumeParams vp;
  vp.scale = ColorScale{ColorMapId::coolwarm, -20, 30};
  vp.opacity_curve = {{-20, 0.05}, {10, 0.3}, {30, 0.6}};
  vp.unit_length = 2;
  for (const Camera& cam : test::random_cameras(m, 2, 41, double(kW) / kH)) {
    InteractiveView view(m, cam, kW, kH);
    ASSERT_TRUE(view.delaunay());
    view.set_volume(corner, &vp);
    EXPECT_TRUE(view.volume());
    EXPECT_NE(view.status().find("volume composited exactly"), std::string::npos) << view.status();
    Framebuffer whole(kW, kH);
    ASSERT_TRUE(draw_volume_picture(m, table, cam, whole, {}, corner, vp).exact_order);
    check_composite_undraw(view, whole, [&](std::span<const std::uint32_t> tets) {
      VolumePainter painter(m, cam, kW, kH, corner, vp);
      painter.draw(tets);
      Framebuffer fb(kW, kH);
      painter.resolve(fb);
      return fb;
    });
  }
  // Bad settings are refused and the previous drawing kept.
  InteractiveView view(m, test::random_cameras(m, 1, 3, double(kW) / kH)[0], kW, kH);
  VolumeParams bad = vp;
  bad.unit_length = 0;
  EXPECT_THROW(view.set_volume(corner, &bad), std::invalid_argument);
  EXPECT_FALSE(view.volume());
  EXPECT_THROW(view.set_volume(std::span<const double>(corner).first(8), &vp), std::invalid_argument);
}

// The view resolves only the screen tiles drawn since its last picture (VolumePainter::resolve_drawn):
// at a size of several tiles (256 x 128 pixels each), the picture asked for after every step equals
// a fresh composite of the tets drawn so far, pixel for pixel, and so after an undraw (a kept picture
// shown, then the painter catching up) and drawing on.
TEST(InteractiveView, VolumePictureAfterEachStepEqualsAFreshCompositeOfThePrefix) {
  constexpr int kBigW = 700, kBigH = 300;  // 3 x 3 tiles
  const Mesh m = bench::kuhn_grid_mesh(8, 0.0);
  const std::vector<double> corner = corner_values(m);
  VolumeParams vp;
  vp.scale = ColorScale{ColorMapId::coolwarm, -20, 30};
  vp.opacity_curve = {{-20, 0.05}, {10, 0.3}, {30, 0.6}};
  vp.unit_length = 2;
  const Camera cam = test::random_cameras(m, 1, 23, double(kBigW) / kBigH)[0];
  auto fresh = [&](std::span<const std::uint32_t> tets) {
    VolumePainter painter(m, cam, kBigW, kBigH, corner, vp);
    painter.draw(tets);
    Framebuffer fb(kBigW, kBigH);
    painter.resolve(fb);
    return fb;
  };
  InteractiveView view(m, cam, kBigW, kBigH);
  view.set_volume(corner, &vp);
  int steps = 0;
  while (view.step()) {
    ++steps;
    EXPECT_EQ(differing(view.framebuffer(), fresh(view.drawn())), 0u) << "after step " << steps;
  }
  ASSERT_GT(steps, 8);
  EXPECT_GT(differing(view.framebuffer(), Framebuffer(kBigW, kBigH)), 1000u) << "something drawn";
  ASSERT_TRUE(view.set_undrawing(true));
  view.undraw(view.drawn().size() / 2);
  EXPECT_EQ(differing(view.framebuffer(), fresh(view.drawn())), 0u) << "undrawn to half";
  ASSERT_TRUE(view.set_undrawing(false));
  for (int k = 0; k < 3 && view.step(); ++k)
    EXPECT_EQ(differing(view.framebuffer(), fresh(view.drawn())), 0u) << "drawing on, step " << k;
}

// A whole-tet subset (set_subset: the regions shown, a threshold) stays when translucency or the
// volume is turned on: the view composites that subset, as the one-call pictures do given it, pixel
// for pixel; iso drawing ends instead. movie_input copies what the view draws.
TEST(InteractiveView, CompositingKeepsTheWholeTetSubset) {
  const Mesh m = bench::kuhn_grid_mesh(10, 0.0);  // regions 1 (lower half) and 2, certified
  const SphereTable table = compute_spheres(m);
  const std::vector<double> corner = corner_values(m);
  std::vector<std::uint32_t> subset;  // a non-convex part: every tet but a slab through the middle
  for (std::uint32_t t = 0; t < m.tet_count(); ++t)
    if (t % 7 != 0) subset.push_back(t);
  TranslucentParams tp;
  tp.region_opacity = {{1, 0.35}, {2, 0.6}};
  VolumeParams vp;
  vp.scale = ColorScale{ColorMapId::coolwarm, -20, 30};
  vp.opacity_curve = {{-20, 0.05}, {30, 0.6}};
  vp.unit_length = 2;
  const Camera cam = test::random_cameras(m, 1, 17, double(kW) / kH)[0];
  InteractiveView view(m, cam, kW, kH);
  view.set_subset(subset);
  view.set_translucent(&tp);
  view.finish();
  EXPECT_EQ(view.shown_tets(), subset);
  Framebuffer ref(kW, kH);
  ASSERT_TRUE(draw_translucent_picture(m, table, cam, ref, subset, tp).exact_order);
  EXPECT_EQ(differing(view.framebuffer(), ref), 0u) << "the x-ray of the subset";
  const ViewMovie movie = view.movie_input();
  ASSERT_TRUE(movie.translucent.has_value());
  EXPECT_EQ(movie.subset, subset);
  EXPECT_FALSE(movie.volume.has_value());
  view.set_volume(corner, &vp);
  view.finish();
  Framebuffer vref(kW, kH);
  ASSERT_TRUE(draw_volume_picture(m, table, cam, vref, subset, corner, vp).exact_order);
  EXPECT_EQ(differing(view.framebuffer(), vref), 0u) << "the volume of the subset";
  EXPECT_EQ(view.movie_input().corner, corner);
  // Iso drawing does not stay: the x-ray of all tets.
  IsoParams ip;
  ip.values = {1.0};
  ip.scale = vp.scale;
  IsoDrawing drawing;
  drawing.corner = corner;
  drawing.params = ip;
  view.set_iso(&drawing, subset);
  EXPECT_THROW((void)view.movie_input(), std::invalid_argument) << "no movie of iso polygons";
  view.set_translucent(&tp);
  view.finish();
  EXPECT_TRUE(view.shown_tets().empty());
  Framebuffer all(kW, kH);
  draw_translucent_picture(m, table, cam, all, {}, tp);
  EXPECT_EQ(differing(view.framebuffer(), all), 0u);
}

TEST(InteractiveView, UncertifiedCompositingSaysSoAndDoesNotUndraw) {
  const Mesh m = bench::kuhn_grid_mesh(12, 0.15, 3);  // not certified (as above)
  const SphereTable table = compute_spheres(m);
  const Camera cam = test::random_cameras(m, 1, 9, double(kW) / kH)[0];
  InteractiveView view(m, cam, kW, kH);
  ASSERT_FALSE(view.delaunay());
  TranslucentParams tp;
  tp.region_opacity = {{1, 0.5}};
  view.set_translucent(&tp);
  view.finish();
  EXPECT_FALSE(view.composite_exact());
  EXPECT_NE(view.status().find("x-ray NOT Delaunay: fragments sorted per pixel"), std::string::npos)
      << view.status();
  EXPECT_FALSE(view.set_undrawing(true));
  EXPECT_EQ(view.undraw(10), 0u);
  Framebuffer ref(kW, kH);
  EXPECT_FALSE(draw_translucent_picture(m, table, cam, ref, {}, tp).exact_order);
  EXPECT_EQ(differing(view.framebuffer(), ref), 0u) << "the same per-pixel sort as the one-call picture";
  const std::vector<double> corner = corner_values(m);
  VolumeParams vp;
  vp.scale = ColorScale{ColorMapId::viridis, -10, 20};
  vp.opacity_curve = {{-10, 0.2}, {20, 0.5}};
  view.set_volume(corner, &vp);
  EXPECT_NE(view.status().find("volume NOT Delaunay: composited in MPVO order, NOT exact"), std::string::npos)
      << view.status();
}

}  // namespace
}  // namespace foxi
