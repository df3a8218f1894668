// select_field_tets against independent oracles (issue 17 items 4 and 5): a slice combined with a
// threshold and a crinkle clip selects exactly the brute-force intersection of the plane's cut
// (crossing_scan), the threshold (threshold_tets) and the clip (clip_tets), and draws the same pixels by
// the painter as by the depth buffer; a cell field's isosurface is found in its per-region nodal
// values (volume-weighted averages over each region's own tets, computed here), so it never averages
// across a material interface and is closed within each region.
#include "foxi/viz/field_selection.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "foxi/viz/camera.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/spheres.hpp"
#include "mesh_factory.hpp"
#include "random_cameras.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr int kW = 160, kH = 120;

double volume(const Mesh& m, std::size_t t) {
  const double* a = &m.xyz[3 * std::size_t(m.tet[4 * t])];
  double e[3][3];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      e[i][k] = m.xyz[3 * std::size_t(m.tet[4 * t + std::size_t(i) + 1]) + std::size_t(k)] - a[k];
  return std::abs(e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                  e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                  e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
         6;
}

std::vector<std::uint32_t> intersection(std::vector<std::uint32_t> a, std::vector<std::uint32_t> b) {
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  std::vector<std::uint32_t> r;
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(r));
  return r;
}

TEST(FieldSelection, SliceCombinesWithThresholdAndClip) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 1500, 3);
  Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n) {
    const double* p = &m.xyz[3 * n];
    t.values.push_back(300 + 50 * p[0] * p[0] + 30 * p[1] - 20 * p[2]);
  }
  m.fields = {t};
  const FieldChoice choice = choose_field(m, "temperature");
  ColorScale scale;
  scale.lo = 270;
  scale.hi = 360;
  Plane slice, clip;
  slice.p[0] = 0.5, slice.p[1] = 0.45, slice.p[2] = 0.5;
  slice.n[0] = 0.3, slice.n[1] = 1, slice.n[2] = 0.2;
  clip.p[0] = 0.6, clip.p[1] = 0.5, clip.p[2] = 0.5;
  clip.n[0] = 1, clip.n[1] = 0, clip.n[2] = 0.4;
  const std::vector<std::uint32_t> cut = crossing_scan(plane_corner_values(m, slice), 0);
  const std::vector<std::uint32_t> warm = threshold_tets(tet_centroid_values(m, choice), 305, 330);
  const std::vector<std::uint32_t> kept = clip_tets(m, clip);
  const SphereTable table = compute_spheres(m);
  std::size_t pixels = 0;
  for (int combo = 0; combo < 3; ++combo) {
    SCOPED_TRACE(combo);
    FieldSelection s;
    s.slice = slice;
    if (combo != 1) s.threshold = std::pair{305.0, 330.0};
    if (combo != 0) s.clip = clip;
    const TetSelection r = select_field_tets(s, m, choice, 0, scale);
    std::vector<std::uint32_t> expected = cut;
    if (s.threshold) expected = intersection(expected, warm);
    if (s.clip) expected = intersection(expected, kept);
    std::vector<std::uint32_t> got = r.subset;
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, intersection(expected, expected));
    EXPECT_EQ(r.crossing, expected.size());
    EXPECT_TRUE(r.polygons);
    ASSERT_GT(expected.size(), 20u) << "the combination keeps part of the slice";
    EXPECT_LT(expected.size(), cut.size()) << "and narrows it";
    // Painter == depth buffer, the slice's polygons of the kept tets only.
    const IsoDrawing drawing = r.drawing();
    for (const Camera& cam : test::random_cameras(m, 3, 40 + unsigned(combo), double(kW) / kH)) {
      PictureParams pp;
      pp.render.edges = false;
      pp.subset = r.subset;
      pp.subset_exact = true;
      pp.iso = &drawing;
      Framebuffer a(kW, kH), b(kW, kH);
      draw_picture(m, table, cam, a, pp);
      pp.render.depth_buffer = true;
      draw_picture(m, table, cam, b, pp);
      std::size_t differ = 0;
      for (std::size_t p = 0; p < a.rgba.size(); ++p) {
        differ += a.rgba[p] != b.rgba[p] || a.id[p] != b.id[p];
        pixels += a.id[p] != kNone;
        if (a.id[p] != kNone) {
          EXPECT_TRUE(std::binary_search(expected.begin(), expected.end(), a.id[p]));
        }
      }
      EXPECT_EQ(differ, 0u);
    }
  }
  EXPECT_GT(pixels, 3000u);
}

// Two regions (x below and above 0.5) with a cell stress sigma_xx = base_r + 40 y + 30 z MPa at each
// tet's centroid, base 100 in region 1 and 300 in region 2: von Mises is sigma_xx.
TEST(FieldSelection, CellFieldIsoUsesEachRegionsOwnNodeValues) {
  Mesh m = test::grid_mesh(8, 4, 4, 0.125, 0.25, 0.25, 6);
  test::regions_along_x(m, 0.5, 2);
  Field s{"stress", FieldLocation::cell, 6, "Pa", {}, {}};
  for (std::size_t e = 0; e < m.tet_count(); ++e) {
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j)
        c[j] += 0.25 * m.xyz[3 * std::size_t(m.tet[4 * e + std::size_t(k)]) + std::size_t(j)];
    const double base = m.region_of(e) == 1 ? 100 : 300;
    for (double v : {base + 40 * c[1] + 30 * c[2], 0.0, 0.0, 0.0, 0.0, 0.0}) s.values.push_back(v * 1e6);
  }
  m.fields = {s};
  const FieldChoice choice = choose_field(m, "stress");
  ASSERT_EQ(choice.scalar.kind, FieldScalar::Kind::von_mises);
  // The oracle: per region and node, the volume-weighted mean of sigma_xx over the region's tets there.
  std::map<std::pair<std::int32_t, std::uint32_t>, std::pair<double, double>> sum;  // (sum v w, sum w)
  for (std::size_t e = 0; e < m.tet_count(); ++e)
    for (int k = 0; k < 4; ++k) {
      auto& [vw, w] = sum[{m.region_of(e), m.tet[4 * e + std::size_t(k)]}];
      const double vol = volume(m, e);
      vw += vol * s.values[6 * e];
      w += vol;
    }
  ColorScale scale;
  scale.lo = 100e6;
  scale.hi = 350e6;
  FieldSelection sel;
  sel.iso = {120e6};
  sel.iso_only = true;
  const TetSelection r = select_field_tets(sel, m, choice, 0, scale);
  ASSERT_TRUE(r.corner);
  const std::vector<double>& corner = *r.corner;
  for (std::size_t e = 0; e < m.tet_count(); ++e)
    for (int k = 0; k < 4; ++k) {
      const auto& [vw, w] = sum.at({m.region_of(e), m.tet[4 * e + std::size_t(k)]});
      ASSERT_NEAR(corner[4 * e + std::size_t(k)], vw / w, 1e-6) << "tet " << e << " corner " << k;
    }
  // Averaged across the interface, the nodes at x = 0.5 would hold about 200 MPa + ..., and 200 MPa
  // would cross the tets beside it: per region, no tet reaches from region 1's top to region 2's floor.
  sel.iso = {230e6};
  EXPECT_EQ(select_field_tets(sel, m, choice, 0, scale).crossing, 0u);
  // Each isosurface lies in its own region and is closed there: every polygon edge inside the region
  // is shared by two polygons (their common points have the same bits), the others lie on the
  // region's box faces (the mesh boundary or the interface).
  for (const auto& [value, region, x0, x1] :
       {std::tuple{120e6, 1, 0.0, 0.5}, std::tuple{330e6, 2, 0.5, 1.0}}) {
    SCOPED_TRACE(region);
    sel.iso = {value};
    const TetSelection q = select_field_tets(sel, m, choice, 0, scale);
    ASSERT_GT(q.crossing, 10u);
    std::map<std::array<double, 6>, int> edges;
    for (std::uint32_t t : q.subset) {
      EXPECT_EQ(m.region_of(t), region);
      const IsoPolygon p = iso_polygon(m, t, &corner[4 * std::size_t(t)], value);
      for (int i = 0; i < p.count; ++i) {
        const double* a = p.xyz[i];
        const double* b = p.xyz[(i + 1) % p.count];
        std::array<double, 6> key{a[0], a[1], a[2], b[0], b[1], b[2]};
        if (std::lexicographical_compare(b, b + 3, a, a + 3)) key = {b[0], b[1], b[2], a[0], a[1], a[2]};
        ++edges[key];
      }
    }
    const double lo[3] = {x0, 0, 0}, hi[3] = {x1, 1, 1};
    std::size_t open = 0;
    for (const auto& [e, count] : edges) {
      EXPECT_LE(count, 2);
      if (count == 2) continue;
      ++open;
      bool on_face = false;
      for (int k = 0; k < 3; ++k)
        for (double f : {lo[k], hi[k]})
          on_face = on_face ||
                    (std::abs(e[std::size_t(k)] - f) < 1e-12 && std::abs(e[std::size_t(k) + 3] - f) < 1e-12);
      EXPECT_TRUE(on_face) << "an open edge inside region " << region << " at (" << e[0] << ", " << e[1]
                           << ", " << e[2] << ")";
    }
    EXPECT_LT(open, edges.size() / 2);
  }
}

}  // namespace
}  // namespace foxi
