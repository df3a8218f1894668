// Models solved end to end (model file -> PLC -> TetGen mesh -> the model's conditions and loads ->
// solver), against analytic answers for layered slabs (heat through two layers with convection, the
// resistance of a two-material bar, a two-dielectric plate capacitor: all piecewise linear in z, so
// P1 elements are exact) and, for every model shipped in models/, against conservation: the heat
// through the boundaries equals the power put in (1e-6), the region volumes equal the parts'
// volumes, the Joule heat equals the terminals' V I. Thermal stress from the model: a bar between
// sliding ends (sigma = -E alpha dT), free expansion on three symmetry planes (u = alpha dT x), and
// the model's thermal run as the load (a linear temperature field: no stress in a free body).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "foxi/mesher/conforming.hpp"
#include "foxi/mesher/model_mesh_params.hpp"
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/structure.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/solver/model_problem.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

using test::TempDir;

const std::string kModels = test::data_dir() + "/../../models/";

struct Solved {
  Model model;
  Structure structure;
  Mesh mesh;
};

// What foxi solve MODEL does before the solve.
Solved mesh_model(const std::filesystem::path& file, std::vector<std::string> sets = {}) {
  Solved s;
  s.model = load_model(file, sets);
  s.structure = build_structure(s.model);
  Plc plc = s.structure.plc;
  const ModelMeshParams mp = mesh_params_from_model(s.model, plc);
  s.mesh = mesh_conforming(plc, mp.params);  // the path foxi solve MODEL takes
  name_mesh(s.model, s.structure, s.mesh);
  validate_and_repair(s.mesh);
  return s;
}

// Signed volume of tet t.
double tet_volume(const Mesh& mesh, std::size_t t) {
  const double* p[4];
  for (int i = 0; i < 4; ++i) p[i] = &mesh.xyz[3 * std::size_t{mesh.tet[4 * t + i]}];
  double a[3], b[3], c[3];
  for (int k = 0; k < 3; ++k) a[k] = p[1][k] - p[0][k], b[k] = p[2][k] - p[0][k], c[k] = p[3][k] - p[0][k];
  return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6;
}

// A 3 x 2 mm slab of two layers, lower (t1, k1, sigma1, eps1) and upper (t2, ...), in z.
std::string slab(const std::string& conditions) {
  return R"TOML(units.length = "mm"
[parameters]
t1 = "0.5 mm"
t2 = "1.5 mm"
[materials.a]
thermal_conductivity = 2.0
electrical_conductivity = 1e3
relative_permittivity = 4
[materials.b]
thermal_conductivity = 50.0
electrical_conductivity = 20.0
relative_permittivity = 10
[[parts]]
name = "slab"
shape = "layers"
origin = [0, 0, 0]
footprint = [3, 2]
thicknesses = ["t1", "t2"]
names = ["lower", "upper"]
materials = ["a", "b"]
[mesh]
max_size = "0.6 mm"
min_dihedral = 5
)TOML" + conditions;
}
constexpr double kArea = 3e-3 * 2e-3, kT1 = 0.5e-3, kT2 = 1.5e-3;

TEST(ModelSolve, HeatThroughTwoLayersWithConvectionIsAnalytic) {
  TempDir dir;
  test::write_text(dir / "slab.toml", slab(R"TOML(
[surfaces.base]
plane = { point = [0, 0, 0], normal = [0, 0, 1] }
[[conditions]]
type = "temperature"
surface = "base"
value = "25 degC"
[[conditions]]
type = "convection"
surface = "upper.top"
h = "1000 W/(m^2*K)"
ambient = "125 degC"
)TOML"));
  Solved s = mesh_model(dir / "slab.toml");
  check_physics(s.model, Physics::thermal);
  const ThermalReport r = solve_thermal(s.mesh, thermal_params_from_model(s.model, s.mesh));
  // series resistances per area: 1/h + t1/k1 + t2/k2
  const double q = (125 - 25) / (1 / 1000.0 + kT1 / 2.0 + kT2 / 50.0);
  EXPECT_NEAR(r.max_temperature, 398.15 - q / 1000.0, 1e-8 * 398.15);
  ASSERT_EQ(r.boundaries.size(), 2u);
  for (const BoundaryHeat& b : r.boundaries)
    EXPECT_NEAR(b.heat_in, (b.kind == "fixed" ? -q : q) * kArea, 1e-8 * q * kArea) << b.kind;
}

TEST(ModelSolve, ResistanceOfATwoMaterialBarIsAnalytic) {
  TempDir dir;
  test::write_text(dir / "bar.toml", slab(R"TOML(
[[conditions]]
type = "ground"
surface = "lower.bottom"
[[conditions]]
type = "current"
surface = "upper.top"
value = "2 mA"
)TOML"));
  Solved s = mesh_model(dir / "bar.toml");
  check_physics(s.model, Physics::current);
  const CurrentReport r = solve_current(s.mesh, current_params_from_model(s.model, s.mesh));
  const double resistance = kT1 / (1e3 * kArea) + kT2 / (20.0 * kArea);
  ASSERT_EQ(r.terminals.size(), 2u);
  EXPECT_NEAR(r.terminals[1].voltage, 2e-3 * resistance, 1e-8 * 2e-3 * resistance);
  EXPECT_NEAR(r.terminals[0].charge, -2e-3, 1e-9);
  EXPECT_NEAR(r.total_power, 4e-6 * resistance, 1e-8 * 4e-6 * resistance);
}

TEST(ModelSolve, TwoDielectricPlateCapacitorIsAnalytic) {
  TempDir dir;
  test::write_text(dir / "cap.toml", slab(R"TOML(
[[conditions]]
type = "ground"
surface = "lower.bottom"
name = "bottom"
[[conditions]]
type = "voltage"
surface = "upper.top"
name = "top"
value = "5 V"
)TOML"));
  Solved s = mesh_model(dir / "cap.toml");
  check_physics(s.model, Physics::electrostatic);
  const ElectrostaticReport r = solve_electrostatic(s.mesh, electrostatic_params_from_model(s.model, s.mesh));
  const double c = kVacuumPermittivity * kArea / (kT1 / 4 + kT2 / 10);
  ASSERT_EQ(r.conductors.size(), 2u);
  EXPECT_EQ(r.conductors[1].name, "top");
  EXPECT_NEAR(r.capacitance[1][1], c, 1e-8 * c);
  EXPECT_NEAR(r.capacitance[0][1], -c, 1e-8 * c);
  EXPECT_NEAR(r.conductors[1].charge, 5 * c, 5e-8 * c);
}

// A 4 x 1 x 1 mm block of one material, and [surfaces] for its x = 0, x = 4, y = 0 and z = 0 faces.
std::string block(const std::string& conditions) {
  return R"TOML(units.length = "mm"
[materials.m]
thermal_conductivity = 10.0
youngs_modulus = 100e9
poisson_ratio = 0.3
thermal_expansion = 1e-5
[[parts]]
name = "block"
material = "m"
shape = "box"
origin = [0, 0, 0]
size = [4, 1, 1]
[surfaces.west]
plane = { point = [0, 0, 0], normal = [1, 0, 0] }
[surfaces.east]
plane = { point = [4, 0, 0], normal = [1, 0, 0] }
[surfaces.south]
plane = { point = [0, 0, 0], normal = [0, 1, 0] }
[surfaces.base]
plane = { point = [0, 0, 0], normal = [0, 0, 1] }
[mesh]
max_size = "0.5 mm"
min_dihedral = 5
)TOML" + conditions;
}
constexpr double kE = 100e9, kNu = 0.3, kAlpha = 1e-5;

// The 6 stress components of tet t.
std::span<const double> tet_stress(const Mesh& mesh, std::size_t t) {
  return mesh.find_field("stress")->step(0, mesh.tet_count()).subspan(6 * t, 6);
}

// A bar whose end faces slide (u_x = 0 there) and whose y = 0 and z = 0 faces slide (symmetry planes,
// holding the rest of the rigid motions): uniaxial stress sigma_xx = -E alpha dT, the other components
// 0, von Mises E alpha |dT| (a linear displacement, exact with P1).
TEST(ModelSolve, BarHeldBetweenSlidingEndsHasSigmaMinusEAlphaDT) {
  TempDir dir;
  test::write_text(dir / "bar.toml", block(R"TOML(
[[conditions]]
type = "sliding"
surface = ["west", "east"]
[[conditions]]
type = "sliding"
surface = ["south", "base"]
[[loads]]
type = "temperature_change"
value = "-80 K"
)TOML"));
  Solved s = mesh_model(dir / "bar.toml");
  check_physics(s.model, Physics::thermal_stress);  // sliding conditions alone may hold a body
  const ThermoelasticParams p = thermoelastic_params_from_model(s.model, s.mesh);
  EXPECT_EQ(p.sliding.size(), 4u);
  EXPECT_EQ(p.delta_t, -80);
  ASSERT_EQ(p.materials.size(), 1u);
  EXPECT_EQ(p.materials[0].youngs_modulus, kE);
  const ThermoelasticReport r = solve_thermoelastic(s.mesh, p);
  const double sigma = -kE * kAlpha * -80;
  for (std::size_t t = 0; t < s.mesh.tet_count(); ++t) {
    const auto st = tet_stress(s.mesh, t);
    ASSERT_NEAR(st[0], sigma, 1e-6 * sigma) << "tet " << t;
    for (int c = 1; c < 6; ++c) ASSERT_NEAR(st[c], 0, 1e-6 * sigma) << "tet " << t << " component " << c;
  }
  EXPECT_NEAR(r.max_von_mises, std::abs(sigma), 1e-6 * std::abs(sigma));
}

// Free expansion held only by three symmetry planes: u = alpha dT x (every node), no stress.
TEST(ModelSolve, BlockOnThreeSymmetryPlanesExpandsFreely) {
  TempDir dir;
  test::write_text(dir / "free.toml", block(R"TOML(
[[conditions]]
type = "sliding"
surface = ["west", "south", "base"]
[[loads]]
type = "temperature_change"
value = "50 K"
)TOML"));
  Solved s = mesh_model(dir / "free.toml");
  const ThermoelasticReport r = solve_thermoelastic(s.mesh, thermoelastic_params_from_model(s.model, s.mesh));
  const std::span<const double> u = s.mesh.find_field("displacement")->step(0, s.mesh.node_count());
  for (std::size_t i = 0; i < s.mesh.xyz.size(); ++i)
    ASSERT_NEAR(u[i], kAlpha * 50 * s.mesh.xyz[i], 1e-9 * kAlpha * 50 * 4e-3) << "node " << i / 3;
  EXPECT_LT(r.max_von_mises, 1e-6 * kE * kAlpha * 50);
}

// Thermal stress needs a condition that holds the body: a temperature condition alone does not.
TEST(ModelSolve, ThermalStressWithoutDisplacementOrSlidingIsNotReady) {
  TempDir dir;
  test::write_text(dir / "loose.toml", block(R"TOML(
[[conditions]]
type = "temperature"
surface = "west"
value = "300 K"
)TOML"));
  const Model model = load_model(dir / "loose.toml");
  check_physics(model, Physics::thermal);
  try {
    check_physics(model, Physics::thermal_stress);
    ADD_FAILURE() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("a displacement or sliding condition"), std::string::npos)
        << e.what();
  }
}

// A per-part temperature change that differs between parts is refused (interface nodes are shared).
TEST(ModelSolve, DifferentTemperatureChangesPerPartAreRefused) {
  TempDir dir;
  test::write_text(dir / "two.toml", slab(R"TOML(
[[conditions]]
type = "displacement"
surface = "lower.bottom"
value = [0, 0, 0]
[[loads]]
type = "temperature_change"
part = "lower"
value = "10 K"
[[loads]]
type = "temperature_change"
part = "upper"
value = "20 K"
)TOML"));
  Solved s = mesh_model(dir / "two.toml");
  EXPECT_THROW(thermoelastic_params_from_model(s.model, s.mesh), SolverError);
}

// Coupled: the model's thermal run (temperatures fixed on the end faces: T linear in x, exact with P1)
// is the load. A linear temperature field in a body free of constraints gives no stress
// (u = alpha [(c0 + c1 x) (0, y, z) + (c0 x + c1 (x^2 - y^2 - z^2) / 2, 0, 0)] is compatible). The
// bar is held by the y = 0 and z = 0 symmetry planes and, against the x translation, by u_x = 0 on
// one x = 0 triangle at the origin (where that field's u_x is O(h^2)). P1 cannot represent the
// quadratic u, so the stress is O(E alpha |grad T| h) rather than 0: its volume RMS is compared with
// E alpha dT, shown to halve with h, and contrasted with the same load on a bar whose ends slide.
TEST(ModelSolve, LinearTemperatureFromTheThermalRunGivesNoStressInAFreeBlock) {
  TempDir dir;
  const std::string conditions = R"TOML(
[[conditions]]
type = "temperature"
surface = "west"
value = "300 K"
[[conditions]]
type = "temperature"
surface = "east"
value = "400 K"
[[conditions]]
type = "sliding"
surface = ["south", "base"]
)TOML";
  // RMS von Mises over the volume, of the free bar (or the one whose ends slide) at mesh size `size`
  auto rms_von_mises = [&](const std::string& size, bool ends_slide) {
    std::string text = block(conditions);
    text.replace(text.find("0.5 mm"), 6, size);
    test::write_text(dir / "grad.toml", text);
    Solved s = mesh_model(dir / "grad.toml");
    check_physics(s.model, Physics::thermal);
    check_physics(s.model, Physics::thermal_stress);
    solve_thermal(s.mesh, thermal_params_from_model(s.model, s.mesh));
    const Field* temperature = s.mesh.find_field("temperature");
    for (std::size_t i = 0; i < s.mesh.node_count(); ++i)
      EXPECT_NEAR(temperature->values[i], 300 + 25 * s.mesh.xyz[3 * i] / 1e-3, 1e-6) << "node " << i;

    ThermoelasticParams p = thermoelastic_params_from_model(s.model, s.mesh);
    EXPECT_EQ(p.delta_t, 0);
    p.temperature = temperature->values;
    p.reference_temperature = 300;  // held ends: sigma_xx about -E alpha (mean T - 300 K)
    std::int32_t pin = 0;
    for (const Boundary& b : s.mesh.boundaries) pin = std::max(pin, b.tag + 1);
    for (const Boundary& b : s.mesh.boundaries)
      if (ends_slide && (b.name == "west" || b.name == "east")) p.sliding.push_back({b.tag});
    // the x = 0 triangle with the node at the origin gets its own tag, where u_x = 0
    for (std::size_t f = 0; f < s.mesh.bface_count() && !ends_slide && s.mesh.find_boundary(pin) == nullptr;
         ++f)
      for (int a = 0; a < 3; ++a) {
        const double* x = &s.mesh.xyz[3 * std::size_t{s.mesh.bface[3 * f + a]}];
        if (x[0] == 0 && x[1] == 0 && x[2] == 0) {
          s.mesh.bface_tag[f] = pin;
          s.mesh.boundaries.push_back({pin, "pin"});
          FixedDisplacement hold;
          hold.tag = pin;
          hold.fix[1] = hold.fix[2] = false;
          p.fixed.push_back(hold);
          break;
        }
      }
    EXPECT_EQ(p.fixed.size(), ends_slide ? 0u : 1u);
    solve_thermoelastic(s.mesh, p);
    const std::span<const double> vm = s.mesh.find_field("von_mises")->step(0, s.mesh.tet_count());
    double sum = 0, volume = 0;
    for (std::size_t t = 0; t < s.mesh.tet_count(); ++t) {
      const double v = tet_volume(s.mesh, t);
      sum += v * vm[t] * vm[t];
      volume += v;
    }
    return std::sqrt(sum / volume);
  };
  const double scale = kE * kAlpha * 100;
  const double coarse = rms_von_mises("0.5 mm", false), fine = rms_von_mises("0.25 mm", false);
  const double held = rms_von_mises("0.5 mm", true);
  EXPECT_LT(coarse, 0.06 * scale);
  EXPECT_LT(fine, 0.65 * coarse);
  EXPECT_GT(held, 0.2 * scale);
}

// Coarser versions of shipped models whose realistic thin layers make large meshes.
const std::map<std::string, std::vector<std::string>> kCoarse = {
    {"power_module.toml", {"solder_h=0.5mm", "cu_h=0.5mm", "ceramic_h=0.6mm", "die_h=0.5mm", "clip_h=1mm"}},
};

// Slow (every shipped model meshed and solved, about 5 minutes under the sanitizers): the Release
// pass runs it.
TEST(ModelSolveSlow, EveryShippedModelMeshesAndSolvesWithBalancedEnergy) {
  std::size_t models = 0, stress_models = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kModels)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".toml" || name == "materials.toml") continue;
    SCOPED_TRACE(name);
    ++models;
    const auto coarse = kCoarse.find(name);
    Solved s =
        mesh_model(entry.path(), coarse == kCoarse.end() ? std::vector<std::string>{} : coarse->second);
    EXPECT_LT(s.mesh.tet_count(), 120000u) << "too large a mesh for a unit test";
    // every part is its region, with the part's volume
    std::vector<double> volume(s.model.parts.size() + 1, 0);
    for (std::size_t t = 0; t < s.mesh.tet_count(); ++t) {
      volume[static_cast<std::size_t>(s.mesh.tet_region[t])] += tet_volume(s.mesh, t);
    }
    for (std::size_t p = 0; p < s.model.parts.size(); ++p)
      EXPECT_NEAR(volume[p + 1], s.structure.part_volume[p], 1e-9 * s.structure.part_volume[p])
          << s.model.parts[p].name;

    bool thermal = false;
    std::size_t conductors = 0;
    for (const BoundaryCondition& c : s.model.conditions) {
      thermal = thermal || condition_applies(c, Physics::thermal);
      conductors += condition_applies(c, Physics::electrostatic);
    }
    const bool electric = conductors >= 2;
    bool stress = false;
    for (const BoundaryCondition& c : s.model.conditions)
      stress = stress || condition_applies(c.kind, Physics::thermal_stress);
    if (stress) {
      // thermal stress under the model's uniform temperature change: converged, a finite positive
      // maximum in a region of the model, each part's material
      ++stress_models;
      check_physics(s.model, Physics::thermal_stress);
      const ThermoelasticParams ep = thermoelastic_params_from_model(s.model, s.mesh);
      EXPECT_NE(ep.delta_t, 0);
      const ThermoelasticReport r = solve_thermoelastic(s.mesh, ep);
      EXPECT_LT(r.relative_residual, 1e-6);
      EXPECT_TRUE(std::isfinite(r.max_von_mises));
      EXPECT_GT(r.max_von_mises, 0);
      ASSERT_EQ(r.regions.size(), s.model.parts.size());
      for (std::size_t p = 0; p < r.regions.size(); ++p)
        for (const Material& m : s.model.materials)
          if (m.name == s.model.parts[p].material) {
            EXPECT_EQ(r.regions[p].youngs_modulus, m.youngs_modulus);
          }
    }
    EXPECT_TRUE(thermal) << "every example has its thermal conditions";
    if (thermal) {
      check_physics(s.model, Physics::thermal);
      const ThermalParams tp = thermal_params_from_model(s.model, s.mesh);
      double expected_power = 0;
      for (const Load& l : s.model.loads)
        for (std::size_t p = 0; p < s.model.parts.size(); ++p)
          if (l.kind == LoadKind::power && s.model.parts[p].name == l.part)
            expected_power += l.total ? l.value : l.value * s.structure.part_volume[p];
      const ThermalReport r = solve_thermal(s.mesh, tp);
      EXPECT_NEAR(r.total_power, expected_power, 1e-9 * expected_power);
      double out = 0;
      for (const BoundaryHeat& b : r.boundaries) out -= b.heat_in;
      EXPECT_NEAR(out, expected_power, 1e-6 * expected_power);
      EXPECT_GT(r.max_temperature, 0);
      for (const BalanceCheck& c : r.checks) EXPECT_TRUE(c.passed) << c.name << " " << c.figure;
    }
    if (electric) {
      // electrostatics: the capacitance matrix's diagonal is positive and every balance check passes
      check_physics(s.model, Physics::electrostatic);
      const ElectrostaticReport e =
          solve_electrostatic(s.mesh, electrostatic_params_from_model(s.model, s.mesh));
      for (std::size_t i = 0; i < e.conductors.size(); ++i) EXPECT_GT(e.capacitance[i][i], 0);
      for (const BalanceCheck& c : e.checks) EXPECT_TRUE(c.passed) << c.name << " " << c.figure;
      EXPECT_NEAR(e.energy, e.field_energy, 1e-6 * e.field_energy);
    }
  }
  EXPECT_GE(models, 6u);
  EXPECT_GE(stress_models, 3u);
}

// DC conduction of the via (copper into silicon through its bottom; the oxide carries ~nothing):
// Joule heat in the regions equals the terminals' sum of V I, and the currents balance.
TEST(ModelSolve, ViaCurrentConservesChargeAndEnergy) {
  Solved s = mesh_model(kModels + "via_in_dielectric.toml");
  check_physics(s.model, Physics::current);
  const CurrentReport r = solve_current(s.mesh, current_params_from_model(s.model, s.mesh));
  ASSERT_EQ(r.terminals.size(), 2u);
  // The via's terminal is on copper (sigma 1.4e11 times silicon's): its current, from the energy form,
  // balances the grounded back's in silicon (nodal reactions on copper lost 0.13 % to round-off).
  const double current = -r.terminals[1].charge;
  EXPECT_NEAR(r.terminals[0].charge, current, 1e-8 * current);
  for (const BalanceCheck& c : r.checks) EXPECT_TRUE(c.passed) << c.name << " " << c.figure;
  double joule = 0;
  for (const RegionJoule& j : r.regions) joule += j.power;
  EXPECT_NEAR(joule, r.terminals[0].voltage * current, 1e-6 * joule);
  EXPECT_GT(r.resistance, 0);
}

}  // namespace
}  // namespace foxi
