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

}  // namespace
}  // namespace foxi
