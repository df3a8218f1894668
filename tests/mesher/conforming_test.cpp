// Conforming Delaunay refinement, checked with the exact global certificate (CGAL predicates) on a
// corpus of PLCs where TetGen -O0 is NOT Delaunay (tests/data/cdt: found by a random PLC generator,
// tilted and floating facets in a unit cube): the plain TetGen mesh must fail the certificate (so the
// case is real), the refined one must pass it, with the same region volume and boundary areas
// (points were only added on facets and segments), within the point budget.
#include "foxi/mesher/conforming.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "foxi/model/delaunay.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/quality.hpp"
#include "foxi/model/validate.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

std::string corpus(const std::string& name) { return test::data_dir() + "/cdt/" + name; }

double tri_area(const Mesh& m, std::size_t f) {
  const double* p = &m.xyz[3 * m.bface[3 * f]];
  const double* q = &m.xyz[3 * m.bface[3 * f + 1]];
  const double* r = &m.xyz[3 * m.bface[3 * f + 2]];
  const double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, w[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
  const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

std::map<std::int32_t, double> areas(const Mesh& m) {
  std::map<std::int32_t, double> a;
  for (std::size_t f = 0; f < m.bface_count(); ++f) a[m.bface_tag[f]] += tri_area(m, f);
  return a;
}

struct Case {
  const char* file;
  double radius_edge;
  double max_volume = 0;
};

class Corpus : public ::testing::TestWithParam<Case> {};

TEST_P(Corpus, RefinementMakesTheO0MeshDelaunay) {
  const Plc plc = read_poly(corpus(GetParam().file));
  MeshParams params;
  params.radius_edge = GetParam().radius_edge;
  params.max_volume = GetParam().max_volume;
  const Mesh plain = mesh_plc(plc, params);
  const DelaunayCertificate before = compute_delaunay_certificate(plain);
  ASSERT_FALSE(before.delaunay) << "the corpus case no longer fails with TetGen -O0";
  EXPECT_GT(before.violating_tet_count, 0u);

  ConformingReport report;
  Plc refined;
  const Mesh m = mesh_conforming(plc, params, {}, &report, &refined);
  const DelaunayCertificate after = compute_delaunay_certificate(m);
  EXPECT_TRUE(after.delaunay) << after.violating_tet_count << " violations left";
  EXPECT_TRUE(report.delaunay);
  EXPECT_EQ(report.first_mesh_violations, before.violating_tet_count);
  EXPECT_GT(report.added_points, 0u);
  if (report.surface_rounds == 0)
    EXPECT_EQ(refined.point_count(), plc.point_count() + report.added_points);
  else  // the surface PLC also holds the Steiner points TetGen added before the surface rounds
    EXPECT_GE(refined.point_count(), plc.point_count() + report.added_points);
  EXPECT_LE(report.added_points, std::max<std::size_t>(100, report.first_mesh_points * 15 / 100));
  EXPECT_GE(report.iterations, 1u);
  EXPECT_EQ(report.violations.size(), report.iterations + 1);
  EXPECT_EQ(report.violations.back(), 0u);
  EXPECT_TRUE(validate(m).ok());

  // Same geometry: the unit cube's volume, and each marker's area as in TetGen's unrefined mesh.
  EXPECT_NEAR(summarize_quality(m).total_volume, 1.0, 1e-12);
  const auto a0 = areas(plain), a1 = areas(m);
  ASSERT_EQ(a0.size(), a1.size());
  for (const auto& [tag, area] : a0) EXPECT_NEAR(a1.at(tag), area, 1e-12) << "marker " << tag;
  // Every added point lies in the cube (on a facet or a segment of it).
  for (std::size_t i = plc.point_count(); i < refined.point_count(); ++i)
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(refined.points[3 * i + std::size_t(k)], -1e-12);
      EXPECT_LE(refined.points[3 * i + std::size_t(k)], 1 + 1e-12);
    }
}

INSTANTIATE_TEST_SUITE_P(Cdt, Corpus,
                         ::testing::Values(Case{"tilted_facets_q1414.poly", 1.414},
                                           Case{"floating_triangles_p.poly", 0},
                                           Case{"floating_facets_p.poly", 0},
                                           Case{"floating_facets_q1414.poly", 1.414},
                                           Case{"floating_facets_q1414_a0002.poly", 1.414, 0.002}),
                         [](const ::testing::TestParamInfo<Case>& p) {
                           std::string n = p.param.file;
                           return n.substr(0, n.find('.'));
                         });

TEST(Conforming, SplitPointsLieOnTheEncroachedConstraints) {
  // Floating triangles in a cube, meshed without quality refinement: constraint triangles separate
  // tets from vertices inside their circumspheres.
  const Plc plc = read_poly(corpus("floating_triangles_p.poly"));
  MeshParams params;
  params.radius_edge = 0;
  const Mesh m = mesh_plc(plc, params);
  const DelaunayCertificate cert = compute_delaunay_certificate(m);
  ASSERT_FALSE(cert.delaunay);
  Plc refined = plc;
  const std::size_t n = split_encroached_constraints(m, cert.violating_tets, refined);
  ASSERT_GT(n, 0u);
  // Each new point is a vertex of some polygon of some facet (a facet point or a segment split),
  // and lies in that facet's plane.
  for (std::uint32_t k = static_cast<std::uint32_t>(plc.point_count()); k < refined.point_count(); ++k) {
    bool found = false;
    for (std::size_t f = 0; f < refined.facet_count() && !found; ++f)
      for (std::uint32_t g = refined.facet_polygon_begin[f]; g < refined.facet_polygon_begin[f + 1] && !found;
           ++g)
        for (std::uint32_t v = refined.polygon_vertex_begin[g]; v < refined.polygon_vertex_begin[g + 1]; ++v)
          if (refined.polygon_vertices[v] == k) found = true;
    EXPECT_TRUE(found) << "point " << k << " is in no facet";
  }
  // No tet violation: nothing to split.
  Plc untouched = plc;
  EXPECT_EQ(split_encroached_constraints(m, {}, untouched), 0u);
  EXPECT_EQ(untouched.point_count(), plc.point_count());
}

// A box PLC (metres) from the origin to (w, w, l).
Plc bar_plc(double w, double l) {
  Plc plc;
  plc.points = {0, 0, 0, w, 0, 0, w, w, 0, 0, w, 0, 0, 0, l, w, 0, l, w, w, l, 0, w, l};
  plc.add_facet({0, 1, 2, 3}, 1);
  plc.add_facet({4, 5, 6, 7}, 2);
  plc.add_facet({0, 1, 5, 4}, 3);
  plc.add_facet({1, 2, 6, 5}, 3);
  plc.add_facet({2, 3, 7, 6}, 3);
  plc.add_facet({3, 0, 4, 7}, 3);
  plc.regions.push_back(RegionSeed{{w / 2, w / 2, l / 2}, 1, 0});
  return plc;
}

// |6V| / (longest edge)^3 of the flattest tet, computed here.
double flattest(const Mesh& m) {
  double least = 1;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const double* p[4];
    for (int k = 0; k < 4; ++k) p[k] = &m.xyz[3 * m.tet[4 * t + std::size_t(k)]];
    double e[3][3], longest = 0;
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) e[k][c] = p[k + 1][c] - p[0][c];
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        longest = std::max(longest, std::hypot(p[i][0] - p[j][0], p[i][1] - p[j][1], p[i][2] - p[j][2]));
    const double six_v = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                         e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                         e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    least = std::min(least, std::abs(six_v) / (longest * longest * longest));
  }
  return least;
}

// Square bars meshed at sizes that put TetGen's Steiner points at the midpoints of the four sides at
// one height (an outside probe's copper bar): four nearly coplanar, cocircular points, and a flat tet
// across them in TetGen's Delaunay mesh (6V 1e-17 of the edges cubed; the solvers' matrix singular).
// Without the removal (flat_tet_bound 0) such tets are there, so the case is real; with it none is,
// and the mesh is still certified, valid, and of the bar's volume.
TEST(Conforming, FlatTetsOfSymmetricSteinerPointsAreRemoved) {
  const std::pair<double, double> bars[] = {
      {0.5e-3, 0.4e-3}, {0.5e-3, 0.5e-3}, {0.5e-3, 0.7e-3}, {0.3e-3, 0.2e-3}, {0.77e-3, 1.2e-3}};
  std::size_t flat_before = 0, removed = 0;
  for (const auto& [size, w] : bars) {
    SCOPED_TRACE("size " + std::to_string(size) + " width " + std::to_string(w));
    const Plc plc = bar_plc(w, 10e-3);
    MeshParams params;
    params.max_volume = size * size * size / (6 * std::sqrt(2.0));
    ConformingParams keep;
    keep.flat_tet_bound = 0;
    const Mesh plain = mesh_conforming(plc, params, keep);
    flat_before += flattest(plain) < 1e-9;
    ConformingReport report;
    const Mesh m = mesh_conforming(plc, params, {}, &report);
    removed += report.flat_tets_removed;
    EXPECT_GE(flattest(m), 1e-9);
    EXPECT_EQ(report.flat_tets, 0u);
    EXPECT_TRUE(compute_delaunay_certificate(m).delaunay);
    EXPECT_TRUE(validate(m).clean()) << describe(validate(m)).front();
    double volume = 0;
    for (std::size_t t = 0; t < m.tet_count(); ++t) {
      const std::uint32_t* v = &m.tet[4 * t];
      volume += std::abs(
          tet_quality(&m.xyz[3 * v[0]], &m.xyz[3 * v[1]], &m.xyz[3 * v[2]], &m.xyz[3 * v[3]]).volume);
    }
    EXPECT_NEAR(volume, w * w * 10e-3, 1e-12 * w * w * 10e-3);
  }
  EXPECT_GE(flat_before, 3u);  // 4 of the 5 with TetGen 1.5 (Debian)
  EXPECT_GE(removed, flat_before);
}

TEST(Conforming, CancelStops) {
  const Plc plc = read_poly(corpus("tilted_facets_q1414.poly"));
  MeshParams params;
  int calls = 0;
  params.progress = [&](std::string_view stage, double) {
    ++calls;
    return stage != "conforming refinement";
  };
  EXPECT_THROW(mesh_conforming(plc, params), MesherError);
  EXPECT_GE(calls, 1);
}

}  // namespace
}  // namespace foxi
