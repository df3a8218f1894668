// foxi solve (the command line) on a TetGen slab: the written .vtu holds the exact linear profile,
// and bad input gives the documented exit statuses and messages.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "foxi/model/mesh_io.hpp"
#include "layered_box.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

// The unit cube, facet markers 1 (x = 0), 2 (x = 1), 3 (the rest), region 1.
const char* kCubePoly =
    "8 3 0 0\n1 0 0 0\n2 0 1 0\n3 0 1 1\n4 0 0 1\n5 1 0 0\n6 1 1 0\n7 1 1 1\n8 1 0 1\n"
    "6 1\n1 0 1\n4 1 2 3 4\n1 0 2\n4 5 6 7 8\n1 0 3\n4 1 2 6 5\n1 0 3\n4 2 3 7 6\n"
    "1 0 3\n4 3 4 8 7\n1 0 3\n4 4 1 5 8\n0\n1\n1 0.5 0.5 0.5 1 0\n";

class SolveCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::have_program("tetgen")) GTEST_SKIP() << "tetgen not installed";
    if (!std::filesystem::exists(test::cli_path())) GTEST_SKIP() << "the foxi program is not built";
    test::write_text(dir_ / "cube.poly", kCubePoly);
    ASSERT_EQ(
        test::run("tetgen -pq1.414AQa0.002 '" + (dir_ / "cube.poly").string() + "'", dir_ / "tetgen.log"), 0);
  }
  int foxi(const std::string& args) {
    return test::run("'" + test::cli_path() + "' " + args, dir_ / "out.log");
  }
  std::string mesh() const { return "'" + (dir_ / "cube.1.node").string() + "'"; }
  test::TempDir dir_;
};

TEST_F(SolveCliTest, WritesTheExactLinearProfile) {
  const std::string out = (dir_ / "result.vtu").string();
  ASSERT_EQ(foxi("solve " + mesh() + " --physics thermal --fix 1=300 --fix 2=400 --k 1=2 -o '" + out + "'"),
            0)
      << test::read_text(dir_ / "out.log");
  const std::string log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("max temperature 400 K"), std::string::npos) << log;
  const Mesh m = read_mesh(out);
  const Field* t = m.find_field("temperature");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->unit, "K");
  double worst = 0;
  for (std::size_t v = 0; v < m.node_count(); ++v)
    worst = std::max(worst, std::abs(t->values[v] - (300 + 100 * m.xyz[3 * v])));
  EXPECT_LT(worst, 1e-9);
  const Field* q = m.find_field("heat_flux");
  ASSERT_NE(q, nullptr);
  ASSERT_EQ(q->components, 3u);
  for (std::size_t c = 0; c < m.tet_count(); ++c) EXPECT_NEAR(q->values[3 * c], -200.0, 1e-7);
}

// Plates at x = 0 and 1 around the unit cube: C = eps0 eps_r, R = 1 / sigma, Joule heat V^2 / R.
TEST_F(SolveCliTest, CapacitanceAndResistanceOfTheCube) {
  const std::string out = (dir_ / "e.vtu").string();
  ASSERT_EQ(
      foxi("solve " + mesh() +
           " --physics electrostatic --conductor 1=left:1 --conductor 2=right --eps 1=2 -o '" + out + "'"),
      0)
      << test::read_text(dir_ / "out.log");
  std::string log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("1.770838e-11  -1.770838e-11"), std::string::npos) << log;  // 2 * 8.8541878128e-12
  const Mesh m = read_mesh(out);
  const Field* phi = m.find_field("potential");
  ASSERT_NE(phi, nullptr);
  for (std::size_t v = 0; v < m.node_count(); ++v) EXPECT_NEAR(phi->values[v], 1 - m.xyz[3 * v], 1e-9);
  ASSERT_NE(m.find_field("electric_field"), nullptr);

  ASSERT_EQ(foxi("solve " + mesh() + " --physics current --terminal 1=2 --terminal 2=0 --sigma 1=4"), 0)
      << test::read_text(dir_ / "out.log");
  log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("resistance 2.500000e-01 ohm"), std::string::npos) << log;
  EXPECT_NE(log.find("total Joule heat 1.600000e+01 W"), std::string::npos) << log;
  EXPECT_EQ(foxi("solve " + mesh() + " --physics current --terminal-current 1=2 --sigma 1=4"), 3);
  EXPECT_NE(test::read_text(dir_ / "out.log").find("ill-posed"), std::string::npos);
  EXPECT_EQ(foxi("solve " + mesh() + " --physics electrostatic --conductor 1=a --conductor 2=b"), 3);
  EXPECT_NE(test::read_text(dir_ / "out.log").find("no relative permittivity"), std::string::npos);
  EXPECT_EQ(foxi("solve " + mesh() + " --physics electrostatic --conductor 1=a --fix 2=3 --eps 1=1"), 2);
}

// The unit cube held at 300 K at x = 0, 100 W/m^2 into x = 1, k = 2: theta = L / (k A) = 0.5 K/W from
// the hottest node to boundary 1, and with a 5 W/(m^2 K) film on x = 0 instead, theta_JA adds 1 / (h A).
TEST_F(SolveCliTest, ThetaIsTheSlabResistance) {
  ASSERT_EQ(foxi("solve " + mesh() + " --fix 1=300 --flux 2=100 --k 1=2 --theta 1:1"), 0)
      << test::read_text(dir_ / "out.log");
  std::string log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("dT 50 K, P 100 W, theta 0.5 K/W; heat out there 100 W, dT/heat 0.5 K/W"),
            std::string::npos)
      << log;
  ASSERT_EQ(foxi("solve " + mesh() + " --convect 1=5,300 --flux 2=100 --k 1=2 --theta max=1:ambient=1"), 0)
      << test::read_text(dir_ / "out.log");
  log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("theta 0.7 K/W"), std::string::npos) << log;
  EXPECT_EQ(foxi("solve " + mesh() + " --fix 1=300 --flux 2=100 --k 1=2 --theta 1:ambient=1"), 3);
  EXPECT_NE(test::read_text(dir_ / "out.log").find("no convection condition"), std::string::npos);
  EXPECT_EQ(foxi("solve " + mesh() + " --fix 1=300 --k 1=2 --theta 1"), 2);
  EXPECT_EQ(foxi("solve " + mesh() + " --fix 1=300 --k 1=2 --theta hottest=1:1"), 2);
}

TEST_F(SolveCliTest, BadInputGivesClearErrors) {
  EXPECT_EQ(foxi("solve " + mesh() + " --fix 1=300"), 3);  // no conductivity
  EXPECT_NE(test::read_text(dir_ / "out.log").find("region 1 has no thermal conductivity"),
            std::string::npos);
  EXPECT_EQ(foxi("solve " + mesh() + " --flux 1=10 --k 1=1"), 3);
  EXPECT_NE(test::read_text(dir_ / "out.log").find("ill-posed"), std::string::npos);
  EXPECT_EQ(foxi("solve " + mesh() + " --fix 1=abc --k 1=1"), 2);
  EXPECT_EQ(foxi("solve " + mesh() + " --fix 1=300 --k 1=1 --frobnicate 3"), 2);
  EXPECT_EQ(foxi("solve " + mesh() + " --physics magic --fix 1=300 --k 1=1"), 2);
  EXPECT_EQ(foxi("solve " + mesh() + " --fix 1=300 --k 1=1 --solver nope"), 2);
  EXPECT_EQ(foxi("solve --help"), 0);
  // A name two boundaries share names neither (--fix fixed the first of two Gmsh surfaces "face";
  // an outside probe): a usage error naming both tags; the tags themselves work.
  Mesh m = read_mesh(dir_ / "cube.1.node");
  m.boundaries = {{1, "face"}, {2, "face"}, {3, "rest"}};
  m.regions = {{1, "solid", kNone}};
  write_mesh(m, dir_ / "named.vtu");
  const std::string named = "'" + (dir_ / "named.vtu").string() + "'";
  EXPECT_EQ(foxi("solve " + named + " --fix face=300 --k solid=1"), 2);
  EXPECT_NE(test::read_text(dir_ / "out.log").find("the name 'face' names the boundaries 1 and 2"),
            std::string::npos)
      << test::read_text(dir_ / "out.log");
  EXPECT_EQ(foxi("solve " + named + " --fix 1=300 --fix 2=400 --k solid=1"), 0)
      << test::read_text(dir_ / "out.log");
}

// Thermal stress from the command line on a 1 x 0.6 x 0.4 box (tags 1..6: x = 0, x = 1, y = 0,
// y = 0.6, z = 0, z = 0.4): sliding on the three planes through the origin, a uniform dT gives the
// exact free expansion u = alpha dT x in the written .vtu, and so does the temperature written by a
// thermal run (both ends at 350 K: uniform) read back with --temperature and --tref 300.
TEST_F(SolveCliTest, ThermoelasticFreeExpansionAndTemperatureFromTheThermalRun) {
  test::write_text(dir_ / "box.poly", test::layered_box_poly(1.0, 0.6, {0, 0.4}));
  ASSERT_EQ(test::run("tetgen -pq1.414AQa0.002 '" + (dir_ / "box.poly").string() + "'", dir_ / "tetgen.log"),
            0);
  const std::string box = "'" + (dir_ / "box.1.node").string() + "'";
  const std::string material = " --E 1=70e9 --nu 1=0.3 --alpha 1=2e-5 --slide 1 --slide 3 --slide 5";
  const std::string out = (dir_ / "stress.vtu").string();
  ASSERT_EQ(foxi("solve " + box + " --physics thermoelastic --dT 50" + material + " -o '" + out + "'"), 0)
      << test::read_text(dir_ / "out.log");
  std::string log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("max von Mises stress"), std::string::npos) << log;
  EXPECT_NE(log.find("max displacement 0.00123288"), std::string::npos) << log;  // 1e-3 |(1, 0.6, 0.4)|
  Mesh m = read_mesh(out);
  auto expansion_error = [](const Mesh& r) {
    const Field* u = r.find_field("displacement");
    EXPECT_NE(u, nullptr);
    if (!u) return HUGE_VAL;
    EXPECT_EQ(u->unit, "m");
    double worst = 0;
    for (std::size_t i = 0; i < 3 * r.node_count(); ++i)
      worst = std::max(worst, std::abs(u->values[i] - 1e-3 * r.xyz[i]));
    return worst;
  };
  EXPECT_LT(expansion_error(m), 1e-12);
  const Field* s = m.find_field("stress");
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->components, 6u);
  EXPECT_EQ(s->location, FieldLocation::cell);
  ASSERT_NE(m.find_field("von_mises"), nullptr);
  ASSERT_NE(m.find_field("principal_stress"), nullptr);

  const std::string temperature = (dir_ / "temperature.vtu").string();
  ASSERT_EQ(
      foxi("solve " + box + " --physics thermal --fix 1=350 --fix 2=350 --k 1=1 -o '" + temperature + "'"),
      0);
  ASSERT_EQ(foxi("solve " + box + " --physics thermoelastic --temperature '" + temperature + "' --tref 300" +
                 material + " -o '" + out + "'"),
            0)
      << test::read_text(dir_ / "out.log");
  EXPECT_LT(expansion_error(read_mesh(out)), 1e-12);
  // Quadratic tets: the same exact answer at the mesh's nodes; an order other than 1 or 2 is a usage error.
  ASSERT_EQ(
      foxi("solve " + box + " --physics thermoelastic --order 2 --dT 50" + material + " -o '" + out + "'"), 0)
      << test::read_text(dir_ / "out.log");
  EXPECT_NE(test::read_text(dir_ / "out.log").find("(P2)"), std::string::npos);
  EXPECT_LT(expansion_error(read_mesh(out)), 1e-12);
  EXPECT_EQ(foxi("solve " + box + " --physics thermoelastic --order 3 --dT 50" + material), 2);

  // The balance checks printed beside the result: a clamped box passes them. (A CG solve stopped at a
  // relative residual of 0.5 fails the force balance: thermoelastic_test; foxi solve refuses such a
  // --tol, which once loosened the thermal and DC checks with it: --tol 0.9 passed a temperature
  // 54 K off.)
  const std::string clamped = " --E 1=70e9 --nu 1=0.3 --alpha 1=2e-5 --fix 5 --dT 50";
  ASSERT_EQ(foxi("solve " + box + " --physics thermoelastic" + clamped), 0)
      << test::read_text(dir_ / "out.log");
  log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("check thermal load   ok"), std::string::npos) << log;
  EXPECT_NE(log.find("check force balance  ok"), std::string::npos) << log;
  EXPECT_EQ(foxi("solve " + box + " --physics thermoelastic" + clamped + " --solver ichol --tol 0.5"), 2);
  log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("--tol takes a relative residual in [1e-14, 1e-3]"), std::string::npos) << log;
  EXPECT_EQ(foxi("solve " + box + " --physics thermoelastic" + clamped + " --solver ichol --tol 1e-3"), 0)
      << test::read_text(dir_ / "out.log");

  // Bad input: no load (2), an unknown component (2), a body free to move (3, the modes named).
  EXPECT_EQ(foxi("solve " + box + " --physics thermoelastic" + material), 2);
  EXPECT_EQ(foxi("solve " + box + " --physics thermoelastic --dT 1 --fix 1=uw" + material), 2);
  EXPECT_EQ(
      foxi("solve " + box + " --physics thermoelastic --dT 1 --slide 5 --E 1=1e9 --nu 1=0.3 --alpha 1=1e-5"),
      3);
  log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("3 rigid-body modes left"), std::string::npos) << log;
  EXPECT_EQ(foxi("solve " + mesh() +
                 " --physics thermoelastic --dT 1 --slide 3 --E 1=1e9 --nu 1=0.3 --alpha 1=1e-5"),
            3);
  log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("not planar"), std::string::npos) << log;
  EXPECT_EQ(foxi("solve --physics thermoelastic --help"), 0);
}

// foxi solve MODEL.toml --physics thermoelastic: a 4 x 1 x 1 mm bar whose end faces slide (and its
// y = 0, z = 0 faces: symmetry planes). --temperature-from-thermal: both ends at 380 K, so the thermal
// run's field is uniform and the stress uniaxial, sigma_xx = -E alpha (380 - 300) K everywhere; --dT
// replaces it; no temperature load at all is a usage error (2).
TEST_F(SolveCliTest, ThermoelasticModelWithTheTemperatureOfItsThermalRun) {
  test::write_text(dir_ / "bar.toml", R"TOML(units.length = "mm"
[materials.m]
thermal_conductivity = 10.0
youngs_modulus = 100e9
poisson_ratio = 0.3
thermal_expansion = 1e-5
[[parts]]
name = "bar"
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
[[conditions]]
type = "temperature"
surface = ["west", "east"]
value = "380 K"
[[conditions]]
type = "sliding"
surface = ["west", "east", "south", "bar.bottom"]
[mesh]
max_size = "0.5 mm"
)TOML");
  const std::string bar = "'" + (dir_ / "bar.toml").string() + "'";
  const std::string out = (dir_ / "bar.vtu").string();
  ASSERT_EQ(foxi("solve " + bar + " --physics thermoelastic --temperature-from-thermal --tref 300 -o '" +
                 out + "'"),
            0)
      << test::read_text(dir_ / "out.log");
  std::string log = test::read_text(dir_ / "out.log");
  EXPECT_NE(log.find("max von Mises stress 8e+07 Pa"), std::string::npos) << log;  // E alpha 80 K
  EXPECT_NE(log.find("1 (bar)"), std::string::npos) << log;
  const Mesh m = read_mesh(out);
  const Field* stress = m.find_field("stress");
  ASSERT_NE(stress, nullptr);
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    ASSERT_NEAR(stress->values[6 * t], -8e7, 1e-6 * 8e7) << "tet " << t;
    ASSERT_NEAR(stress->values[6 * t + 1], 0, 1e-6 * 8e7) << "tet " << t;
  }
  ASSERT_EQ(foxi("solve " + bar + " --physics thermoelastic --dT -20 -o '" + out + "'"), 0)
      << test::read_text(dir_ / "out.log");
  EXPECT_NEAR(read_mesh(out).find_field("stress")->values[0], 2e7, 1e-6 * 2e7);

  EXPECT_EQ(foxi("solve " + bar + " --physics thermoelastic"), 2);  // no temperature_change load
  EXPECT_NE(test::read_text(dir_ / "out.log").find("no temperature_change load"), std::string::npos);
  EXPECT_EQ(foxi("solve " + mesh() + " --physics thermoelastic --temperature-from-thermal"), 2);
  EXPECT_EQ(foxi("solve " + bar + " --physics thermoelastic --dT 1 --temperature-from-thermal"), 2);
}

}  // namespace
}  // namespace foxi
