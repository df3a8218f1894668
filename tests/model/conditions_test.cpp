// Boundary conditions, loads, named surfaces and mesh controls of model files (conditions.hpp,
// surfaces.hpp, physics.hpp): values converted to SI as the units say (degC with its offset), plane
// and box selectors that become their own boundary markers with the analytic area (checked on the
// PLC and on a mesh of it made by the tetgen program), and bad input that fails naming the file, the
// line and the entity before any meshing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "foxi/model/io_error.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/structure.hpp"
#include "test_util.hpp"

namespace {

using foxi::test::TempDir;

// A 4 x 3 mm slab of two layers (1 and 2 mm), a 1 mm cube standing on it at (0, 0) and a cube
// floating apart from everything.
const std::string kModel = R"TOML(units.length = "mm"
[parameters]
t_amb = "25"
[materials.a]
thermal_conductivity = "2 W/(m*K)"
electrical_conductivity = 1e3
[materials.b]
thermal_conductivity = 10.0
[[parts]]
name = "slab"
shape = "layers"
origin = [0, 0, 0]
footprint = [4, 3]
thicknesses = [1, 2]
names = ["lower", "upper"]
materials = ["a", "b"]
[[parts]]
name = "cube"
material = "a"
shape = "box"
origin = [0, 0, 3]
size = [1, 1, 1]
[[parts]]
name = "island"
material = "a"
shape = "box"
origin = [10, 0, 0]
size = [1, 1, 1]
[surfaces.base]
plane = { point = [0, 0, 0], normal = [0, 0, 2] }
[surfaces.west]
box = { min = [-1, -1, -1], max = ["0 mm", "3e-3 m", 5] }
[[conditions]]
type = "temperature"
surface = "base"
value = "t_amb degC"
[[conditions]]
type = "convection"
surface = ["upper.top", "cube.top"]
h = "10 W/(m^2*K)"
ambient = "300 K"
[[conditions]]
type = "heat_flux"
surface = "island.top"
value = "2 W/cm^2"
[[conditions]]
type = "ground"
surface = "base"
[[conditions]]
type = "current"
surface = "cube/upper"
value = "3e-3 A"
name = "pad"
[[conditions]]
type = "displacement"
surface = "base"
value = [0, 0, "1 um"]
[[conditions]]
type = "sliding"
surface = "west"
[[loads]]
type = "power"
part = "cube"
value = "0.5 W"
[[loads]]
type = "power"
part = "upper"
value = "2e6 W/m^3"
[[loads]]
type = "temperature_change"
value = "-100 degC"
[mesh]
max_size = "0.5 mm"
quality = 1.5
min_dihedral = 8
parts = { cube = "100 um" }
[[mesh.refine]]
min = [0, 0, 2]
max = [1, 1, 3]
max_size = 0.05
)TOML";

std::uint64_t line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  return 1 + static_cast<std::uint64_t>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

foxi::Model load(const TempDir& dir, const std::string& text) {
  foxi::test::write_text(dir / "m.toml", text);
  return foxi::load_model(dir / "m.toml");
}

// Loads and builds `text`, which must fail; returns the error.
foxi::IoError build_error(const std::string& text) {
  TempDir dir;
  try {
    foxi::build_structure(load(dir, text));
  } catch (const foxi::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("m.toml"), std::string::npos) << e.what();
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return foxi::IoError("", 0, 0, "");
}

double area_of(const foxi::Structure& s, const std::string& name) {
  for (std::size_t b = 0; b < s.boundary_names.size(); ++b)
    if (s.boundary_names[b] == name) return s.boundary_area[b];
  ADD_FAILURE() << "no boundary " << name;
  return -1;
}

TEST(ModelConditions, ValuesInSiWithCelsiusOffsets) {
  TempDir dir;
  const foxi::Model m = load(dir, kModel);
  ASSERT_EQ(m.conditions.size(), 7u);
  using K = foxi::ConditionKind;
  const auto& c = m.conditions;
  EXPECT_EQ(c[0].kind, K::temperature);
  EXPECT_DOUBLE_EQ(c[0].value, 298.15);  // "t_amb degC" with t_amb = 25
  EXPECT_EQ(c[1].kind, K::convection);
  EXPECT_EQ(c[1].surfaces, (std::vector<std::string>{"upper.top", "cube.top"}));
  EXPECT_DOUBLE_EQ(c[1].h, 10);
  EXPECT_DOUBLE_EQ(c[1].ambient, 300);
  EXPECT_DOUBLE_EQ(c[2].value, 2e4);  // 2 W/cm^2
  EXPECT_EQ(c[3].kind, K::voltage);
  EXPECT_EQ(c[3].value, 0);
  EXPECT_EQ(c[4].kind, K::current);
  EXPECT_DOUBLE_EQ(c[4].value, 3e-3);
  EXPECT_EQ(c[4].name, "pad");
  // an interface written in either order is the builder's "earlier/later"
  EXPECT_EQ(c[4].surfaces, std::vector<std::string>{"upper/cube"});
  EXPECT_DOUBLE_EQ(c[5].displacement[2], 1e-6);
  EXPECT_EQ(c[5].displacement[0], 0);
  EXPECT_EQ(c[6].kind, K::sliding);
  ASSERT_EQ(m.loads.size(), 3u);
  EXPECT_TRUE(m.loads[0].total);
  EXPECT_DOUBLE_EQ(m.loads[0].value, 0.5);
  EXPECT_FALSE(m.loads[1].total);
  EXPECT_DOUBLE_EQ(m.loads[1].value, 2e6);
  EXPECT_EQ(m.loads[2].kind, foxi::LoadKind::temperature_change);
  EXPECT_DOUBLE_EQ(m.loads[2].value, -100);  // a change: no offset
  EXPECT_TRUE(m.loads[2].part.empty());
  EXPECT_DOUBLE_EQ(m.mesh.max_size, 5e-4);
  EXPECT_DOUBLE_EQ(m.mesh.quality, 1.5);
  EXPECT_DOUBLE_EQ(m.mesh.min_dihedral, 8);
  ASSERT_EQ(m.mesh.part_sizes.size(), 1u);
  EXPECT_EQ(m.mesh.part_sizes[0].part, "cube");
  EXPECT_DOUBLE_EQ(m.mesh.part_sizes[0].max_size, 1e-4);
  ASSERT_EQ(m.mesh.refine.size(), 1u);
  EXPECT_DOUBLE_EQ(m.mesh.refine[0].hi[2], 3e-3);
  EXPECT_DOUBLE_EQ(m.mesh.refine[0].max_size, 5e-5);
  ASSERT_EQ(m.surfaces.size(), 2u);
  EXPECT_DOUBLE_EQ(m.surfaces[0].normal[2], 1);  // normalized
}

TEST(ModelConditions, SelectorsBecomeMarkersWithTheAnalyticArea) {
  TempDir dir;
  const foxi::Model m = load(dir, kModel);
  const foxi::Structure s = foxi::build_structure(m);
  constexpr double kMm2 = 1e-6;
  // base: z = 0 holds the slab's bottom (4 x 3) and the island's bottom (1 x 1)
  EXPECT_NEAR(area_of(s, "base"), 13 * kMm2, 1e-12 * kMm2);
  EXPECT_NEAR(area_of(s, "lower.bottom"), 0, 1e-12 * kMm2);
  EXPECT_NEAR(area_of(s, "island.bottom"), 0, 1e-12 * kMm2);
  // west: x = 0 walls of the slab (3 x 3) and of the cube (1 x 1), not the interfaces
  EXPECT_NEAR(area_of(s, "west"), 10 * kMm2, 1e-12 * kMm2);
  EXPECT_NEAR(area_of(s, "lower.side"), (14 - 3) * kMm2, 1e-12 * kMm2);
  EXPECT_NEAR(area_of(s, "cube.side"), 3 * kMm2, 1e-12 * kMm2);
  EXPECT_NEAR(area_of(s, "upper/cube"), 1 * kMm2, 1e-12 * kMm2);

  // The tetgen program meshes the PLC; its boundary triangles carry the selectors' markers.
  if (!foxi::test::have_program("tetgen")) GTEST_SKIP() << "no tetgen program";
  foxi::write_poly(s.plc, dir / "m.poly");
  ASSERT_EQ(foxi::test::run("cd '" + dir.path().string() + "' && tetgen -pq1.414AQ m.poly", dir / "log"), 0)
      << foxi::test::read_text(dir / "log");
  const foxi::Mesh mesh = foxi::read_tetgen(dir / "m.1");
  std::vector<double> area(s.boundary_names.size() + 1, 0);
  for (std::size_t f = 0; f < mesh.bface_count(); ++f) {
    const double* p[3];
    for (int i = 0; i < 3; ++i) p[i] = &mesh.xyz[3 * std::size_t{mesh.bface[3 * f + i]}];
    double u[3], v[3];
    for (int k = 0; k < 3; ++k) u[k] = p[1][k] - p[0][k], v[k] = p[2][k] - p[0][k];
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const auto tag = static_cast<std::size_t>(mesh.bface_tag[f]);
    ASSERT_LT(tag, area.size());
    area[tag] += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  for (std::size_t b = 0; b < s.boundary_names.size(); ++b)
    EXPECT_NEAR(area[b + 1], s.boundary_area[b], 1e-9 * kMm2) << s.boundary_names[b];
}

TEST(ModelConditions, PhysicsNeedsItsMaterialProperties) {
  TempDir dir;
  const foxi::Model m = load(dir, kModel);
  EXPECT_NO_THROW(foxi::check_physics(m, foxi::Physics::thermal));
  try {
    foxi::check_physics(m, foxi::Physics::current);  // material b has no electrical conductivity
    ADD_FAILURE() << "no error";
  } catch (const foxi::IoError& e) {
    EXPECT_NE(e.reason().find("part 'upper'"), std::string::npos) << e.what();
    EXPECT_NE(e.reason().find("material 'b' has no electrical_conductivity"), std::string::npos) << e.what();
    EXPECT_EQ(e.line(), line_of(kModel, "name = \"slab\"") - 1);  // the [[parts]] entry
  }
  // no condition fixes the potential
  const foxi::Model n =
      load(dir, replaced(replaced(kModel, "type = \"ground\"", "type = \"current\"\nvalue = \"1 A\""),
                         "thermal_conductivity = 10.0",
                         "thermal_conductivity = 10.0\nelectrical_conductivity = 50.0"));
  try {
    foxi::check_physics(n, foxi::Physics::current);
    ADD_FAILURE() << "no error";
  } catch (const foxi::IoError& e) {
    EXPECT_NE(e.reason().find("no [[conditions]] fix the current solution"), std::string::npos) << e.what();
  }
}

// Thermal stress needs E > 0, -1 < nu < 0.5 and a finite alpha: model check said "ready" with E = 0
// or nu = 0.5 and the solve refused them only after meshing, without the file (an outside probe).
TEST(ModelConditions, ElasticConstantsOutOfRangeAreRefusedBeforeMeshing) {
  TempDir dir;
  const std::string elastic =
      replaced(replaced(kModel, "thermal_conductivity = 10.0",
                        "thermal_conductivity = 10.0\nyoungs_modulus = \"E\"\npoisson_ratio = \"nu\"\n"
                        "thermal_expansion = 1e-5"),
               "electrical_conductivity = 1e3",
               "electrical_conductivity = 1e3\nyoungs_modulus = 1e9\n"
               "poisson_ratio = 0.3\nthermal_expansion = 1e-5");
  const std::string with_slide = elastic + "[[conditions]]\ntype = \"sliding\"\nsurface = \"base\"\n";
  auto with = [&](const std::string& e, const std::string& nu) {
    return replaced(with_slide, "t_amb = \"25\"", "t_amb = \"25\"\nE = \"" + e + "\"\nnu = \"" + nu + "\"");
  };
  EXPECT_NO_THROW(foxi::check_physics(load(dir, with("70 GPa", "0.3")), foxi::Physics::thermal_stress));
  for (const auto& [e, nu, what] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"0", "0.3", "youngs_modulus 0"},  // (negative values the model loader refuses)
           {"70 GPa", "0.5", "poisson_ratio 0.5"},
           {"70 GPa", "0.7", "poisson_ratio 0.7"}}) {
    try {
      foxi::check_physics(load(dir, with(e, nu)), foxi::Physics::thermal_stress);
      ADD_FAILURE() << "no error for E " << e << ", nu " << nu;
    } catch (const foxi::IoError& ex) {
      EXPECT_NE(ex.reason().find("material 'b' has " + what), std::string::npos) << ex.what();
      EXPECT_NE(ex.reason().find("--physics thermoelastic needs"), std::string::npos) << ex.what();
      EXPECT_GT(ex.line(), 0u);
    }
  }
}

// A voltage or ground condition with `physics` applies to that physics only.
TEST(ModelConditions, VoltageConditionForOnePhysics) {
  TempDir dir;
  const std::string only =
      replaced(kModel, "type = \"ground\"", "type = \"ground\"\nphysics = \"electrostatic\"");
  const foxi::Model m = load(dir, only);
  const foxi::BoundaryCondition* ground = nullptr;
  for (const foxi::BoundaryCondition& c : m.conditions)
    if (c.kind == foxi::ConditionKind::voltage) ground = &c;
  ASSERT_NE(ground, nullptr);
  EXPECT_EQ(ground->physics, "electrostatic");
  EXPECT_TRUE(foxi::condition_applies(*ground, foxi::Physics::electrostatic));
  EXPECT_FALSE(foxi::condition_applies(*ground, foxi::Physics::current));
  EXPECT_TRUE(foxi::condition_applies(foxi::ConditionKind::voltage, foxi::Physics::current));
  const foxi::Model n = load(dir, replaced(only, "thermal_conductivity = 10.0",
                                           "thermal_conductivity = 10.0\nelectrical_conductivity = 50.0"));
  try {
    foxi::check_physics(n, foxi::Physics::current);  // the current terminal alone fixes nothing
    ADD_FAILURE() << "no error";
  } catch (const foxi::IoError& e) {
    EXPECT_NE(e.reason().find("no [[conditions]] fix the current solution"), std::string::npos) << e.what();
  }
  const std::string bad = replaced(kModel, "type = \"ground\"", "type = \"ground\"\nphysics = \"thermal\"");
  try {
    load(dir, bad);
    ADD_FAILURE() << "no error";
  } catch (const foxi::IoError& e) {
    EXPECT_NE(e.reason().find("physics must be \"electrostatic\" or \"current\""), std::string::npos)
        << e.what();
    EXPECT_EQ(e.line(), line_of(bad, "physics = \"thermal\""));
  }
}

TEST(ModelConditionsBadInput, UnknownSurfaceIsNamedWithItsLine) {
  const std::string t = replaced(kModel, "surface = \"island.top\"", "surface = \"iland.top\"");
  const foxi::IoError e = build_error(t);
  EXPECT_NE(e.reason().find("condition 'heat_flux'"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("surface 'iland.top' does not exist"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), line_of(t, "iland.top"));
}

TEST(ModelConditionsBadInput, InterfaceOfPartsThatDoNotTouch) {
  const std::string t = replaced(kModel, "surface = \"cube/upper\"", "surface = \"island/cube\"");
  const foxi::IoError e = build_error(t);
  EXPECT_NE(e.reason().find("surface 'cube/island' does not exist in the built structure"), std::string::npos)
      << e.what();
  EXPECT_EQ(e.line(), line_of(t, "type = \"current\"") - 1);
}

TEST(ModelConditionsBadInput, UnitMismatchIsNamed) {
  const std::string t = replaced(kModel, "h = \"10 W/(m^2*K)\"", "h = \"10 W/m^2\"");
  const foxi::IoError e = build_error(t);
  EXPECT_NE(e.reason().find("condition 'convection' on 'upper.top' h: unit mismatch"), std::string::npos)
      << e.what();
  EXPECT_EQ(e.line(), line_of(t, "h = \"10 W/m^2\""));
  const foxi::IoError v = build_error(replaced(kModel, "value = \"3e-3 A\"", "value = \"3 V\""));
  EXPECT_NE(v.reason().find("unit mismatch"), std::string::npos) << v.what();
  const foxi::IoError d =
      build_error(replaced(kModel, "value = \"t_amb degC\"", "value = \"t_amb * 1 mm degC\""));
  EXPECT_NE(d.reason().find("before degC"), std::string::npos) << d.what();
}

TEST(ModelConditionsBadInput, CelsiusWrittenAsKelvin) {
  const std::string t = replaced(kModel, "value = \"t_amb degC\"", "value = \"-20 K\"");
  const foxi::IoError e = build_error(t);
  EXPECT_NE(e.reason().find("not above absolute zero"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("-20 degC"), std::string::npos) << e.what();
  // below absolute zero in degC is refused as well (it was once taken as -26.85 K)
  const std::string c = replaced(kModel, "value = \"t_amb degC\"", "value = \"-300 degC\"");
  const foxi::IoError ce = build_error(c);
  EXPECT_NE(ce.reason().find("not above absolute zero"), std::string::npos) << ce.what();
  EXPECT_EQ(ce.line(), line_of(c, "value = \"-300 degC\""));
}

TEST(ModelConditionsBadInput, CelsiusInAParameterIsExplained) {
  const std::string t = replaced(kModel, "t_amb = \"25\"", "t_amb = \"25 degC\"");
  const foxi::IoError e = build_error(t);
  EXPECT_NE(e.reason().find("parameter 't_amb'"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("degC is an absolute temperature"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), line_of(t, "t_amb = "));
}

TEST(ModelConditionsBadInput, TwoThermalConditionsOnOneSurface) {
  const std::string t = replaced(kModel, "surface = \"island.top\"", "surface = \"cube.top\"");
  const foxi::IoError e = build_error(t);
  EXPECT_NE(e.reason().find("surface 'cube.top' already has a 'convection' condition"), std::string::npos)
      << e.what();
  EXPECT_EQ(e.line(), line_of(t, "type = \"heat_flux\"") - 1);
}

TEST(ModelConditionsBadInput, SelectorThatPicksNothingAndOneThatTookEverything) {
  const std::string t = replaced(kModel, "normal = [0, 0, 2]", "normal = [1, 1, 0]");
  const foxi::IoError e = build_error(t);
  EXPECT_NE(e.reason().find("surface 'base' picks no outer boundary facet"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), line_of(t, "[surfaces.base]"));
  const foxi::IoError g = build_error(replaced(kModel, "surface = \"base\"", "surface = \"lower.bottom\""));
  EXPECT_NE(g.reason().find("'lower.bottom' has no facets left"), std::string::npos) << g.what();
}

TEST(ModelConditionsBadInput, UnknownTypesPartsAndKeys) {
  EXPECT_NE(build_error(replaced(kModel, "type = \"sliding\"", "type = \"slipping\""))
                .reason()
                .find("unknown condition type 'slipping'"),
            std::string::npos);
  EXPECT_NE(
      build_error(replaced(kModel, "part = \"cube\"", "part = \"cub\"")).reason().find("unknown part 'cub'"),
      std::string::npos);
  EXPECT_NE(build_error(replaced(kModel, "parts = { cube", "parts = { cubes"))
                .reason()
                .find("unknown part 'cubes'"),
            std::string::npos);
  EXPECT_NE(build_error(replaced(kModel, "h = \"10", "hh = 1\nh = \"10")).reason().find("unknown key 'hh'"),
            std::string::npos);
  EXPECT_NE(
      build_error(replaced(kModel, "value = \"0.5 W\"", "value = \"0.5 K\"")).reason().find("unit mismatch"),
      std::string::npos);
  EXPECT_NE(build_error(replaced(kModel, "quality = 1.5", "quality = 0.5")).reason().find("mesh quality"),
            std::string::npos);
  // Below sqrt(2) TetGen's refinement ran for minutes on thin layers: refused with the bound named.
  EXPECT_NE(build_error(replaced(kModel, "quality = 1.5", "quality = 1.2")).reason().find("at least 1.414"),
            std::string::npos);
  // The issue's own case (past 120 s on die_on_substrate before the bound).
  EXPECT_NE(build_error(replaced(kModel, "quality = 1.5", "quality = 1.0")).reason().find("at least 1.414"),
            std::string::npos);
}

}  // namespace
