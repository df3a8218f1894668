// Shapes beyond boxes and cylinders: polygon extrusions (non-convex outlines), balls (sphere
// segments) and closed STL surfaces, turned into one conforming PLC and meshed by the `tetgen`
// program; region volumes and boundary areas are checked against formulas (shoelace areas of the
// outlines, frustum volumes of the faceted balls, the analytic sphere segment) and bad shapes must
// fail with the file, the line and the part's name.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "foxi/model/io_error.hpp"
#include "foxi/model/surface.hpp"
#include "structure_mesh.hpp"
#include "test_util.hpp"

namespace {

using namespace foxi::test;  // NOLINT: the structure test helpers

std::string extrusion(const std::string& name, const std::string& points, double z, double h) {
  return "[[parts]]\nname = \"" + name + "\"\nmaterial = \"a\"\nshape = \"extrusion\"\npoints = " + points +
         "\nz = " + std::to_string(z) + "\nheight = " + std::to_string(h) + "\n";
}

// The build error of a model text (which must fail).
foxi::IoError build_error(const std::string& text) {
  TempDir dir;
  foxi::test::write_text(dir / "bad.toml", text);
  try {
    foxi::build_structure(foxi::load_model(dir / "bad.toml"));
  } catch (const foxi::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.toml"), std::string::npos) << e.what();
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return foxi::IoError("", 0, 0, "");
}

// det(a, b, c) / 6: the signed volume of the tetrahedron (origin, a, b, c).
double origin_tet_volume(const double* a, const double* b, const double* c) {
  return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6;
}

double triangle_area(const double* a, const double* b, const double* c) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return 0.5 * std::sqrt(std::pow(u[1] * v[2] - u[2] * v[1], 2) + std::pow(u[2] * v[0] - u[0] * v[2], 2) +
                         std::pow(u[0] * v[1] - u[1] * v[0], 2));
}

TEST(StructureShapes, UShapedExtrusionAroundABoxAndAClockwiseL) {
  // on a 3 x 3 x 1 base: a U (area 9 - 2 = 7) 1 high with a box filling its notch [1,2] x [1,3];
  // an L written clockwise (area 2 x 2 - 1 = 3) sunk 0.5 into the base at the corner x, y in [3,5]
  // beside it, so the L carves 0 from the base (it starts at x = 3) but shares the wall x = 3.
  const std::string u = "[[0, 0], [3, 0], [3, 3], [2, 3], [2, 1], [1, 1], [1, 3], [0, 3]]";
  const std::string l = "[[3, 0], [3, 2], [5, 2], [5, 1], [4, 1], [4, 0]]";  // clockwise
  const Meshed m = mesh_text(boxes_model(box("base", 0, 0, 0, 3, 3, 1) + extrusion("u", u, 1, 1) +
                                         box("fill", 1, 1, 1, 1, 2, 1) + extrusion("l", l, 0.5, 1)),
                             1e-10);
  expect_volumes(m, {{"base", 9 * kMm3}, {"u", 7 * kMm3}, {"fill", 2 * kMm3}, {"l", 3 * kMm3}});
  // the U's inner walls: x = 1 and x = 2 (2 long each) and y = 1 (1 long), all 1 high
  expect_near_rel(m.boundary_area.at("u/fill"), 5 * kMm2, "u/fill");
  expect_near_rel(m.boundary_area.at("base/u"), 7 * kMm2, "base/u");
  expect_near_rel(m.boundary_area.at("base/fill"), 2 * kMm2, "base/fill");
  // the L touches the base's wall x = 3 along y in [0, 2], z in [0.5, 1], and the U's above it
  expect_near_rel(m.boundary_area.at("base/l"), 1 * kMm2, "base/l");
  expect_near_rel(m.boundary_area.at("u/l"), 1 * kMm2, "u/l");
  expect_near_rel(m.boundary_area.at("l.top"), 3 * kMm2, "l.top");
  expect_near_rel(m.boundary_area.at("l.bottom"), 3 * kMm2, "l.bottom");
  // the U's top less nothing (the fill is beside it, not on it): 7; the fill's top 2
  expect_near_rel(m.boundary_area.at("u.top"), 7 * kMm2, "u.top");
  expect_near_rel(m.boundary_area.at("fill.top"), 2 * kMm2, "fill.top");
}

TEST(StructureShapes, ExtrusionCarvesANotchIntoABox) {
  // a T-shaped extrusion through the top half of a 4 x 4 x 2 block takes its volume from the block
  const std::string t = "[[1, 1], [3, 1], [3, 2], [2.5, 2], [2.5, 3], [1.5, 3], [1.5, 2], [1, 2]]";
  const Meshed m = mesh_text(boxes_model(box("block", 0, 0, 0, 4, 4, 2) + extrusion("t", t, 1, 1)), 1e-10);
  const double a = 2 * 1 + 1 * 1;
  expect_volumes(m, {{"block", (32 - a) * kMm3}, {"t", a * kMm3}});
  expect_areas(m, {{"block.bottom", 16 * kMm2},
                   {"block.side", 16 * 2 * kMm2},
                   {"block.top", (16 - a) * kMm2},
                   {"block/t", (a + 8) * kMm2},  // bottom and the T outline (8 long), 1 high
                   {"t.top", a * kMm2}});
}

TEST(StructureShapes, SelfIntersectingOutlineIsRejectedWithThePart) {
  const std::string bow = "[[0, 0], [2, 2], [2, 0], [0, 2]]";
  const std::string text = boxes_model(extrusion("bow", bow, 0, 1));
  const foxi::IoError e = build_error(text);
  EXPECT_NE(e.reason().find("part 'bow' points"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("not a simple polygon"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), 8u);  // the points line
}

// ---- balls ----

std::string ball(const std::string& name, double cx, double cy, double cz, double r, double z0, double z1,
                 double tol) {
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "[[parts]]\nname = \"%s\"\nmaterial = \"a\"\nshape = \"ball\"\ncenter = [%.17g, %.17g, %.17g]\n"
      "radius = %.17g\nz_range = [%.17g, %.17g]\ntolerance = %.17g\n",
      name.c_str(), cx, cy, cz, r, z0, z1, tol);
  return buf;
}

// The faceting of the same ball in metres (the model is in mm).
foxi::BallFaceting faceting_mm(double cz, double r, double z0, double z1, double tol) {
  foxi::Ball b;
  b.center[2] = cz * 1e-3;
  b.radius = r * 1e-3;
  b.z0 = z0 * 1e-3;
  b.z1 = z1 * 1e-3;
  b.tolerance = tol * 1e-3;
  return foxi::ball_faceting(b);
}

// Volume of the faceted ball as a stack of frusta of regular n-gon pyramids: h/3 (A + B + sqrt(A B)).
double frusta_volume(const foxi::BallFaceting& f) {
  double v = 0;
  for (std::size_t k = 0; k + 1 < f.ring_z.size(); ++k) {
    const double a = ngon_area(static_cast<int>(f.around), f.ring_radius[k]);
    const double b = ngon_area(static_cast<int>(f.around), f.ring_radius[k + 1]);
    v += (f.ring_z[k] - f.ring_z[k + 1]) / 3 * (a + b + std::sqrt(a * b));
  }
  return v;
}

// The sphere between two planes: pi * integral of r^2 - (z - c)^2 dz.
double segment_volume(double cz, double r, double z0, double z1) {
  auto prim = [&](double z) { return r * r * z - std::pow(z - cz, 3) / 3; };
  return std::numbers::pi * (prim(z1) - prim(z0));
}

TEST(StructureShapes, BallFacetingStaysWithinTheTolerance) {
  // every ring vertex on the sphere, every chord's sagitta (around and along meridians) <= tol / 2
  const double r = 0.5e-3, tol = 3e-6;
  foxi::Ball b;
  b.radius = r;
  b.z0 = -0.3e-3;
  b.z1 = 0.45e-3;
  b.tolerance = tol;
  const foxi::BallFaceting f = foxi::ball_faceting(b);
  EXPECT_EQ(f.around % 4, 0u);
  EXPECT_LE(r * (1 - std::cos(std::numbers::pi / f.around)), tol / 2);
  EXPECT_DOUBLE_EQ(f.ring_z.front(), b.z1);
  EXPECT_DOUBLE_EQ(f.ring_z.back(), b.z0);
  for (std::size_t k = 0; k < f.ring_z.size(); ++k) {
    EXPECT_NEAR(std::hypot(f.ring_radius[k], f.ring_z[k]), r, 1e-15) << k;
    if (k == 0) continue;
    const double chord = std::hypot(f.ring_radius[k] - f.ring_radius[k - 1], f.ring_z[k] - f.ring_z[k - 1]);
    EXPECT_LE(r - std::sqrt(r * r - chord * chord / 4), tol / 2 * (1 + 1e-12)) << k;
  }
  // the surface: closed (every edge twice, once each way) with the frusta volume (divergence theorem)
  const foxi::TriSurface s = foxi::ball_surface(b);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  double vol = 0;
  for (std::size_t t = 0; t < s.triangle_count(); ++t) {
    const std::uint32_t* c = &s.tri[3 * t];
    for (int i = 0; i < 3; ++i) ++edges[{c[i], c[(i + 1) % 3]}];
    const double* p = &s.xyz[3 * c[0]];
    const double* q = &s.xyz[3 * c[1]];
    const double* w = &s.xyz[3 * c[2]];
    vol += origin_tet_volume(p, q, w);
  }
  for (const auto& [e, k] : edges) {
    EXPECT_EQ(k, 1);
    EXPECT_EQ(edges.count({e.second, e.first}), 1u);
  }
  EXPECT_NEAR(vol, frusta_volume(f), 1e-12 * vol);
  EXPECT_GT(vol, 0);
}

TEST(StructureShapes, SolderBallBetweenTwoPads) {
  // pads [0,2]^2 x [0,0.2] and [0,2]^2 x [1,1.2] mm, a ball r 0.5 centred at (1, 1, 0.6) cut by both
  const double cz = 0.6, r = 0.5, z0 = 0.2, z1 = 1.0, tol = 0.02;
  const Meshed m = mesh_text(boxes_model(box("low", 0, 0, 0, 2, 2, 0.2) + box("high", 0, 0, 1, 2, 2, 0.2) +
                                         ball("ball", 1, 1, cz, r, z0, z1, tol)),
                             0);
  const foxi::BallFaceting f = faceting_mm(cz, r, z0, z1, tol);
  const double vf = frusta_volume(f);
  expect_volumes(m, {{"low", 0.8 * kMm3}, {"high", 0.8 * kMm3}, {"ball", vf}});
  // the faceted ball is inscribed: smaller than the sphere segment by at most tolerance x area
  const double va = segment_volume(cz, r, z0, z1) * kMm3;
  EXPECT_GT(va, vf);
  EXPECT_LT(va - vf, tol * kMm * 4 * std::numbers::pi * r * r * kMm2);
  const double a_low = ngon_area(static_cast<int>(f.around), f.ring_radius.back());
  const double a_high = ngon_area(static_cast<int>(f.around), f.ring_radius.front());
  expect_near_rel(m.boundary_area.at("low/ball"), a_low, "low/ball");
  expect_near_rel(m.boundary_area.at("high/ball"), a_high, "high/ball");
  expect_near_rel(m.boundary_area.at("low.top"), 4 * kMm2 - a_low, "low.top");
  expect_near_rel(m.boundary_area.at("high.bottom"), 4 * kMm2 - a_high, "high.bottom");
  expect_near_rel(m.boundary_area.at("low.bottom"), 4 * kMm2, "low.bottom");
  EXPECT_EQ(m.boundary_area.count("ball.top"), 0u);
  EXPECT_EQ(m.boundary_area.count("ball.bottom"), 0u);
  EXPECT_EQ(m.boundary_area.size(), 9u);  // + low.side, high.side, high.top, ball.side
}

TEST(StructureShapes, BallCarvesHalfItsVolumeOutOfABox) {
  // a whole ball centred on the face x = 2 of a 2 mm cube: the faceting is symmetric about x = 2,
  // so the cube loses exactly half the faceted volume and half the faceted surface is the interface
  const double r = 0.6, tol = 0.03;
  const Meshed m =
      mesh_text(boxes_model(box("cube", 0, 0, 0, 2, 2, 2) + ball("ball", 2, 1, 1, r, 0, 2, tol)), 0);
  const double vf = frusta_volume(faceting_mm(1, r, 0.4, 1.6, tol));
  expect_volumes(m, {{"cube", 8 * kMm3 - vf / 2}, {"ball", vf}});
  foxi::Ball b;
  b.radius = r * kMm;
  b.z0 = -r * kMm;
  b.z1 = r * kMm;
  b.tolerance = tol * kMm;
  const foxi::TriSurface s = foxi::ball_surface(b);
  double area = 0;
  for (std::size_t t = 0; t < s.triangle_count(); ++t) {
    const double* p = &s.xyz[3 * s.tri[3 * t]];
    const double* q = &s.xyz[3 * s.tri[3 * t + 1]];
    const double* w = &s.xyz[3 * s.tri[3 * t + 2]];
    area += triangle_area(p, q, w);
  }
  expect_near_rel(m.boundary_area.at("cube/ball"), area / 2, "cube/ball");
  expect_near_rel(m.boundary_area.at("ball.side"), area / 2, "ball.side");
  expect_near_rel(m.boundary_area.at("cube.top"), 4 * kMm2, "cube.top");
}

// Side area of the faceted ball: `around` planar trapezoids per ring step, parallel sides
// 2 rho sin(pi / n), height sqrt(dz^2 + (d rho cos(pi / n))^2).
double frusta_side_area(const foxi::BallFaceting& f) {
  const double n = f.around, s = std::sin(std::numbers::pi / n), c = std::cos(std::numbers::pi / n);
  double a = 0;
  for (std::size_t k = 0; k + 1 < f.ring_z.size(); ++k) {
    const double dz = f.ring_z[k] - f.ring_z[k + 1], dr = f.ring_radius[k] - f.ring_radius[k + 1];
    a += n * (f.ring_radius[k] + f.ring_radius[k + 1]) * s * std::sqrt(dz * dz + dr * dr * c * c);
  }
  return a;
}

TEST(StructureShapes, BallGridArrayModelMeshesWithItsRegionsAndBoundaries) {
  // models/bga.toml: board 8 x 8 x 0.8, package 6 x 6 x 0.4 at z 1.4, 9 balls r 0.38 centred at
  // z 1.1 between them, a 6 x 6 x 0.6 mold cap carved by a 3 x 3 x 0.3 die; coarse balls for speed
  const Meshed m = foxi::test::mesh_model(foxi::test::kModels + "bga.toml", {"ball_tol=0.05mm"}, 0);
  const foxi::BallFaceting f = faceting_mm(1.1, 0.38, 0.8, 1.4, 0.05);
  const double vb = frusta_volume(f), end = ngon_area(static_cast<int>(f.around), f.ring_radius.front());
  EXPECT_NEAR(f.ring_radius.front(), f.ring_radius.back(), 1e-12 * f.ring_radius.back());  // symmetric
  expect_volumes(m, {{"board", 51.2 * kMm3},
                     {"package", 14.4 * kMm3},
                     {"balls", 9 * vb},
                     {"mold", (21.6 - 2.7) * kMm3},
                     {"die", 2.7 * kMm3}});
  expect_areas(m, {{"board.bottom", 64 * kMm2},
                   {"board.side", 4 * 8 * 0.8 * kMm2},
                   {"board.top", 64 * kMm2 - 9 * end},
                   {"board/balls", 9 * end},
                   {"balls.side", 9 * frusta_side_area(f)},
                   {"package/balls", 9 * end},
                   {"package.bottom", 36 * kMm2 - 9 * end},
                   {"package.side", 4 * 6 * 0.4 * kMm2},
                   {"package/mold", 27 * kMm2},
                   {"package/die", 9 * kMm2},
                   {"mold/die", (9 + 4 * 3 * 0.3) * kMm2},
                   {"mold.side", 4 * 6 * 0.6 * kMm2},
                   {"mold.top", 36 * kMm2}});
}

TEST(StructureShapes, OverlappingBallsOfAnArrayAreRejectedWithThePart) {
  // pitch 0.5 < diameter 0.8: the items of one part intersect each other
  const std::string text = boxes_model(
      box("base", 0, 0, 0, 3, 3, 1) +
      "[[parts]]\nname = \"balls\"\nmaterial = \"a\"\nshape = \"array\"\ncount = [2, 1]\npitch = [0.5, 1]\n"
      "item = { shape = \"ball\", center = [1, 1, 1.2], radius = 0.4, z_range = [1, 2] }\n");
  const foxi::IoError e = build_error(text);
  EXPECT_NE(e.reason().find("part 'balls'"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("intersects itself"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), 10u);
}

TEST(StructureShapes, BoxSwallowedByALaterBallIsAnError) {
  const foxi::IoError e = build_error(
      boxes_model(box("chip", 0, 0, 0, 0.2, 0.2, 0.2) + ball("blob", 0.1, 0.1, 0.1, 1, -1, 1, 0.05)));
  EXPECT_NE(e.reason().find("'chip' is carved away entirely"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), 4u);
}

TEST(StructureShapes, ProgressReportsStagesAndCancels) {
  TempDir dir;
  foxi::test::write_text(dir / "m.toml",
                         boxes_model(box("cube", 0, 0, 0, 2, 2, 2) + ball("ball", 2, 1, 1, 0.6, 0, 2, 0.05)));
  const foxi::Model model = foxi::load_model(dir / "m.toml");
  std::vector<std::string> stages;
  foxi::build_structure(model, [&](std::string_view stage, double f) {
    EXPECT_GE(f, 0);
    EXPECT_LE(f, 1);
    if (stages.empty() || stages.back() != stage) stages.emplace_back(stage);
    return true;
  });
  EXPECT_EQ(stages, (std::vector<std::string>{"surfaces", "carve", "conform", "seeds"}));
  EXPECT_THROW(
      foxi::build_structure(model, [](std::string_view stage, double) { return stage != "conform"; }),
      foxi::StructureCancelled);
  EXPECT_THROW(  // the one cancellation outcome of every library
      foxi::build_structure(model, [](std::string_view stage, double) { return stage != "conform"; }),
      foxi::Cancelled);
}

// ---- STL surfaces ----

using Tri = std::array<std::array<double, 3>, 3>;

// The 12 outward triangles of the box [x0, x1] x [y0, y1] x [z0, z1].
std::vector<Tri> cube(double x0, double y0, double z0, double x1, double y1, double z1) {
  const double X[2] = {x0, x1}, Y[2] = {y0, y1}, Z[2] = {z0, z1};
  auto c = [&](int i, int j, int k) { return std::array<double, 3>{X[i], Y[j], Z[k]}; };
  std::vector<Tri> t;
  auto quad = [&](std::array<double, 3> a, std::array<double, 3> b, std::array<double, 3> d,
                  std::array<double, 3> e) {  // counter-clockwise seen from outside
    t.push_back({a, b, d});
    t.push_back({a, d, e});
  };
  quad(c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0));  // bottom
  quad(c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1));  // top
  quad(c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1));  // y = y0
  quad(c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0));  // y = y1
  quad(c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0));  // x = x0
  quad(c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1));  // x = x1
  return t;
}

// The 4 outward triangles of the tetrahedron o, o + a x, o + a y, o + a z.
std::vector<Tri> tetra(double x, double y, double z, double a) {
  const std::array<double, 3> o{x, y, z}, px{x + a, y, z}, py{x, y + a, z}, pz{x, y, z + a};
  return {{o, py, px}, {o, px, pz}, {o, pz, py}, {px, py, pz}};
}

void write_ascii_stl(const std::filesystem::path& path, const std::vector<Tri>& tris) {
  std::string text = "solid test\n";
  char buf[128];
  for (const Tri& t : tris) {
    text += "  facet normal 0 0 0\n    outer loop\n";
    for (const auto& v : t) {
      std::snprintf(buf, sizeof buf, "      vertex %.17g %.17g %.17g\n", v[0], v[1], v[2]);
      text += buf;
    }
    text += "    endloop\n  endfacet\n";
  }
  foxi::test::write_text(path, text + "endsolid test\n");
}

void write_binary_stl(const std::filesystem::path& path, const std::vector<Tri>& tris) {
  std::string data(80, ' ');
  const auto n = static_cast<std::uint32_t>(tris.size());
  data.append(reinterpret_cast<const char*>(&n), 4);
  for (const Tri& t : tris) {
    float f[12] = {};
    for (std::size_t v = 0; v < 3; ++v)
      for (std::size_t i = 0; i < 3; ++i) f[3 + 3 * v + i] = static_cast<float>(t[v][i]);
    data.append(reinterpret_cast<const char*>(f), sizeof f);
    data.append(2, '\0');
  }
  std::ofstream(path, std::ios::binary).write(data.data(), static_cast<std::streamsize>(data.size()));
}

std::string stl_part(const std::string& name, const std::string& file) {
  return "[[parts]]\nname = \"" + name + "\"\nmaterial = \"a\"\nshape = \"stl\"\nfile = \"" + file + "\"\n";
}

TEST(StructureShapes, StlCubeCarvesABaseAndAnStlTetrahedronSitsOnItsEdge) {
  // base [0,3]^2 x [0,1]; a binary STL cube [1,2]^2 x [0.5,1.5] sunk half into it; an ASCII STL
  // tetrahedron (legs 1 from (2.5, 2.5, 1)) standing on the base's top, overhanging its edges x = 3
  // and y = 3: its foot inside the base is the triangle of legs 1 less two corners of legs 0.5.
  TempDir dir;
  write_binary_stl(dir / "cube.stl", cube(1, 1, 0.5, 2, 2, 1.5));
  write_ascii_stl(dir / "tet.stl", tetra(2.5, 2.5, 1, 1));
  foxi::test::write_text(
      dir / "m.toml",
      boxes_model(box("base", 0, 0, 0, 3, 3, 1) + stl_part("cube", "cube.stl") + stl_part("tet", "tet.stl")));
  const Meshed m = foxi::test::mesh_model((dir / "m.toml").string(), {}, 0);
  expect_volumes(m, {{"base", 8.5 * kMm3}, {"cube", 1 * kMm3}, {"tet", kMm3 / 6}});
  expect_near_rel(m.boundary_area.at("base/cube"), 3 * kMm2, "base/cube");
  expect_near_rel(m.boundary_area.at("cube.top"), 1 * kMm2, "cube.top");
  expect_near_rel(m.boundary_area.at("cube.side"), 2 * kMm2, "cube.side");
  expect_near_rel(m.boundary_area.at("base/tet"), 0.25 * kMm2, "base/tet");
  expect_near_rel(m.boundary_area.at("tet.bottom"), 0.25 * kMm2, "tet.bottom");
  expect_near_rel(m.boundary_area.at("base.top"), (9 - 1 - 0.25) * kMm2, "base.top");
}

// The build error of a model with one STL part of these triangles (ASCII).
foxi::IoError stl_error(const std::vector<Tri>& tris) {
  TempDir dir;
  write_ascii_stl(dir / "s.stl", tris);
  const std::string text = boxes_model(box("base", 0, 0, 0, 3, 3, 1) + stl_part("blob", "s.stl"));
  foxi::test::write_text(dir / "bad.toml", text);
  try {
    foxi::build_structure(foxi::load_model(dir / "bad.toml"));
  } catch (const foxi::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.toml"), std::string::npos) << e.what();
    EXPECT_NE(e.reason().find("part 'blob'"), std::string::npos) << e.what();
    EXPECT_NE(e.reason().find("s.stl"), std::string::npos) << e.what();
    EXPECT_EQ(e.line(), 10u);  // [[parts]] of blob
    return e;
  }
  ADD_FAILURE() << "no error";
  return foxi::IoError("", 0, 0, "");
}

TEST(StructureShapes, SelfIntersectingStlIsRejectedWithThePart) {
  std::vector<Tri> t = tetra(0, 0, 0, 1);
  for (const Tri& x : tetra(0.2, 0.2, 0.2, 1)) t.push_back(x);  // a second tetrahedron through the first
  const foxi::IoError e = stl_error(t);
  EXPECT_NE(e.reason().find("intersects itself"), std::string::npos) << e.what();
}

TEST(StructureShapes, OpenOrInconsistentStlIsRejectedWithThePart) {
  std::vector<Tri> open = cube(0, 0, 0, 1, 1, 1);
  open.pop_back();
  EXPECT_NE(stl_error(open).reason().find("not closed"), std::string::npos);
  std::vector<Tri> flipped = cube(0, 0, 0, 1, 1, 1);
  std::swap(flipped[3][0], flipped[3][1]);
  EXPECT_NE(stl_error(flipped).reason().find("consistently oriented"), std::string::npos);
}

TEST(StructureShapes, InsideOutStlIsTurnedAround) {
  std::vector<Tri> t = tetra(4, 0, 0, 1);
  for (Tri& x : t) std::swap(x[0], x[1]);
  TempDir dir;
  write_ascii_stl(dir / "t.stl", t);
  foxi::test::write_text(dir / "m.toml", boxes_model(box("base", 0, 0, 0, 3, 3, 1) + stl_part("t", "t.stl")));
  const foxi::Structure s = foxi::build_structure(foxi::load_model(dir / "m.toml"));
  EXPECT_NEAR(s.part_volume[1], kMm3 / 6, 1e-15 * kMm3);
}

TEST(StructureShapes, GmshSphereStlCarvesACube) {
  // gmsh writes the STL (a foreign file); the expected volume and area are summed here from its
  // "vertex" lines, independently of foxi's reader (divergence theorem: sum of det(a, b, c) / 6)
  if (!foxi::test::have_program("gmsh")) GTEST_SKIP() << "gmsh is missing";
  TempDir dir;
  foxi::test::write_text(
      dir / "s.geo", "SetFactory(\"OpenCASCADE\");\nSphere(1) = {2, 2, 2, 1};\nMesh.MeshSizeMax = 0.4;\n");
  ASSERT_EQ(foxi::test::run("cd '" + dir.path().string() + "' && gmsh -2 s.geo -format stl -o s.stl",
                            dir / "gmsh.log"),
            0)
      << foxi::test::read_text(dir / "gmsh.log");
  const std::string stl = foxi::test::read_text(dir / "s.stl");
  std::vector<double> c;
  for (std::size_t at = stl.find("vertex"); at != std::string::npos; at = stl.find("vertex", at + 6)) {
    const char* p = stl.c_str() + at + 6;
    char* e = nullptr;
    for (int i = 0; i < 3; ++i, p = e) c.push_back(std::strtod(p, &e));
  }
  ASSERT_EQ(c.size() % 9, 0u);
  double vol = 0, area = 0;
  for (std::size_t t = 0; t < c.size(); t += 9) {
    const double* a = &c[t];
    const double* b = &c[t + 3];
    const double* d = &c[t + 6];
    vol += origin_tet_volume(a, b, d);
    area += triangle_area(a, b, d);
  }
  vol = std::abs(vol);
  EXPECT_NEAR(vol, 4 * std::numbers::pi / 3, 0.25);  // a sphere of radius 1, coarsely faceted (size 0.4)
  foxi::test::write_text(dir / "m.toml",
                         boxes_model(box("cube", 0, 0, 0, 4, 4, 4) + stl_part("ball", "s.stl")));
  const Meshed m = foxi::test::mesh_model((dir / "m.toml").string(), {}, 0);
  expect_volumes(m, {{"cube", (64 - vol) * kMm3}, {"ball", vol * kMm3}});
  expect_areas(m, {{"cube.top", 16 * kMm2},
                   {"cube.bottom", 16 * kMm2},
                   {"cube.side", 64 * kMm2},
                   {"cube/ball", area * kMm2}});
}

}  // namespace
