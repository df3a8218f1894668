// The PLC clean-up and surface steps of the conforming refinement (mesher/src internals): coordinate
// snapping, joining coplanar facet pieces, re-triangulating edited facets, and the surface rescue.
// Oracles: the exact geometry of the boxes (volumes, areas per marker, through TetGen's mesh of the
// edited PLC) and the exact Delaunay certificate.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "coplanar_facets.hpp"
#include "facet_triangulation.hpp"
#include "foxi/mesher/conforming.hpp"
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/plc.hpp"
#include "plc_edit.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

std::map<std::int32_t, double> areas(const Mesh& m) {
  std::map<std::int32_t, double> a;
  for (std::size_t f = 0; f < m.bface_count(); ++f) {
    const detail::Vec p = detail::at(m.xyz, m.bface[3 * f]), q = detail::at(m.xyz, m.bface[3 * f + 1]),
                      r = detail::at(m.xyz, m.bface[3 * f + 2]);
    a[m.bface_tag[f]] += 0.5 * std::sqrt(detail::norm2(detail::cross(detail::sub(q, p), detail::sub(r, p))));
  }
  return a;
}

std::map<std::int32_t, double> volumes(const Mesh& m) { return detail::region_volumes(m); }

std::uint32_t point(Plc& plc, double x, double y, double z) {
  plc.points.insert(plc.points.end(), {x, y, z});
  return static_cast<std::uint32_t>(plc.point_count() - 1);
}

// A 4x4x1 slab (region 1) under a 2x2x1 block (region 2) standing on its middle. The slab's top is a
// triangle soup: the exposed ring (marker 5) fanned in slivers from the block's corners to the slab's,
// and the interface (marker 6) as two triangles. Other faces: marker 1 (slab), 2 (block).
Plc slab_and_block() {
  Plc plc;
  const std::uint32_t s[8] = {point(plc, 0, 0, 0), point(plc, 4, 0, 0), point(plc, 4, 4, 0),
                              point(plc, 0, 4, 0), point(plc, 0, 0, 1), point(plc, 4, 0, 1),
                              point(plc, 4, 4, 1), point(plc, 0, 4, 1)};
  const std::uint32_t b[8] = {point(plc, 1, 1, 1), point(plc, 3, 1, 1), point(plc, 3, 3, 1),
                              point(plc, 1, 3, 1), point(plc, 1, 1, 2), point(plc, 3, 1, 2),
                              point(plc, 3, 3, 2), point(plc, 1, 3, 2)};
  // Slab bottom and sides.
  plc.add_facet({s[0], s[1], s[2], s[3]}, 1);
  plc.add_facet({s[0], s[1], s[5], s[4]}, 1);
  plc.add_facet({s[1], s[2], s[6], s[5]}, 1);
  plc.add_facet({s[2], s[3], s[7], s[6]}, 1);
  plc.add_facet({s[3], s[0], s[4], s[7]}, 1);
  // The ring, as triangles: each slab top edge with a block corner, and each block edge with a slab corner.
  for (int i = 0; i < 4; ++i) {
    plc.add_facet({s[4 + i], s[4 + (i + 1) % 4], b[(i + 1) % 4]}, 5);
    plc.add_facet({s[4 + i], b[(i + 1) % 4], b[i]}, 5);
  }
  // The interface.
  plc.add_facet({b[0], b[1], b[2]}, 6);
  plc.add_facet({b[0], b[2], b[3]}, 6);
  // Block sides and top.
  for (int i = 0; i < 4; ++i) plc.add_facet({b[i], b[(i + 1) % 4], b[4 + (i + 1) % 4], b[4 + i]}, 2);
  plc.add_facet({b[4], b[5], b[6], b[7]}, 2);
  plc.regions.push_back({{0.5, 0.5, 0.5}, 1, 0});
  plc.regions.push_back({{2, 2, 1.5}, 2, 0});
  return plc;
}

void expect_slab_and_block_geometry(const Mesh& m) {
  const auto v = volumes(m);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_NEAR(v.at(1), 16.0, 1e-12);
  EXPECT_NEAR(v.at(2), 4.0, 1e-12);
  const auto a = areas(m);
  EXPECT_NEAR(a.at(1), 16.0 + 4 * 4.0, 1e-12);
  EXPECT_NEAR(a.at(5), 16.0 - 4.0, 1e-12);
  EXPECT_NEAR(a.at(6), 4.0, 1e-12);
  EXPECT_NEAR(a.at(2), 4 * 2.0 + 4.0, 1e-12);
}

TEST(PlcCleanup, SnapMakesRoundingDifferencesEqualAndLeavesRealOnesAlone) {
  Plc plc = slab_and_block();
  plc.points[3 * 4] = std::nextafter(0.0, 1.0);      // slab corner x: one rounding step off 0
  plc.points[3 * 9 + 1] = std::nextafter(1.0, 2.0);  // block corner y: one step off 1
  plc.points[3 * 10 + 2] = 1 + 1e-6;                 // a real offset: kept
  EXPECT_EQ(detail::snap_coordinates(plc), 2u);
  EXPECT_EQ(plc.points[3 * 4], 0.0);
  EXPECT_EQ(plc.points[3 * 9 + 1], 1.0);
  EXPECT_EQ(plc.points[3 * 10 + 2], 1 + 1e-6);
}

TEST(PlcCleanup, CoplanarPiecesJoinIntoOneFacetWithAHoleAndTheGeometryStays) {
  Plc plc = slab_and_block();
  const Mesh before = mesh_plc(plc, {});
  expect_slab_and_block_geometry(before);
  const std::size_t facets = plc.facet_count();
  const detail::CoplanarMerge r = detail::merge_coplanar_facets(plc);
  // The ring's 8 slivers become one facet (outer square, hole loop, hole point); the interface's 2
  // triangles one facet.
  EXPECT_EQ(r.groups, 2u);
  EXPECT_EQ(r.groups_skipped, 0u);
  EXPECT_EQ(plc.facet_count(), facets - 8);
  std::size_t with_hole = 0;
  for (std::size_t f = 0; f < plc.facet_count(); ++f)
    if (plc.facet_hole_begin[f + 1] > plc.facet_hole_begin[f]) {
      ++with_hole;
      EXPECT_EQ(plc.facet_marker[f], 5);
      const double* h = &plc.facet_holes[3 * plc.facet_hole_begin[f]];
      EXPECT_GT(h[0], 1);
      EXPECT_LT(h[0], 3);
      EXPECT_GT(h[1], 1);
      EXPECT_LT(h[1], 3);
      EXPECT_EQ(h[2], 1);
    }
  EXPECT_EQ(with_hole, 1u);
  const Mesh after = mesh_plc(plc, {});
  expect_slab_and_block_geometry(after);
}

TEST(PlcCleanup, EditedFacetsBecomeTrianglesCoveringTheSameSurface) {
  Plc plc = slab_and_block();
  detail::merge_coplanar_facets(plc);
  // Points on the ring's outer edge and inside it, as a refinement round adds them.
  detail::EditablePlc edit(plc);
  const std::uint32_t k = edit.add_point({2, 0, 1});
  edit.split_segment(4, 5, k);  // slab top edge (0,0,1)-(4,0,1)
  const std::uint32_t c = edit.add_point({0.5, 2, 1});
  const std::size_t ring = edit.facet_at({0.5, 2, 1});
  ASSERT_LT(ring, edit.facets.size());
  EXPECT_EQ(plc.facet_marker[ring], 5);
  edit.facet_points[ring].push_back(c);
  edit.write_back();
  const std::size_t written = detail::triangulate_facets(plc);
  EXPECT_GT(written, 8u);
  // The edited facets (the ring with its hole, the split side wall) are triangles now.
  for (std::size_t f = 0; f < plc.facet_count(); ++f)
    if (plc.facet_marker[f] == 5) {
      EXPECT_EQ(plc.facet_hole_begin[f + 1], plc.facet_hole_begin[f]);
      ASSERT_EQ(plc.facet_polygon_begin[f + 1] - plc.facet_polygon_begin[f], 1u);
      const std::uint32_t g = plc.facet_polygon_begin[f];
      EXPECT_EQ(plc.polygon_vertex_begin[g + 1] - plc.polygon_vertex_begin[g], 3u);
    }
  std::size_t triangles_with_c = 0, triangles_with_k = 0;
  for (std::size_t f = 0; f < plc.facet_count(); ++f)
    for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g)
      for (std::uint32_t i = plc.polygon_vertex_begin[g]; i < plc.polygon_vertex_begin[g + 1]; ++i) {
        triangles_with_c += plc.polygon_vertices[i] == c;
        triangles_with_k += plc.polygon_vertices[i] == k;
      }
  EXPECT_GE(triangles_with_c, 3u);  // inside the ring: a fan around it
  EXPECT_GE(triangles_with_k, 3u);  // on the slab's edge: ring triangles and the split side wall
  MeshParams no_refinement;
  no_refinement.radius_edge = 0;
  const Mesh m = mesh_plc(plc, no_refinement);
  expect_slab_and_block_geometry(m);
  EXPECT_EQ(m.node_count(), plc.point_count());  // TetGen needed no point of its own
}

TEST(PlcCleanup, SurfaceRescueCertifiesFromTheFirstMesh) {
  // No conforming rounds of the usual kind: the rescue refines TetGen's first mesh's own surface.
  const Plc plc = read_poly(test::data_dir() + "/cdt/floating_facets_q1414.poly");
  MeshParams params;
  params.radius_edge = 1.414;
  ConformingParams cp;
  cp.max_iterations = 0;
  cp.surface_rescue = true;
  ConformingReport report;
  const Mesh m = mesh_conforming(plc, params, cp, &report);
  EXPECT_FALSE(report.violations.empty());
  EXPECT_GT(report.violations.front(), 0u);
  EXPECT_GE(report.surface_rounds, 1u);
  const DelaunayCertificate cert = compute_delaunay_certificate(m);
  EXPECT_TRUE(cert.delaunay) << cert.violating_tet_count << " violations left";
  EXPECT_TRUE(report.delaunay);
  EXPECT_NEAR(volumes(m).begin()->second, 1.0, 1e-12);
  const Mesh plain = mesh_plc(plc, params);
  const auto a0 = areas(plain), a1 = areas(m);
  ASSERT_EQ(a0.size(), a1.size());
  for (const auto& [tag, area] : a0) EXPECT_NEAR(a1.at(tag), area, 1e-12) << "marker " << tag;
}

}  // namespace
}  // namespace foxi
