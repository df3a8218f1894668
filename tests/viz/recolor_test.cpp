// Recolouring through the id buffer (issue 17, TetRasterizer::recolor): a picture drawn with one field
// paint and recoloured with another equals, pixel for pixel (colour and id), a fresh draw of the same
// tets with the other paint. Flat and graded both ways, another colour map, back to region colours, with
// and without edges, one and two threads, perspective views (eyes inside the mesh among them: faces cut
// by the near plane) and orthographic ones, a subset with shrunk tets, and a progressive draw stopped
// half way. Flat colours of the same shading band go through the shade buffer (Framebuffer::shade):
// its bytes must equal a fresh draw's too, after undraw (restored pixels keep theirs), with "no value"
// tets and over a background that is not the default; an undoable picture recoloured so and then
// undrawn equals the remaining tets drawn in the new colours. InteractiveView::set_field of a finished
// picture recolours (no new draw) and equals a fresh view of the new field.
#include "foxi/viz/rasterizer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "foxi/viz/camera.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/interactive_view.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "mesh_factory.hpp"
#include "picture_diff.hpp"
#include "random_cameras.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr int kW = 160, kH = 120;

struct Paints {
  std::vector<std::shared_ptr<const FieldPaint>>
      all;  // flat a, graded a, flat b (coolwarm), graded b (rainbow)
};

// Two fields on m (a random cell field "a" and a smooth node field "b") and their paints.
Paints make_paints(Mesh& m) {
  Field a{"a", FieldLocation::cell, 1, "", {}, {}};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (std::size_t t = 0; t < m.tet_count(); ++t) a.values.push_back(u(rng));
  Field b{"b", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n) {
    const double* p = &m.xyz[3 * n];
    b.values.push_back(std::sin(4 * p[0]) * std::cos(3 * p[1]) + p[2]);
  }
  m.fields = {a, b};
  Paints ps;
  for (const char* name : {"a", "b"})
    for (bool graded : {false, true}) {
      const FieldChoice choice = choose_field(m, name);
      const std::vector<double> v = graded ? tet_corner_values(m, choice) : tet_centroid_values(m, choice);
      ColorScale s;
      std::tie(s.lo, s.hi) = finite_range(v);
      if (name[0] == 'b') s.map = graded ? ColorMapId::rainbow : ColorMapId::coolwarm;
      ps.all.push_back(
          std::make_shared<const FieldPaint>(graded ? graded_field_paint(v, s) : flat_field_paint(v, s)));
    }
  return ps;
}

std::size_t differing(const Framebuffer& a, const Framebuffer& b) {
  return test::compare_pictures(a, b).differing;
}

// Pixels showing a tet in both whose shade bytes differ (the shade is undefined on the background).
std::size_t differing_shades(const Framebuffer& a, const Framebuffer& b) {
  std::size_t n = 0;
  for (std::size_t p = 0; p < a.id.size(); ++p)
    n += a.id[p] != kNone && b.id[p] != kNone && a.shade[p] != b.shade[p];
  return n;
}

// Draws `tets` with paint `from`, recolours with `to` and compares with a fresh draw with `to`; returns
// the pixels the recolouring changed (so that a test sees it did something).
std::size_t check(const Mesh& m, const Camera& cam, std::span<const std::uint32_t> tets, RenderParams p,
                  std::shared_ptr<const FieldPaint> from, std::shared_ptr<const FieldPaint> to,
                  const char* what) {
  p.field = from;
  TetRasterizer r(m, cam, kW, kH, p);
  Framebuffer fb(kW, kH);
  r.draw(fb, tets);
  const Framebuffer before = fb;
  r.recolor(fb, to);
  p.field = to;
  const Framebuffer fresh = render_tets(m, cam, kW, kH, tets, p);
  EXPECT_EQ(differing(fb, fresh), 0u) << what;
  EXPECT_EQ(differing_shades(fb, fresh), 0u) << what;
  EXPECT_EQ(fb.id, before.id) << what;
  return differing(fb, before);
}

TEST(Recolor, EqualsAFreshDrawWithTheNewPaint) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 900, 31);
  test::regions_along_x(m, 0.35, 0.7);
  const Paints ps = make_paints(m);
  const SphereTable table = compute_spheres(m);
  std::vector<Camera> cams = test::random_cameras(m, 6, 41, double(kW) / kH);
  double lo[3], hi[3];
  mesh_bounds(m, lo, hi);
  const double dir1[3] = {0.3, -1, -0.4}, up[3] = {0, 0, 1};
  cams.push_back(fit_camera(lo, hi, dir1, up, false, 30, double(kW) / kH));
  Camera inside;  // the eye inside the mesh: faces cut by the near plane
  inside.eye[0] = 0.5, inside.eye[1] = 0.45, inside.eye[2] = 0.5;
  inside.at[0] = 1, inside.at[1] = 0.8, inside.at[2] = 0.6;
  inside.fov_deg = 70;
  cams.push_back(inside);
  std::size_t changed = 0;
  for (const Camera& cam : cams) {
    const std::vector<std::uint32_t> order = visibility_order(m, table, view_of(cam));
    for (int threads : {1, 2})
      for (bool edges : {true, false}) {
        RenderParams p;
        p.threads = threads;
        p.edges = edges;
        for (std::size_t i = 0; i < ps.all.size(); ++i)
          for (std::size_t j = 0; j < ps.all.size(); ++j)
            if (i != j) changed += check(m, cam, order, p, ps.all[i], ps.all[j], "field to field");
        changed += check(m, cam, order, p, ps.all[3], nullptr, "field to regions");
        changed += check(m, cam, order, p, nullptr, ps.all[0], "regions to field");
      }
  }
  EXPECT_GT(changed, cams.size() * 4 * 14 * 2000);  // the paints differ, and the recolouring shows it
}

TEST(Recolor, SubsetsShrinkAndProgressiveStops) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 700, 32);
  const Paints ps = make_paints(m);
  const SphereTable table = compute_spheres(m);
  std::vector<std::uint32_t> subset;  // a crinkle clip: the tets with a centroid below x + y < 1
  for (std::uint32_t t = 0; t < m.tet_count(); ++t) {
    double s = 0;
    for (int k = 0; k < 4; ++k) s += m.xyz[3 * m.tet[4 * t + k]] + m.xyz[3 * m.tet[4 * t + k] + 1];
    if (s / 4 < 1) subset.push_back(t);
  }
  for (const Camera& cam : test::random_cameras(m, 4, 43, double(kW) / kH)) {
    const std::vector<std::uint32_t> order = visibility_order(m, table, view_of(cam), subset);
    RenderParams p;
    p.shrink = 0.8;
    check(m, cam, order, p, ps.all[0], ps.all[3], "subset, shrunk");
    const std::vector<std::uint32_t> full = visibility_order(m, table, view_of(cam));
    const std::span<const std::uint32_t> all(full);
    check(m, cam, all.first(all.size() / 2), RenderParams{}, ps.all[1], ps.all[2], "half an order");
    // Stopped half way, recoloured, then drawn on: the rest comes in the new paint.
    RenderParams q;
    q.field = ps.all[1];
    TetRasterizer r(m, cam, kW, kH, q);
    Framebuffer fb(kW, kH);
    r.draw(fb, all.first(all.size() / 2));
    r.recolor(fb, ps.all[2]);
    r.draw(fb, all.subspan(all.size() / 2));
    q.field = ps.all[2];
    EXPECT_EQ(differing(fb, render_tets(m, cam, kW, kH, full, q)), 0u) << "drawn on after a recolour";
  }
}

// Flat paints of a field with "no value" tets (NaN: the scale's no-value colour).
std::shared_ptr<const FieldPaint> flat_with_gaps(const Mesh& m, unsigned seed, ColorMapId map) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> v(m.tet_count());
  for (double& x : v) x = u(rng) < 0.2 ? std::nan("") : u(rng);
  ColorScale s;
  s.lo = 0;
  s.hi = 1;
  s.map = map;
  return std::make_shared<const FieldPaint>(flat_field_paint(v, s));
}

TEST(Recolor, ThroughShadesAfterUndrawWithNoValueAndABackground) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 800, 34);
  test::regions_along_x(m, 0.4, 0.8);
  const auto a = flat_with_gaps(m, 1, ColorMapId::viridis), b = flat_with_gaps(m, 2, ColorMapId::coolwarm);
  const SphereTable table = compute_spheres(m);
  const std::uint32_t background = pack_rgba(20, 30, 40);
  std::size_t restored = 0;
  for (const Camera& cam : test::random_cameras(m, 4, 45, double(kW) / kH)) {
    const std::vector<std::uint32_t> order = visibility_order(m, table, view_of(cam));
    for (int threads : {1, 2}) {
      RenderParams p;
      p.threads = threads;
      p.undoable = true;
      p.field = a;
      ASSERT_TRUE(TetRasterizer(m, cam, kW, kH, p).recolors_by_shade(b.get()));
      // Drawn, a third undrawn, recoloured: the rest in b's colours over the background.
      TetRasterizer r(m, cam, kW, kH, p);
      Framebuffer fb(kW, kH, false, background);
      r.draw(fb, order);
      const Framebuffer drawn = fb;
      r.undraw(fb, order.size() / 3);
      for (std::size_t q = 0; q < fb.id.size(); ++q) restored += fb.id[q] != drawn.id[q] && fb.id[q] != kNone;
      r.recolor(fb, b);
      const std::span<const std::uint32_t> kept(order.data(), order.size() - order.size() / 3);
      RenderParams fresh_p;
      fresh_p.threads = threads;
      fresh_p.field = b;
      Framebuffer fresh(kW, kH, false, background);
      TetRasterizer(m, cam, kW, kH, fresh_p).draw(fresh, kept);
      EXPECT_EQ(differing(fb, fresh), 0u) << "undrawn, then recoloured";
      EXPECT_EQ(differing_shades(fb, fresh), 0u);
      // The saved pixels were recoloured too: undrawing further gives b's colours.
      r.undraw(fb, kept.size() / 2);
      Framebuffer fresh2(kW, kH, false, background);
      TetRasterizer(m, cam, kW, kH, fresh_p).draw(fresh2, kept.first(kept.size() - kept.size() / 2));
      EXPECT_EQ(differing(fb, fresh2), 0u) << "recoloured, then undrawn";
      // And back to region colours (another shading band: rasterized again) gives a fresh region draw.
      EXPECT_FALSE(r.recolors_by_shade(nullptr));
      r.recolor(fb, nullptr);
      RenderParams regions;
      regions.threads = threads;
      Framebuffer fresh3(kW, kH, false, background);
      TetRasterizer(m, cam, kW, kH, regions).draw(fresh3, kept.first(kept.size() - kept.size() / 2));
      EXPECT_EQ(differing(fb, fresh3), 0u) << "to region colours";
    }
  }
  EXPECT_GT(restored, 1000u);  // undraw uncovered tets (restored or repainted), not only background
}

TEST(Recolor, TheViewRecoloursAFinishedPictureAsAFreshViewDraws) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 800, 35);
  const Paints ps = make_paints(m);
  const Camera cam = test::random_cameras(m, 1, 46, double(kW) / kH)[0];
  for (bool undoable : {false, true}) {
    RenderParams p;
    p.undoable = undoable;
    p.field = ps.all[0];
    InteractiveView view(m, cam, kW, kH, p);
    view.restart();
    view.finish();
    const std::size_t generation = view.generation();
    view.set_field(ps.all[2]);  // flat to flat, same band: recoloured
    EXPECT_EQ(view.generation(), generation);
    EXPECT_TRUE(view.done());
    p.field = ps.all[2];
    InteractiveView fresh(m, cam, kW, kH, p);
    fresh.restart();
    fresh.finish();
    EXPECT_EQ(differing(view.framebuffer(), fresh.framebuffer()), 0u);
    if (undoable) {  // and undraws in the new colours
      view.undraw(view.drawn().size() / 2);
      fresh.undraw(fresh.drawn().size() / 2);
      EXPECT_EQ(differing(view.framebuffer(), fresh.framebuffer()), 0u);
    }
    view.set_field(ps.all[1]);  // graded: drawn again
    EXPECT_GT(view.generation(), generation);
  }
}

TEST(Recolor, APaintOfAnotherMeshIsRefusedAndTheOldOneKept) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 300, 33);
  const Paints ps = make_paints(m);
  const Camera cam = test::random_cameras(m, 1, 44, double(kW) / kH)[0];
  const std::vector<std::uint32_t> order = visibility_order(m, compute_spheres(m), view_of(cam));
  RenderParams p;
  p.field = ps.all[0];
  TetRasterizer r(m, cam, kW, kH, p);
  Framebuffer fb(kW, kH);
  r.draw(fb, order);
  const Framebuffer before = fb;
  auto wrong = std::make_shared<FieldPaint>(*ps.all[0]);
  wrong->tet_color.pop_back();
  EXPECT_THROW(r.recolor(fb, wrong), std::invalid_argument);
  EXPECT_EQ(differing(fb, before), 0u);
  Framebuffer other(kW + 1, kH);
  EXPECT_THROW(r.recolor(other, ps.all[1]), std::invalid_argument);
  r.recolor(fb, ps.all[0]);  // the same paint again: nothing moves
  EXPECT_EQ(differing(fb, before), 0u);
}

}  // namespace
}  // namespace foxi
