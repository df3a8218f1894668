// Meshing PLCs through TetGen's library, checked against analytic volumes and areas, against the
// tetgen program run on the same .poly, and against the Delaunay certificate.
#include "foxi/mesher/tetgen_mesher.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <regex>

#include "foxi/model/delaunay.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/validate.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

std::string example(const std::string& name) { return test::data_dir() + "/../../examples/" + name; }

double tet_volume(const Mesh& m, std::size_t t) {
  const double* p[4];
  for (int i = 0; i < 4; ++i) p[i] = &m.xyz[3 * m.tet[4 * t + i]];
  double a[3], b[3], c[3];
  for (int k = 0; k < 3; ++k) {
    a[k] = p[1][k] - p[0][k];
    b[k] = p[2][k] - p[0][k];
    c[k] = p[3][k] - p[0][k];
  }
  return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6;
}

double tri_area(const Mesh& m, std::size_t f) {
  const double* p = &m.xyz[3 * m.bface[3 * f]];
  const double* q = &m.xyz[3 * m.bface[3 * f + 1]];
  const double* r = &m.xyz[3 * m.bface[3 * f + 2]];
  double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, w[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
  double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

TEST(TetgenMesher, DieOnSubstrateRegionsAndBoundariesHaveAnalyticSizes) {
  Plc plc = read_poly(example("die_on_substrate.poly"));
  MeshParams params;
  params.max_volume = 2e-9;
  MeshReport report;
  Mesh m = mesh_plc(plc, params, &report);
  EXPECT_GT(m.tet_count(), 300u);
  EXPECT_TRUE(validate(m).ok());
  std::map<std::int32_t, double> volume, area;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    double v = tet_volume(m, t);
    EXPECT_GT(v, 0);  // positively oriented, as foxi's convention says
    volume[m.region_of(t)] += v;
  }
  for (std::size_t f = 0; f < m.bface_count(); ++f) area[m.bface_tag[f]] += tri_area(m, f);
  EXPECT_NEAR(volume[1], 0.010 * 0.008 * 0.001, 1e-18);        // substrate
  EXPECT_NEAR(volume[2], 0.004 * 0.003 * 0.0005, 1e-18);       // die
  EXPECT_NEAR(area[1], 0.010 * 0.008, 1e-15);                  // substrate bottom
  EXPECT_NEAR(area[3], 0.010 * 0.008 - 0.004 * 0.003, 1e-15);  // top ring around the die
  EXPECT_NEAR(area[4], 0.004 * 0.003, 1e-15);                  // die/substrate interface
  EXPECT_NEAR(area[6], 0.004 * 0.003, 1e-15);                  // die top
  EXPECT_NEAR(area[5], 2 * (0.004 + 0.003) * 0.0005, 1e-15);   // die sides
  EXPECT_GT(report.steiner_points, 0u);
}

TEST(TetgenMesher, ThreeMaterialViaIsDelaunayWithExactVolumes) {
  Plc plc = read_poly(example("via_in_dielectric.poly"));
  ASSERT_EQ(plc.regions.size(), 3u);
  MeshParams params;
  params.max_volume = 0.0005;
  Mesh m = mesh_plc(plc, params);
  std::map<std::int32_t, double> volume, area;
  for (std::size_t t = 0; t < m.tet_count(); ++t) volume[m.region_of(t)] += tet_volume(m, t);
  for (std::size_t f = 0; f < m.bface_count(); ++f) area[m.bface_tag[f]] += tri_area(m, f);
  const double disc = 16.0 / 2 * 0.2 * 0.2 * std::sin(2 * M_PI / 16);  // the 16-gon's area
  EXPECT_NEAR(volume[1], 0.5, 1e-12);
  EXPECT_NEAR(volume[3], disc * 0.5, 1e-12);
  EXPECT_NEAR(volume[2], 0.5 - disc * 0.5, 1e-12);
  EXPECT_NEAR(area[5], disc, 1e-12);
  EXPECT_NEAR(area[4], 1 - disc, 1e-12);
  EXPECT_NEAR(area[6], 16 * 2 * 0.2 * std::sin(M_PI / 16) * 0.5, 1e-12);  // the via wall
  EXPECT_TRUE(compute_delaunay_certificate(m).delaunay);
}

TEST(TetgenMesher, SameMeshAsTheTetgenProgram) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  test::write_text(dir / "t.poly", test::read_text(example("trench.poly")));
  ASSERT_EQ(test::run("cd '" + dir.path().string() + "' && tetgen -pq1.414a0.002O0 t.poly", dir / "log"), 0);
  Mesh cli = read_tetgen(dir / "t.1");
  MeshParams params;
  params.max_volume = 0.002;
  Mesh lib = mesh_plc(read_poly(dir / "t.poly"), params);
  EXPECT_EQ(lib.node_count(), cli.node_count());
  EXPECT_EQ(lib.tet_count(), cli.tet_count());
  EXPECT_EQ(lib.xyz, cli.xyz);
  EXPECT_EQ(lib.tet, cli.tet);
  EXPECT_EQ(lib.bface_count(), cli.bface_count());  // boundary triangles with their markers
  EXPECT_EQ(lib.bface_tag, cli.bface_tag);
  double v = 0;
  for (std::size_t t = 0; t < lib.tet_count(); ++t) v += tet_volume(lib, t);
  EXPECT_NEAR(v, 2.0 - 0.5, 1e-12);  // the box less the trench
  // Without mesh optimisation TetGen's mesh of this PLC is Delaunay (issue 6's measurement).
  EXPECT_TRUE(compute_delaunay_certificate(lib).delaunay);
}

TEST(TetgenMesher, CancelStopsTetgen) {
  Plc plc = read_poly(example("die_on_substrate.poly"));
  MeshParams params;
  params.max_volume = 1e-15;  // tens of millions of tets: long enough to be cancelled first
  int calls = 0;
  params.progress = [&](std::string_view stage, double) {
    EXPECT_EQ(stage, "meshing");
    return ++calls < 3;
  };
  try {
    mesh_plc(plc, params);
    FAIL() << "not cancelled";
  } catch (const MesherError& e) {
    EXPECT_EQ(e.tetgen_code(), -1);
    EXPECT_EQ(calls, 3);
  }
}

TEST(TetgenMesher, PolyRoundTrip) {
  test::TempDir dir;
  Plc plc = read_poly(example("die_on_substrate.poly"));
  write_poly(plc, dir / "copy.poly");
  Plc again = read_poly(dir / "copy.poly");
  EXPECT_EQ(again.points, plc.points);
  EXPECT_EQ(again.polygon_vertices, plc.polygon_vertices);
  EXPECT_EQ(again.facet_marker, plc.facet_marker);
  EXPECT_EQ(again.facet_holes, plc.facet_holes);
  ASSERT_EQ(again.regions.size(), plc.regions.size());
  for (std::size_t r = 0; r < plc.regions.size(); ++r) EXPECT_EQ(again.regions[r].id, plc.regions[r].id);
}

TEST(TetgenMesher, BrokenInputGivesTypedErrors) {
  // A .poly that declares more facets than it has: a located reader error.
  try {
    parse_poly("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1\n1 0 1\n3 1 2 3\n", "short.poly");
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.file(), "short.poly");
    EXPECT_GT(e.line(), 0u);
  }
  try {
    parse_poly("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n1 0\n1\n3 1 2 9\n", "range.poly");
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
  }
  // Two crossing facets: TetGen refuses, and foxi says why instead of crashing or exiting.
  Plc plc;
  plc.points = {0, 0, 0, 1, 0, 0, 1,   1,    0,    0,   1,   0,    0,   0,   1,   1,   0,    1,
                1, 1, 1, 0, 1, 1, 0.5, -0.5, -0.5, 0.5, 1.5, -0.5, 0.5, 1.5, 1.5, 0.5, -0.5, 1.5};
  plc.add_facet({0, 1, 2, 3}, 1);
  plc.add_facet({4, 5, 6, 7}, 1);
  plc.add_facet({0, 1, 5, 4}, 1);
  plc.add_facet({2, 3, 7, 6}, 1);
  plc.add_facet({0, 3, 7, 4}, 1);
  plc.add_facet({1, 2, 6, 5}, 1);
  plc.add_facet({8, 9, 10, 11}, 2);  // cuts through the cube and sticks out of it
  EXPECT_THROW(mesh_plc(plc), MesherError);

  // A triangle through the bottom of a tet: TetGen 1.5 crashes on it (signal 11) rather than stopping
  // with its self-intersection error; foxi's message still says what is wrong, and where.
  Plc crossing;
  crossing.points = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.2, 0.2, -0.5, 0.2, 0.2, 0.5};
  crossing.add_facet({0, 1, 2}, 1);
  crossing.add_facet({0, 1, 3}, 1);
  crossing.add_facet({0, 2, 3}, 1);
  crossing.add_facet({1, 2, 3}, 1);
  crossing.add_facet({0, 4, 5}, 2);
  try {
    mesh_plc(crossing);
    FAIL() << "no error";
  } catch (const MesherError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("intersect"), std::string::npos) << what;
    if (what.find("check finds") != std::string::npos) {  // TetGen died: its check names the triangle
      EXPECT_NE(what.find("(0.2, 0.2, -0.5)"), std::string::npos) << what;
    }
  }

  // A radius-edge bound below sqrt(2) ran TetGen for minutes (1.0 never finished on a model of a die on
  // a substrate): refused before TetGen starts, with the bound named.
  MeshParams tight;
  tight.radius_edge = 1.1;
  try {
    mesh_plc(plc, tight);
    FAIL() << "no error";
  } catch (const MesherError& e) {
    EXPECT_NE(std::string(e.what()).find("at least 1.414"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace foxi
