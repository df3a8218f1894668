// Field colours in the painter against independent oracles: a pixel of a flat-coloured tet is that
// tet's colour-map colour under a shading factor in [shade_min, 1] (and decodes back to its entry);
// a graded face shows, at each pixel, the colour-map entry of the linear field at the point the
// pixel's ray enters the tet (ray casting in the camera frame, perspective and orthographic); the
// painter's picture equals the depth buffer's pixel for pixel with field colours, and field colours
// leave the id buffer as region colours have it; undrawing graded colours equals drawing the rest afresh.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "foxi/viz/camera.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "mesh_factory.hpp"
#include "pixel_ray.hpp"
#include "random_cameras.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr int kW = 160, kH = 120;

// Whether pixel p can be colour c scaled by some s in [smin, 1], each channel rounded.
bool shaded_from(std::uint32_t p, std::uint32_t c, double smin) {
  double lo = smin, hi = 1;
  for (int k = 0; k < 3; ++k) {
    const double pc = double((p >> (8 * k)) & 255u), cc = double((c >> (8 * k)) & 255u);
    if (cc == 0) {
      if (pc != 0) return false;
      continue;
    }
    lo = std::max(lo, (pc - 0.5 - 1e-4) / cc);
    hi = std::min(hi, (pc + 0.5 + 1e-4) / cc);
  }
  return lo <= hi;
}

// The entries of `map` that pixel p can show (shaded_from).
std::vector<int> decode(std::uint32_t p, ColorMapId map, double smin) {
  std::vector<int> out;
  for (int i = 0; i < 256; ++i)
    if (shaded_from(p, color_map_entry(map, i), smin)) out.push_back(i);
  return out;
}

double linear_field(const double* p) { return 2 * p[0] - 1.5 * p[1] + 0.75 * p[2]; }

Mesh grid_with_linear_field() {
  Mesh m = test::grid_mesh(4, 3, 3, 0.25, 0.3, 0.3, 6);
  Field f{"f", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n) f.values.push_back(linear_field(&m.xyz[3 * n]));
  m.fields = {f};
  return m;
}

TEST(FieldRender, FlatTetPixelsAreTheirValuesColourUnderTheShadingBand) {
  Mesh m = test::grid_mesh(4, 4, 4, 0.25, 0.25, 0.25, 6);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5, 5);
  std::vector<double> value(m.tet_count());
  for (double& v : value) v = u(rng);
  value[7] = std::nan("");
  const SphereTable table = compute_spheres(m);
  std::size_t checked = 0, decoded_exactly = 0;
  for (ColorMapId map :
       {ColorMapId::viridis, ColorMapId::cividis, ColorMapId::coolwarm, ColorMapId::rainbow}) {
    int worst = 0;  // the farthest entry a pixel of this map could be read as
    ColorScale s;
    s.map = map;
    s.lo = -5;
    s.hi = 5;
    auto paint = std::make_shared<FieldPaint>(flat_field_paint(value, s));
    RenderParams rp;
    rp.edges = false;
    rp.field = paint;
    for (const Camera& cam : test::random_cameras(m, 6, 11, double(kW) / kH)) {
      const Framebuffer fb = render_tets(m, cam, kW, kH, visibility_order(m, table, view_of(cam)), rp);
      for (std::size_t p = 0; p < fb.rgba.size(); ++p) {
        const std::uint32_t t = fb.id[p];
        if (t == kNone) continue;
        ++checked;
        ASSERT_TRUE(shaded_from(fb.rgba[p], paint->tet_color[t], paint->shade_min))
            << "pixel " << p << " tet " << t << " value " << value[t];
        if (std::isnan(value[t])) continue;
        // Decoding: the pixel's colour names its value's entry, within one step.
        const int entry = int(std::clamp(std::floor(s.position(value[t]) * 256), 0.0, 255.0));
        const std::vector<int> can = decode(fb.rgba[p], map, paint->shade_min);
        ASSERT_FALSE(can.empty());
        EXPECT_TRUE(std::find(can.begin(), can.end(), entry) != can.end());
        worst = std::max({worst, std::abs(can.front() - entry), std::abs(can.back() - entry)});
        decoded_exactly += can.size() == 1;
      }
    }
    std::printf("%s: a shaded pixel decodes to within %d entries of its value's\n", color_map_name(map),
                worst);
    // Measured bounds (8-bit tables, shading in [0.75, 1]): coolwarm and rainbow change hue from entry to
    // entry, so a pixel reads back within one entry; viridis has neighbouring entries equal in 8 bits
    // (two); cividis is almost a lightness ramp, which lightness shading aliases (17 entries, 7% of the
    // range): read cividis pictures by hue only roughly.
    EXPECT_LE(worst, map == ColorMapId::cividis   ? 17
                     : map == ColorMapId::viridis ? 2
                                                  : 1)
        << color_map_name(map);
  }
  EXPECT_GT(checked, 20000u);
  std::printf("flat: %zu pixels, %.1f%% decode to exactly one entry\n", checked,
              100.0 * double(decoded_exactly) / double(checked));
}

// Where the ray enters tet t (camera frame): the nearest face hit inside its triangle; the linear
// field's value there, by the barycentric weights of the face's corners. NaN if none is hit, if the
// hit is within `margin` of the face's edges (barycentric) or the face is seen nearly edge-on.
// Perspective: only hits beyond the near plane (the eye may be inside the mesh).
double value_at_entry(const Mesh& m, const Projector& p, std::uint32_t t, const double o[3],
                      const double d[3], double margin, double near) {
  static const int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  double c[4][3], f[4];
  for (int k = 0; k < 4; ++k) {
    const double* w = &m.xyz[3 * std::size_t(m.tet[4 * std::size_t(t) + std::size_t(k)])];
    p.to_camera(w, c[k]);
    f[k] = linear_field(w);
  }
  double best_s = 1e300, best = std::nan("");
  for (const auto& face : kFaces) {
    const double* A = c[face[0]];
    const double* B = c[face[1]];
    const double* C = c[face[2]];
    // Solve o + s d = A + u (B - A) + v (C - A) by Cramer's rule.
    const double e1[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]},
                 e2[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
    const double h[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2],
                         d[0] * e2[1] - d[1] * e2[0]};
    const double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
    if (std::abs(det) < 1e-300) continue;
    const double sv[3] = {o[0] - A[0], o[1] - A[1], o[2] - A[2]};
    const double uu = (sv[0] * h[0] + sv[1] * h[1] + sv[2] * h[2]) / det;
    const double q[3] = {sv[1] * e1[2] - sv[2] * e1[1], sv[2] * e1[0] - sv[0] * e1[2],
                         sv[0] * e1[1] - sv[1] * e1[0]};
    const double vv = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
    const double s = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    if (uu < -1e-9 || vv < -1e-9 || uu + vv > 1 + 1e-9) continue;
    if (p.perspective && s * d[2] < near) continue;  // behind the near plane: not drawn
    if (s < best_s) {
      best_s = s;
      best = (1 - uu - vv) * f[face[0]] + uu * f[face[1]] + vv * f[face[2]];
      // A face seen nearly edge-on projects to a sliver whose corners' snapping to 1/256 pixel moves
      // the interpolation by whole entries: not a clear sample (|cos| of the ray to the normal < 0.2).
      const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                           e1[0] * e2[1] - e1[1] * e2[0]};
      const double cosine =
          (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) /
          std::sqrt((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
      if (std::abs(cosine) < 0.2) best = std::nan("");
      // Within `margin` of the entry face's edges: the pixel may be drawn by a neighbouring face.
      if (uu < margin || vv < margin || uu + vv > 1 - margin) best = std::nan("");
    }
  }
  return best;
}

TEST(FieldRender, GradedFacesInterpolateTheFieldLinearly) {
  const Mesh m = grid_with_linear_field();
  const SphereTable table = compute_spheres(m);
  const FieldChoice choice = choose_field(m, "f");
  ColorScale s;
  s.map = ColorMapId::rainbow;  // Turbo: neighbouring entries differ most
  const auto range = finite_range(field_scalar_values(m, choice));
  s.lo = range.first;
  s.hi = range.second;
  auto paint = std::make_shared<FieldPaint>(graded_field_paint(tet_corner_values(m, choice), s));
  RenderParams rp;
  rp.edges = false;
  rp.field = paint;
  std::size_t checked = 0, exact = 0;
  std::vector<int> seen(256, 0);
  for (const Camera& cam : test::random_cameras(m, 9, 5, double(kW) / kH)) {
    TetRasterizer r(m, cam, kW, kH, rp);
    Framebuffer fb(kW, kH);
    r.draw(fb, visibility_order(m, table, view_of(cam)));
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const std::uint32_t t = fb.id[fb.index(x, y)];
        if (t == kNone) continue;
        double o[3], d[3];
        test::pixel_ray(r.projector(), x, y, o, d);
        const double v = value_at_entry(m, r.projector(), t, o, d, 1e-3, r.near_plane());
        if (std::isnan(v)) continue;  // along an edge: the face is not clear
        const int entry = int(std::clamp(std::floor(s.position(v) * 256), 0.0, 255.0));
        const std::vector<int> can = decode(fb.rgba[fb.index(x, y)], s.map, paint->shade_min);
        ASSERT_FALSE(can.empty());
        // Within one entry: the pixel's position is interpolated from snapped corners in float.
        EXPECT_TRUE(std::abs(can.front() - entry) <= 1 || std::abs(can.back() - entry) <= 1)
            << (cam.perspective ? "perspective " : "orthographic ") << "pixel " << x << "," << y << " value "
            << v << " entry " << entry << " decoded " << can.front() << ".." << can.back();
        exact += std::find(can.begin(), can.end(), entry) != can.end();
        ++seen[std::size_t(entry)];
        ++checked;
      }
  }
  int distinct = 0;
  for (int n : seen) distinct += n > 0;
  EXPECT_GT(checked, 20000u);
  EXPECT_GT(distinct, 150);  // the faces really are graded, not flat
  EXPECT_GT(double(exact), 0.95 * double(checked));
  std::printf("graded: %zu pixels, %.2f%% show exactly their entry, %d entries seen\n", checked,
              100.0 * double(exact) / double(checked), distinct);
}

TEST(FieldRender, PainterEqualsDepthBufferWithFieldColours) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 400, 23);
  test::regions_along_x(m, 0.35, 0.7);
  Field cell{"c", FieldLocation::cell, 1, "", {}, {}};
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  for (std::size_t t = 0; t < m.tet_count(); ++t) cell.values.push_back(u(rng));
  Field node{"n", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n) node.values.push_back(linear_field(&m.xyz[3 * n]));
  m.fields = {cell, node};
  const SphereTable table = compute_spheres(m);
  std::size_t compared = 0, ties = 0;
  for (const char* name : {"c", "n"})
    for (bool graded : {false, true}) {
      const FieldChoice choice = choose_field(m, name);
      ColorScale s;
      const std::vector<double> values =
          graded ? tet_corner_values(m, choice) : tet_centroid_values(m, choice);
      std::tie(s.lo, s.hi) = finite_range(values);
      RenderParams pp;
      pp.field =
          std::make_shared<FieldPaint>(graded ? graded_field_paint(values, s) : flat_field_paint(values, s));
      RenderParams zp = pp;
      zp.depth_buffer = true;
      RenderParams plain;  // region colours: the same geometry
      for (const Camera& cam : test::random_cameras(m, 8, 19, double(kW) / kH)) {
        const std::vector<std::uint32_t> order = visibility_order(m, table, view_of(cam));
        const Framebuffer painter = render_tets(m, cam, kW, kH, order, pp);
        const Framebuffer zbuf = render_tets(m, cam, kW, kH, order, zp);
        const Framebuffer regions = render_tets(m, cam, kW, kH, order, plain);
        EXPECT_EQ(painter.id, regions.id);  // colours do not move a pixel
        for (std::size_t p = 0; p < painter.rgba.size(); ++p) {
          if (painter.id[p] != zbuf.id[p]) {
            ++ties;  // equal depth along an edge: either tet (see rasterizer_test)
            continue;
          }
          ++compared;
          ASSERT_EQ(painter.rgba[p], zbuf.rgba[p])
              << name << (graded ? " graded" : " flat") << " pixel " << p;
        }
      }
    }
  EXPECT_GT(compared, 50000u);
  EXPECT_LT(ties, compared / 500);
}

// Graded colours undrawn: draw a prefix of the order, undraw part of it, and the picture equals drawing
// the shorter prefix from scratch, pixel for pixel (colours and ids). A cell field averaged per
// region gives a node different positions on either side of an interface, so a repainted face must
// take its own tet's positions, not the undrawn tet's; eyes inside the mesh clip faces.
TEST(FieldRender, GradedUndrawEqualsDrawingFromScratch) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 300, 41);
  test::regions_along_x(m, 0.3, 0.6);
  Field cell{"c", FieldLocation::cell, 1, "", {}, {}};
  for (std::size_t t = 0; t < m.tet_count(); ++t)
    cell.values.push_back(m.region_of(t) + 0.2 * std::sin(7.0 * double(t)));
  Field node{"n", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n) node.values.push_back(linear_field(&m.xyz[3 * n]));
  m.fields = {cell, node};
  const SphereTable table = compute_spheres(m);
  std::mt19937 rng(4);
  std::size_t compared = 0;
  for (const char* name : {"c", "n"}) {
    const FieldChoice choice = choose_field(m, name);
    const std::vector<double> corners = tet_corner_values(m, choice);
    ColorScale s;
    s.map = ColorMapId::rainbow;
    std::tie(s.lo, s.hi) = finite_range(corners);
    RenderParams fresh;
    fresh.field = std::make_shared<FieldPaint>(graded_field_paint(corners, s));
    RenderParams undoable = fresh;
    undoable.undoable = true;
    for (const Camera& cam : test::random_cameras(m, 9, 29, double(kW) / kH)) {
      const std::vector<std::uint32_t> order = visibility_order(m, table, view_of(cam));
      const std::span<const std::uint32_t> all(order);
      const std::size_t k = order.size() / 2 + rng() % (order.size() / 2 + 1), j = rng() % (k + 1);
      TetRasterizer r(m, cam, kW, kH, undoable);
      Framebuffer fb(kW, kH);
      r.draw(fb, all.first(k / 2));
      r.draw(fb, all.subspan(k / 2, k - k / 2));
      r.undraw(fb, (k - j) / 3);
      r.undraw(fb, k - j - (k - j) / 3);
      const Framebuffer want = render_tets(m, cam, kW, kH, all.first(j), fresh);
      std::size_t differ = 0;
      for (std::size_t p = 0; p < want.rgba.size(); ++p)
        differ += want.rgba[p] != fb.rgba[p] || want.id[p] != fb.id[p];
      EXPECT_EQ(differ, 0u) << name << " k " << k << " j " << j << " of " << order.size();
      compared += want.rgba.size();
    }
  }
  EXPECT_GT(compared, 200000u);
}

TEST(FieldRender, BadPaintsAreRefused) {
  const Mesh m = grid_with_linear_field();
  Camera cam;
  RenderParams rp;
  auto paint = std::make_shared<FieldPaint>();
  paint->tet_color.resize(3);
  rp.field = paint;
  EXPECT_THROW(TetRasterizer(m, cam, 10, 10, rp), std::invalid_argument);
  auto graded = std::make_shared<FieldPaint>(
      graded_field_paint(tet_corner_values(m, choose_field(m, "f")), ColorScale{}));
  graded->corner_position.pop_back();
  rp.field = graded;
  EXPECT_THROW(TetRasterizer(m, cam, 10, 10, rp), std::invalid_argument);
  auto shade = std::make_shared<FieldPaint>(
      flat_field_paint(tet_centroid_values(m, choose_field(m, "f")), ColorScale{}));
  shade->shade_min = 1.5;
  rp.field = shade;
  EXPECT_THROW(TetRasterizer(m, cam, 10, 10, rp), std::invalid_argument);
}

}  // namespace
}  // namespace foxi
