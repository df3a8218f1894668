// Structure models -> PLC, checked against independent truth: TetGen (the `tetgen` program) meshes
// each shipped model's PLC, and every region's tet volume and every named boundary's triangle area
// must equal the analytic volume and area of the parts (boxes, regular n-gon prisms) as written in
// the model files. Bad input must fail with messages naming the file, the line and the entity.
#include "foxi/model/structure.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "foxi/model/io_error.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/plc.hpp"
#include "structure_mesh.hpp"
#include "test_util.hpp"

namespace {

using foxi::test::box;
using foxi::test::boxes_model;
using foxi::test::expect_areas;
using foxi::test::expect_near_rel;
using foxi::test::expect_volumes;
using foxi::test::kMm;
using foxi::test::kMm2;
using foxi::test::kMm3;
using foxi::test::kModels;
using foxi::test::mesh_model;
using foxi::test::mesh_text;
using foxi::test::Meshed;
using foxi::test::ngon_area;
using foxi::test::ngon_perimeter;
using foxi::test::TempDir;
using foxi::test::tet_volume;
using foxi::test::tri_area;

TEST(Structure, DieOnSubstrateMeshesToAnalyticVolumesAndAreas) {
  const Meshed m = mesh_model(kModels + "die_on_substrate.toml", {}, 1e-9);
  // substrate 10 x 8 x 1 mm, die 4 x 3 x 0.5 mm on top
  expect_volumes(m, {{"substrate", 80 * kMm3}, {"die", 6 * kMm3}});
  expect_areas(m, {{"substrate.bottom", 80 * kMm2},
                   {"substrate.top", (80 - 12) * kMm2},
                   {"substrate.side", 2 * (10 + 8) * 1 * kMm2},
                   {"substrate/die", 12 * kMm2},
                   {"die.top", 12 * kMm2},
                   {"die.side", 2 * (4 + 3) * 0.5 * kMm2}});
}

TEST(Structure, SetChangesVolumesAsTheFormulaSays) {
  const Meshed m =
      mesh_model(kModels + "die_on_substrate.toml", {"die_w=6mm", "sub_h=2 mm", "die_h=die_d/6"}, 2e-9);
  expect_volumes(m, {{"substrate", 10 * 8 * 2 * kMm3}, {"die", 6 * 3 * 0.5 * kMm3}});
  EXPECT_NEAR(m.boundary_area.at("substrate.top"), (80 - 18) * kMm2, 1e-9 * kMm2);
  EXPECT_NEAR(m.boundary_area.at("die.side"), 2 * (6 + 3) * 0.5 * kMm2, 1e-9 * kMm2);
}

TEST(Structure, ViaCarvesItsPrismOutOfTheDielectric) {
  const Meshed m = mesh_model(kModels + "via_in_dielectric.toml", {}, 1e-11);
  const double a = ngon_area(16, 0.2) * kMm2, p = ngon_perimeter(16, 0.2) * kMm;
  expect_volumes(
      m, {{"substrate", 0.5 * kMm3}, {"dielectric", 0.5 * kMm3 - a * 0.5 * kMm}, {"via", a * 0.5 * kMm}});
  expect_areas(m, {{"substrate.bottom", 1 * kMm2},
                   {"substrate.side", 4 * 0.5 * kMm2},
                   {"dielectric.side", 4 * 0.5 * kMm2},
                   {"substrate/dielectric", 1 * kMm2 - a},
                   {"substrate/via", a},
                   {"dielectric/via", p * 0.5 * kMm},
                   {"dielectric.top", 1 * kMm2 - a},
                   {"via.top", a}});
}

TEST(Structure, ViaSegmentsAndRadiusFromSet) {
  const Meshed m = mesh_model(kModels + "via_in_dielectric.toml", {"via_n=8", "via_r=0.3mm"}, 1e-11);
  const double a = ngon_area(8, 0.3) * kMm2;
  expect_volumes(
      m, {{"substrate", 0.5 * kMm3}, {"dielectric", 0.5 * kMm3 - a * 0.5 * kMm}, {"via", a * 0.5 * kMm}});
}

TEST(Structure, FlipChipBumpsCarveTheUnderfill) {
  const Meshed m = mesh_model(kModels + "flip_chip.toml", {}, 2e-9);
  // substrate 10 x 10 x 1, underfill 6 x 6 x 0.2 minus 4 bumps (16-gons, r 0.3, h 0.2), die 6 x 6 x 0.5
  const double a = ngon_area(16, 0.3), p = ngon_perimeter(16, 0.3);
  expect_volumes(m, {{"substrate", 100 * kMm3},
                     {"underfill", (36 - 4 * a) * 0.2 * kMm3},
                     {"bumps", 4 * a * 0.2 * kMm3},
                     {"die", 36 * 0.5 * kMm3}});
  expect_areas(m, {{"substrate.bottom", 100 * kMm2},
                   {"substrate.top", 64 * kMm2},
                   {"substrate.side", 40 * kMm2},
                   {"substrate/underfill", (36 - 4 * a) * kMm2},
                   {"substrate/bumps", 4 * a * kMm2},
                   {"underfill/bumps", 4 * p * 0.2 * kMm2},
                   {"underfill.side", 24 * 0.2 * kMm2},
                   {"underfill/die", (36 - 4 * a) * kMm2},
                   {"bumps/die", 4 * a * kMm2},
                   {"die.top", 36 * kMm2},
                   {"die.side", 24 * 0.5 * kMm2}});
}

TEST(Structure, MultiChipDiesCarveTheMold) {
  const Meshed m = mesh_model(kModels + "multi_chip.toml", {"die_h=0.6mm"}, 5e-9);
  // substrate 20 x 12 x 1.2, mold 20 x 12 x 1 minus the dies 6 x 6 and 4 x 4, 0.6 high
  expect_volumes(m, {{"substrate", 20 * 12 * 1.2 * kMm3},
                     {"mold", (240 - (36 + 16) * 0.6) * kMm3},
                     {"die1", 36 * 0.6 * kMm3},
                     {"die2", 16 * 0.6 * kMm3}});
  expect_areas(m, {{"substrate.bottom", 240 * kMm2},
                   {"substrate.side", 2 * (20 + 12) * 1.2 * kMm2},
                   {"substrate/mold", (240 - 52) * kMm2},
                   {"substrate/die1", 36 * kMm2},
                   {"substrate/die2", 16 * kMm2},
                   {"mold/die1", (36 + 24 * 0.6) * kMm2},
                   {"mold/die2", (16 + 16 * 0.6) * kMm2},
                   {"mold.top", 240 * kMm2},
                   {"mold.side", 2 * (20 + 12) * 1 * kMm2}});
}

TEST(Structure, ModelsCarryMaterialsFromTheLibrary) {
  const foxi::Model m = foxi::load_model(kModels + "flip_chip.toml");
  ASSERT_EQ(m.materials.size(), 4u);
  for (const auto& mat : m.materials) {
    EXPECT_GT(mat.thermal_conductivity, 0) << mat.name;
    EXPECT_GT(mat.youngs_modulus, 1e9) << mat.name;
    EXPECT_GT(mat.poisson_ratio, 0) << mat.name;
    EXPECT_LT(mat.poisson_ratio, 0.5) << mat.name;
    // Transient heat: every library material has rho and c, in the range of solids (water's
    // volumetric heat capacity 4.2e6 J/(m^3 K) is above all of them, 1e6 below).
    EXPECT_GT(mat.density * mat.specific_heat, 1e6) << mat.name;
    EXPECT_LT(mat.density * mat.specific_heat, 4.2e6) << mat.name;
  }
  EXPECT_DOUBLE_EQ(m.length_scale, 1e-3);
}

// Carving and nesting beyond the shipped models: a die buried in mold compound (a box strictly
// inside a box), a via through two layers into a pad (three levels of nesting), and a disconnected
// part, each checked against the analytic volumes.
TEST(Structure, BuriedViaThroughTwoLayersAndDisconnectedParts) {
  TempDir dir;
  foxi::test::write_text(dir / "m.toml", R"TOML(units.length = "um"
[parameters]
r = "100 um"
[materials.a]
thermal_conductivity = 1
[[parts]]
name = "mold"
material = "a"
shape = "box"
origin = [0, 0, 0]
size = [1000, 1000, 600]
[[parts]]
name = "die"
material = "a"
shape = "box"
origin = [200, 200, 100]
size = [600, 600, 300]
[[parts]]
name = "pad"
material = "a"
shape = "box"
origin = [350, 350, 150]
size = [300, 300, 50]
[[parts]]
name = "via"
material = "a"
shape = "cylinder"
center = [500, 500, 150]
radius = "r"
height = "350 um"
segments = 12
[[parts]]
name = "island"
material = "a"
shape = "box"
origin = [2000, 0, 0]
size = [100, 200, 300]
)TOML");
  const Meshed m = mesh_model((dir / "m.toml").string(), {}, 2e-12);
  const double um3 = 1e-18, a = ngon_area(12, 100);
  // via: z 150..500 crosses the pad (150..200), the die (200..400) and the mold (400..500)
  expect_volumes(m, {{"mold", (1000.0 * 1000 * 600 - 600.0 * 600 * 300 - a * 100) * um3},
                     {"die", (600.0 * 600 * 300 - 300.0 * 300 * 50 - a * 200) * um3},
                     {"pad", (300.0 * 300 * 50 - a * 50) * um3},
                     {"via", a * 350 * um3},
                     {"island", 100.0 * 200 * 300 * um3}});
  EXPECT_EQ(m.boundary_area.count("via.top"), 0u);  // the via ends inside the mold
  EXPECT_EQ(m.boundary_area.count("mold/via"), 1u);
}

TEST(Structure, PartialOverlapIsCarvedByTheLaterPart) {
  // lid [1,3]^2 x [0.5,1.5] over base [0,2]^2 x [0,1]: the lid takes [1,2]^2 x [0.5,1] from the base
  const Meshed m =
      mesh_text(boxes_model(box("base", 0, 0, 0, 2, 2, 1) + box("lid", 1, 1, 0.5, 2, 2, 1)), 1e-10);
  expect_volumes(m, {{"base", 3.5 * kMm3}, {"lid", 4 * kMm3}});
  // interface: the lid's bottom over the base (1 mm^2) and two lid walls inside the base (2 x 0.5)
  expect_near_rel(m.boundary_area.at("base/lid"), 2 * kMm2, "base/lid");
  expect_near_rel(m.boundary_area.at("base.top"), 3 * kMm2, "base.top");
  expect_near_rel(m.boundary_area.at("lid.bottom"), 3 * kMm2, "lid.bottom");
}

TEST(Structure, SideBySideBoxesShareTheirWalls) {
  // the seed paper's U-shaped trench in a 2 x 1 x 1 block, built from three touching boxes
  const Meshed m =
      mesh_text(boxes_model(box("left", 0, 0, 0, 0.5, 1, 1) + box("floor", 0.5, 0, 0, 1, 1, 0.5) +
                            box("right", 1.5, 0, 0, 0.5, 1, 1)),
                1e-11);
  expect_volumes(m, {{"left", 0.5 * kMm3}, {"floor", 0.5 * kMm3}, {"right", 0.5 * kMm3}});
  expect_areas(m, {{"left.bottom", 0.5 * kMm2},
                   {"floor.bottom", 1 * kMm2},
                   {"right.bottom", 0.5 * kMm2},
                   {"left.top", 0.5 * kMm2},
                   {"floor.top", 1 * kMm2},
                   {"right.top", 0.5 * kMm2},
                   {"left/floor", 0.5 * kMm2},
                   {"floor/right", 0.5 * kMm2},
                   {"left.side", (1 + 2 * 0.5 + 0.5) * kMm2},  // x = 0, y = 0 and 1, trench wall x = 0.5
                   {"floor.side", 2 * 0.5 * kMm2},
                   {"right.side", (1 + 2 * 0.5 + 0.5) * kMm2}});
}

TEST(Structure, CrossingBarsAndACylinderOverACorner) {
  // bar b crosses bar a (a loses 1 x 1 x 1); a 16-gon cylinder (r 0.5) centred on the corner (0, 1)
  // of bar a takes a quarter of its cross-section from a (the 16-gon is symmetric under 90 degrees)
  const std::string cyl =
      "[[parts]]\nname = \"c\"\nmaterial = \"a\"\nshape = \"cylinder\"\ncenter = [0, 1, 0]\nradius = 0.5\n"
      "height = 1\nsegments = 16\n";
  const Meshed m =
      mesh_text(boxes_model(box("a", 0, 1, 0, 3, 1, 1) + box("b", 1, 0, 0, 1, 3, 1) + cyl), 1e-10);
  const double q = ngon_area(16, 0.5);
  expect_volumes(m, {{"a", (3 - 1 - q / 4) * kMm3}, {"b", 3 * kMm3}, {"c", q * kMm3}});
  expect_near_rel(m.boundary_area.at("a/b"), 2 * kMm2, "a/b");
  // the quarter of the 16-gon outline inside a, 1 high
  expect_near_rel(m.boundary_area.at("a/c"), ngon_perimeter(16, 0.5) / 4 * kMm2, "a/c");
}

TEST(Structure, PartsTouchingAtACornerOnASubstrate) {
  // p and q touch only at the corner (2, 2) on the substrate's top, r is sunk 0.5 into it beside p
  const Meshed m = mesh_text(boxes_model(box("sub", 0, 0, 0, 4, 4, 1) + box("p", 1, 1, 1, 1, 1, 1) +
                                         box("q", 2, 2, 1, 1, 1, 0.5) + box("r", 2, 1, 0.5, 1, 1, 1)),
                             1e-10);
  expect_volumes(m, {{"sub", 15.5 * kMm3}, {"p", 1 * kMm3}, {"q", 0.5 * kMm3}, {"r", 1 * kMm3}});
  expect_near_rel(m.boundary_area.at("sub.top"), 13 * kMm2, "sub.top");
  expect_near_rel(m.boundary_area.at("sub/r"), (1 + 4 * 0.5) * kMm2, "sub/r");
  expect_near_rel(m.boundary_area.at("p/r"), 0.5 * kMm2, "p/r");
  expect_near_rel(m.boundary_area.at("q/r"), 0.5 * kMm2, "q/r");
}

TEST(Structure, ThinDieAttachLayer500To1) {
  // a 20 um die attach under a 4 x 4 mm die on a 10 mm substrate (the issue's 500:1 thin layer)
  const Meshed m =
      mesh_text(boxes_model(box("substrate", 0, 0, 0, 10, 10, 1) + box("attach", 3, 3, 1, 4, 4, 0.02) +
                            box("die", 3, 3, 1.02, 4, 4, 0.5)),
                0);
  expect_volumes(m, {{"substrate", 100 * kMm3}, {"attach", 16 * 0.02 * kMm3}, {"die", 8 * kMm3}});
  expect_near_rel(m.boundary_area.at("attach.side"), 16 * 0.02 * kMm2, "attach.side");
  expect_near_rel(m.boundary_area.at("attach/die"), 16 * kMm2, "attach/die");
}

// ---- bad input ----

const char* kGood = R"TOML(units.length = "mm"
[parameters]
w = "2 mm"
h = "w / 2"
[materials.glue]
thermal_conductivity = "2 W/(m*K)"
[[parts]]
name = "base"
material = "glue"
shape = "box"
origin = [0, 0, 0]
size = ["w", "w", "h"]
)TOML";

// The 1-based line of the first occurrence of `needle` in `text`.
std::uint64_t line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  return 1 + static_cast<std::uint64_t>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

// Loads (and builds) `text`, which must fail; returns the error.
foxi::IoError load_error(const std::string& text, std::vector<std::string> sets = {}) {
  TempDir dir;
  foxi::test::write_text(dir / "bad.toml", text);
  try {
    const foxi::Model m = foxi::load_model(dir / "bad.toml", sets);
    foxi::build_structure(m);
  } catch (const foxi::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.toml"), std::string::npos) << e.what();
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return foxi::IoError("", 0, 0, "");
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  s.replace(s.find(from), from.size(), to);
  return s;
}

TEST(StructureBadInput, TheGoodModelLoads) {
  TempDir dir;
  foxi::test::write_text(dir / "good.toml", kGood);
  const foxi::Model m = foxi::load_model(dir / "good.toml");
  const foxi::Structure s = foxi::build_structure(m);
  EXPECT_NEAR(s.part_volume[0], 2e-3 * 2e-3 * 1e-3, 1e-20);
  EXPECT_DOUBLE_EQ(m.materials[0].thermal_conductivity, 2.0);
}

// Density and specific heat take units like the other properties (a bare number is SI), and a wrong
// dimension or a negative value is refused with its line.
TEST(StructureBadInput, DensityAndSpecificHeatTakeUnits) {
  TempDir dir;
  const std::string t = replaced(
      kGood, "thermal_conductivity = \"2 W/(m*K)\"",
      "thermal_conductivity = \"2 W/(m*K)\"\ndensity = \"8.96 g/cm^3\"\nspecific_heat = \"0.385 J/(g*K)\"");
  foxi::test::write_text(dir / "u.toml", t);
  const foxi::Model m = foxi::load_model(dir / "u.toml");
  EXPECT_NEAR(m.materials[0].density, 8960, 1e-9);
  EXPECT_NEAR(m.materials[0].specific_heat, 385, 1e-9);
  const std::string bad = replaced(kGood, "thermal_conductivity = \"2 W/(m*K)\"",
                                   "thermal_conductivity = \"2 W/(m*K)\"\ndensity = \"3 kg/m^2\"");
  const foxi::IoError e = load_error(bad);
  EXPECT_NE(e.reason().find("unit mismatch"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), line_of(bad, "density ="));
  const std::string neg = replaced(kGood, "thermal_conductivity = \"2 W/(m*K)\"",
                                   "thermal_conductivity = \"2 W/(m*K)\"\nspecific_heat = -1");
  const foxi::IoError n = load_error(neg);
  EXPECT_NE(n.reason().find("must not be negative"), std::string::npos) << n.what();
  // A Poisson ratio takes (-1, ...]: auxetic materials are negative (the model file refused -0.3,
  // which --nu took); -1 and below are refused.
  const std::string auxetic = replaced(kGood, "thermal_conductivity = \"2 W/(m*K)\"",
                                       "thermal_conductivity = \"2 W/(m*K)\"\npoisson_ratio = -0.3");
  foxi::test::write_text(dir / "a.toml", auxetic);
  EXPECT_NEAR(foxi::load_model(dir / "a.toml").materials[0].poisson_ratio, -0.3, 1e-15);
  const foxi::IoError q = load_error(replaced(auxetic, "poisson_ratio = -0.3", "poisson_ratio = -1"));
  EXPECT_NE(q.reason().find("must be above -1"), std::string::npos) << q.what();
}

TEST(StructureBadInput, UnknownParameterIsNamed) {
  const std::string t = replaced(kGood, "\"w\", \"h\"]", "\"w\", \"height\"]");
  const foxi::IoError e = load_error(t);
  EXPECT_NE(e.reason().find("unknown parameter 'height'"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("part 'base'"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), line_of(t, "size ="));
}

TEST(StructureBadInput, UnknownParameterInSetIsNamed) {
  const foxi::IoError e = load_error(kGood, {"width=3mm"});
  EXPECT_NE(e.reason().find("'width'"), std::string::npos) << e.what();
}

TEST(StructureBadInput, UnitMismatchIsNamed) {
  const std::string t = replaced(kGood, "h = \"w / 2\"", "h = \"w + 300 K\"");
  const foxi::IoError e = load_error(t);
  EXPECT_NE(e.reason().find("unit mismatch"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("parameter 'h'"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), line_of(t, "\nh = ") + 1);
}

TEST(StructureBadInput, TemperatureWhereALengthIsExpected) {
  const std::string t = replaced(kGood, "h = \"w / 2\"", "h = \"300 K\"");
  const foxi::IoError e = load_error(t);
  EXPECT_NE(e.reason().find("unit mismatch"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("part 'base' size"), std::string::npos) << e.what();
}

TEST(StructureBadInput, CircularExpressionIsNamed) {
  const std::string t = replaced(kGood, "w = \"2 mm\"", "w = \"2 * h\"");
  const foxi::IoError e = load_error(t);
  EXPECT_NE(e.reason().find("circular"), std::string::npos) << e.what();
  const std::string r = e.reason();
  EXPECT_TRUE(r.find("h -> w -> h") != std::string::npos || r.find("w -> h -> w") != std::string::npos) << r;
}

TEST(StructureBadInput, NegativeSizeIsNamed) {
  const std::string t = replaced(kGood, "h = \"w / 2\"", "h = \"-w / 2\"");
  const foxi::IoError e = load_error(t);
  EXPECT_NE(e.reason().find("part 'base' size[2]"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("not positive"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), line_of(t, "size ="));
}

TEST(StructureBadInput, UnknownMaterialIsNamed) {
  const std::string t = replaced(kGood, "material = \"glue\"", "material = \"unobtainium\"");
  const foxi::IoError e = load_error(t);
  EXPECT_NE(e.reason().find("unknown material 'unobtainium'"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("part 'base'"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), line_of(t, "material = \"unob"));
}

TEST(StructureBadInput, TomlSyntaxErrorHasTheLine) {
  const std::string t = replaced(kGood, "shape = \"box\"", "shape = \"box");
  const foxi::IoError e = load_error(t);
  EXPECT_EQ(e.line(), line_of(t, "shape = \"box"));
}

// A box whose corner is 1e-7 mm short of another's edge (an outside probe): the PLC gets an edge of
// 1e-7 mm, below any part's own smallest feature (1e-6 of the extent), and TetGen's refinement ran
// without end on it (foxi mesh and foxi solve until killed). Refused with where it is; the same box
// exactly on the edge, or off it by round-off (welded by the mesher), builds.
TEST(Structure, PartsThatNearlyMeetAreRefused) {
  // box() prints 6 digits: b's origin written here in full
  auto model = [](double gap) {
    char b[256];
    std::snprintf(b, sizeof b,
                  "[[parts]]\nname = \"b\"\nmaterial = \"a\"\nshape = \"box\"\norigin = [%.17g, 0, 1]\n"
                  "size = [1, 1, 1]\n",
                  1 - gap);
    return boxes_model(box("a", 0, 0, 0, 1, 1, 1) + b);
  };
  for (const double gap : {1e-7, 1e-10, 1e-6}) {
    const foxi::IoError e = load_error(model(gap));
    EXPECT_NE(std::string(e.what()).find("the parts leave an edge of"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("on boundary 'a/b'"), std::string::npos) << e.what();
  }
  for (const double gap : {0.0, 1e-14, 3e-6}) {
    TempDir dir;
    foxi::test::write_text(dir / "ok.toml", model(gap));
    EXPECT_NO_THROW(foxi::build_structure(foxi::load_model(dir / "ok.toml", std::vector<std::string>{})))
        << gap;
  }
}

}  // namespace
