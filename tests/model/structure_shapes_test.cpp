// Shapes beyond boxes and cylinders: polygon extrusions (non-convex outlines), balls (sphere
// segments) and closed STL surfaces, turned into one conforming PLC and meshed by the `tetgen`
// program; region volumes and boundary areas are checked against formulas (shoelace areas of the
// outlines, frustum volumes of the faceted balls, the analytic sphere segment) and bad shapes must
// fail with the file, the line and the part's name.
#include <gtest/gtest.h>

#include <string>

#include "foxi/model/io_error.hpp"
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

}  // namespace
