// A host's own arrays through MeshView (mesh_view.hpp), its own field and its own RGBA buffer with a
// stride (picture.hpp RgbaImage): the oracle is the same mesh copied into a foxi::Mesh and drawn through
// the Mesh path (itself checked against the depth buffer in picture_test): spheres, orders and pictures
// must agree bit for bit, the host's padding must stay untouched, and the field helpers must give what
// tet_corner_values gives for the same values as a foxi::Field (and, for a field constant per region,
// that constant: the analytic answer). The tet painter draws in place into an image of whole uint32
// pixels; other images are drawn into the scratch framebuffer and copied (both checked here).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_view.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/isosurface.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "mesh_factory.hpp"
#include "random_cameras.hpp"

namespace foxi {
namespace {

constexpr int kW = 150, kH = 110;
constexpr std::size_t kStride = 4 * 160 + 12;  // bytes: wider than a row, and not a multiple of 16
constexpr std::uint8_t kPad = 0xA5;

// The host's arrays: plain vectors it owns (a grid of Kuhn cubes with three regions along x).
struct HostArrays {
  std::vector<double> xyz;
  std::vector<std::uint32_t> tet;
  std::vector<std::int32_t> region;
};

HostArrays host_grid() {
  Mesh m = test::grid_mesh(8, 6, 5, 0.125, 1.0 / 6, 0.1, 6);
  test::regions_along_x(m, 0.3, 0.7);
  return {m.xyz, m.tet, m.tet_region};
}

Mesh copy_into_mesh(const HostArrays& h) {
  Mesh m;
  m.xyz = h.xyz;
  m.tet = h.tet;
  m.tet_region = h.region;
  return m;
}

// Rows of `image` against fb's colours; counts the bytes that differ and the padding bytes changed.
void compare_image(const std::vector<std::uint8_t>& image, const Framebuffer& fb, std::size_t& wrong,
                   std::size_t& padding) {
  wrong = padding = 0;
  for (int y = 0; y < fb.height; ++y)
    for (std::size_t b = 0; b < kStride; ++b) {
      const std::uint8_t got = image[std::size_t(y) * kStride + b];
      if (b >= 4 * std::size_t(fb.width)) {
        padding += got != kPad;
        continue;
      }
      const std::uint32_t px = fb.rgba[fb.index(int(b / 4), y)];
      wrong += got != std::uint8_t(px >> (8 * (b % 4)));
    }
}

TEST(MeshView, HostArraysOrderAndDrawAsTheSameMesh) {
  const HostArrays host = host_grid();
  const Mesh mesh = copy_into_mesh(host);
  DerivedCache derived;  // the host's: where the view's adjacency and certificate are kept
  MeshView view{host.xyz, host.tet, host.region, {}, {}, &derived};
  EXPECT_EQ(view.xyz.data(), host.xyz.data());  // no copy
  EXPECT_EQ(view.tet.data(), host.tet.data());

  EXPECT_TRUE(delaunay_certificate(view).delaunay);
  EXPECT_EQ(&delaunay_certificate(view), &delaunay_certificate(view));  // cached in `derived`
  const SphereTable vt = compute_spheres(view), mt = compute_spheres(mesh);
  EXPECT_EQ(vt.c, mt.c);
  EXPECT_EQ(vt.s, mt.s);
  EXPECT_EQ(vt.cluster_tets, mt.cluster_tets);

  std::vector<std::uint8_t> image(kStride * kH, kPad);
  const RgbaImage target{image.data(), kW, kH, kStride};
  Framebuffer scratch;
  for (const Camera& cam : test::random_cameras(mesh, 5, 7, double(kW) / kH)) {
    const View v = view_of(cam);
    EXPECT_EQ(visibility_order(view, vt, v), visibility_order(mesh, mt, v));
    EXPECT_EQ(mpvo_order(view, vt, v), mpvo_order(mesh, mt, v));

    Framebuffer fb(kW, kH);
    const PictureReport want = draw_picture(mesh, mt, cam, fb);
    const PictureReport got = draw_picture(view, vt, cam, target, scratch);
    EXPECT_TRUE(got.delaunay);
    EXPECT_FALSE(got.depth_buffer);
    EXPECT_EQ(got.tets_drawn, want.tets_drawn);
    EXPECT_EQ(scratch.id, fb.id);
    std::size_t wrong = 0, padding = 0;
    compare_image(image, fb, wrong, padding);
    EXPECT_EQ(wrong, 0u);
    EXPECT_EQ(padding, 0u);
  }
}

TEST(MeshView, HostFieldIsosurfaceIntoHostImage) {
  const HostArrays host = host_grid();
  DerivedCache derived;
  const MeshView view{host.xyz, host.tet, host.region, {}, {}, &derived};
  // The host's own solver arrays: a node field and a cell field.
  std::vector<double> node_t(view.node_count()), cell_q(view.tet_count());
  for (std::size_t v = 0; v < node_t.size(); ++v)
    node_t[v] =
        std::sin(std::numbers::pi * host.xyz[3 * v]) * (1 + host.xyz[3 * v + 1]) + host.xyz[3 * v + 2];
  for (std::size_t t = 0; t < cell_q.size(); ++t) cell_q[t] = 10.0 * view.region_of(t) + 0.01 * double(t % 7);

  // The oracle: the same values as foxi::Fields of a foxi::Mesh.
  Mesh mesh = copy_into_mesh(host);
  mesh.fields.push_back({"T", FieldLocation::node, 1, "K", {0}, node_t});
  mesh.fields.push_back({"q", FieldLocation::cell, 1, "W", {0}, cell_q});
  const std::vector<double> node_corners = node_corner_values(view, node_t);
  const std::vector<double> cell_corners = cell_corner_values(view, cell_q);
  EXPECT_EQ(node_corners, tet_corner_values(mesh, choose_field(mesh, "T")));
  EXPECT_EQ(cell_corners, tet_corner_values(mesh, choose_field(mesh, "q")));
  // A cell field constant per region: every corner gets its own tet's region value (no blending).
  std::vector<double> per_region(view.tet_count());
  for (std::size_t t = 0; t < per_region.size(); ++t) per_region[t] = 10.0 * view.region_of(t);
  const std::vector<double> pr = cell_corner_values(view, per_region);
  for (std::size_t i = 0; i < pr.size(); ++i) ASSERT_NEAR(pr[i], per_region[i / 4], 1e-12) << "corner " << i;
  EXPECT_THROW(node_corner_values(view, cell_q), std::invalid_argument);
  EXPECT_THROW(cell_corner_values(view, node_t), std::invalid_argument);

  IsoDrawing iso;
  iso.corner = node_corners;
  iso.params.values = {0.6, 1.2};
  iso.params.scale.lo = 0;
  iso.params.scale.hi = 2.5;
  PictureParams params;
  params.iso = &iso;
  std::vector<std::uint32_t> crossing;
  TetIntervals(node_corners).crossing_any(iso.params.values, crossing);
  params.subset = crossing;
  params.subset_exact = true;

  std::vector<std::uint8_t> image(kStride * kH, kPad);
  Framebuffer scratch;
  const SphereTable vt = compute_spheres(view), mt = compute_spheres(mesh);
  std::size_t shown = 0;
  for (const Camera& cam : test::random_cameras(mesh, 4, 3, double(kW) / kH)) {
    Framebuffer fb(kW, kH);
    draw_picture(mesh, mt, cam, fb, params);
    const PictureReport r =
        draw_picture(view, vt, cam, RgbaImage{image.data(), kW, kH, kStride}, scratch, params);
    EXPECT_EQ(r.tets_ordered, crossing.size());
    std::size_t wrong = 0, padding = 0;
    compare_image(image, fb, wrong, padding);
    EXPECT_EQ(wrong, 0u);
    EXPECT_EQ(padding, 0u);
    for (std::uint32_t id : fb.id) shown += id != kNone;
  }
  EXPECT_GT(shown, std::size_t(kW) * kH / 10);  // the isosurfaces cover part of every picture
}

// The tet painter draws straight into a host image whose rows are whole uint32 pixels (no copy pass):
// a sub-image at an offset inside a larger canvas, its stride not the width, each mode (painter, depth
// buffer, graded field, a stop) against the Mesh path's framebuffer, and every canvas byte outside the
// sub-image (padding, rows above and below, columns left and right) untouched. A stride or an address
// that is not 4-byte aligned takes the copy path: the same picture.
TEST(MeshView, HostImageDrawnInPlaceIsTheSamePicture) {
  const HostArrays host = host_grid();
  DerivedCache derived;
  const MeshView view{host.xyz, host.tet, host.region, {}, {}, &derived};
  const Mesh mesh = copy_into_mesh(host);
  const SphereTable vt = compute_spheres(view), mt = compute_spheres(mesh);
  std::vector<double> node_t(view.node_count());
  for (std::size_t v = 0; v < node_t.size(); ++v) node_t[v] = host.xyz[3 * v] + 2 * host.xyz[3 * v + 2];
  ColorScale scale;
  scale.lo = 0;
  scale.hi = 3;
  const auto graded =
      std::make_shared<const FieldPaint>(graded_field_paint(node_corner_values(view, node_t), scale));

  struct Layout {
    std::size_t stride, x0, y0, shift;  // bytes a row; the sub-image's first pixel; extra byte offset
  };
  const Layout layouts[] = {{4 * (kW + 9) + 8, 3, 5, 0},  // in place (stride and address 4-aligned)
                            {4 * kW + 6, 0, 2, 0},        // copy: the stride is not whole pixels
                            {4 * kW + 8, 1, 1, 1}};       // copy: the address is not 4-aligned
  const Camera cam = test::random_cameras(mesh, 3, 11, double(kW) / kH)[1];
  for (int mode = 0; mode < 4; ++mode) {
    PictureParams params;
    if (mode == 1) params.render.depth_buffer = true;
    if (mode == 2) params.render.field = graded;
    if (mode == 3) params.stop_fraction = 0.5;
    Framebuffer fb(kW, kH);
    draw_picture(mesh, mt, cam, fb, params);
    for (const Layout& l : layouts) {
      const std::size_t rows = l.y0 + kH + 3;
      std::vector<std::uint8_t> canvas(l.stride * rows + l.shift, kPad);
      std::uint8_t* origin = canvas.data() + l.shift + l.y0 * l.stride + 4 * l.x0;
      Framebuffer scratch;
      const PictureReport r =
          draw_picture(view, vt, cam, RgbaImage{origin, kW, kH, l.stride}, scratch, params);
      EXPECT_EQ(r.depth_buffer, mode == 1);
      // In place (scratch holds no colours) exactly where the rows are whole uint32 pixels.
      EXPECT_EQ(scratch.rgba.empty(), l.stride % 4 == 0 && l.shift == 0);
      EXPECT_EQ(scratch.id, fb.id) << "mode " << mode << " stride " << l.stride;
      std::size_t wrong = 0, outside = 0;
      for (std::size_t i = 0; i < canvas.size(); ++i) {
        const std::ptrdiff_t at = std::ptrdiff_t(i) - (origin - canvas.data());
        const std::ptrdiff_t y = at >= 0 ? at / std::ptrdiff_t(l.stride) : -1;
        const std::ptrdiff_t b = at >= 0 ? at % std::ptrdiff_t(l.stride) : 0;
        if (y < 0 || y >= kH || b >= 4 * kW) {
          outside += canvas[i] != kPad;
          continue;
        }
        const std::uint32_t px = fb.rgba[fb.index(int(b / 4), int(y))];
        wrong += canvas[i] != std::uint8_t(px >> (8 * (b % 4)));
      }
      EXPECT_EQ(wrong, 0u) << "mode " << mode << " stride " << l.stride;
      EXPECT_EQ(outside, 0u) << "mode " << mode << " stride " << l.stride;
    }
  }
  // An undoable picture keeps its colours in the framebuffer (undraw reads them back).
  RenderParams undoable;
  undoable.undoable = true;
  TetRasterizer raster(view, cam, kW, kH, undoable);
  Framebuffer fb(kW, kH);
  std::vector<std::uint32_t> rows(std::size_t(kW) * kH);
  const std::vector<std::uint32_t> order = visibility_order(view, vt, view_of(cam));
  EXPECT_THROW(raster.draw_into(fb, order, rows.data(), kW), std::logic_error);
}

TEST(MeshView, BadHostInputIsRefused) {
  const HostArrays host = host_grid();
  const MeshView no_cache{host.xyz, host.tet, host.region};
  EXPECT_THROW(delaunay_certificate(no_cache), std::invalid_argument);  // nowhere to keep it
  const SphereTable t = compute_spheres(copy_into_mesh(host));
  Framebuffer scratch;
  std::vector<std::uint8_t> image(kStride * kH, kPad);
  DerivedCache derived;
  const MeshView view{host.xyz, host.tet, host.region, {}, {}, &derived};
  const Camera cam = test::random_cameras(copy_into_mesh(host), 1, 1, 1.0)[0];
  EXPECT_THROW(draw_picture(view, t, cam, RgbaImage{image.data(), kW, kH, 4 * kW - 4}, scratch),
               std::invalid_argument);  // stride below a row
  EXPECT_THROW(draw_picture(view, t, cam, RgbaImage{nullptr, kW, kH, kStride}, scratch),
               std::invalid_argument);
  Framebuffer other(kW + 1, kH);
  EXPECT_THROW(copy_rgba(other, RgbaImage{image.data(), kW, kH, kStride}), std::invalid_argument);
  for (std::uint8_t b : image) ASSERT_EQ(b, kPad);  // nothing written on refusal
}

}  // namespace
}  // namespace foxi
