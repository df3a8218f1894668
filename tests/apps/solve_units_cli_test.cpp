// foxi solve's option values with units (--fix top=300K, '25 degC', --power die=3W, --dT 5degC) and
// foxi model check / foxi solve warnings on an unsound model. Oracles: a 1 mm cube held at 0 degC
// below and a fixed temperature above conducts linearly, which P1 elements reproduce exactly (the
// maximum is the fixed top, the heat k A dT / L); the same value written in other units gives the
// same printed line; linear thermoelasticity scales with dT (5 degC is a 5 K change, half of 10 K).
#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>

#include "test_util.hpp"

namespace {

using foxi::test::TempDir;
namespace test = foxi::test;

const char* kCube = R"TOML(units.length = "mm"
[materials.m]
thermal_conductivity = "1 W/(m*K)"
electrical_conductivity = 1
relative_permittivity = 1
youngs_modulus = "100 GPa"
poisson_ratio = 0.3
thermal_expansion = "10 ppm/K"
[[parts]]
name = "cube"
material = "m"
shape = "box"
origin = [0, 0, 0]
size = [1, 1, 1]
[[conditions]]
type = "temperature"
surface = "cube.bottom"
value = "0 degC"
[[conditions]]
type = "displacement"
surface = "cube.bottom"
value = [0, 0, 0]
[mesh]
max_size = "0.5 mm"
)TOML";

struct Result {
  int rc = 0;
  std::string out;
};

Result solve(const TempDir& dir, const std::string& args) {
  static int n = 0;
  const auto log = dir / ("run" + std::to_string(++n) + ".txt");
  Result r;
  r.rc = test::run_cli("solve '" + (dir / "cube.toml").string() + "' " + args, log);
  r.out = test::read_text(log);
  return r;
}

// The first line of `out` that starts with `prefix`.
std::string line(const std::string& out, const std::string& prefix) {
  for (std::size_t at = 0; at < out.size();) {
    const std::size_t end = std::min(out.find('\n', at), out.size());
    if (out.compare(at, prefix.size(), prefix) == 0) return out.substr(at, end - at);
    at = end + 1;
  }
  return "(no line '" + prefix + "')";
}

double number_after(const std::string& text, const std::string& label) {
  const std::smatch m = [&] {
    std::smatch x;
    std::regex_search(text, x, std::regex(label + R"(\s+([-+0-9.eE]+))"));
    return x;
  }();
  return m.empty() ? NAN : std::stod(m[1].str());
}

// The heat in through cube.top, from the boundary table's line "  N (cube.top)  fixed  AREA  HEAT ...".
double top_heat(const std::string& out) {
  std::smatch m;
  const std::string table = out.substr(std::min(out.find("boundaries"), out.size()));
  if (!std::regex_search(table, m, std::regex(R"(\(cube\.top\)\s+fixed\s+\S+\s+(\S+))"))) return NAN;
  return std::stod(m[1].str());
}

TEST(SolveUnitsCli, TemperaturesInKelvinOrCelsius) {
  TempDir dir;
  test::write_text(dir / "cube.toml", kCube);
  const Result c = solve(dir, "--physics thermal --fix cube.top=50degC --k 'cube=2 W/(m*K)'");
  ASSERT_EQ(c.rc, 0) << c.out;
  // no source: the maximum is the fixed top, 50 degC
  EXPECT_EQ(line(c.out, "max temperature").substr(0, 33), "max temperature 323.15 K (50 C) a") << c.out;
  // heat in through the top: k A dT / L = 2 * 1e-6 * 50 / 1e-3 = 0.1 W
  EXPECT_NEAR(top_heat(c.out), 0.1, 1e-9) << c.out;
  for (const char* same : {"--fix 'cube.top=50 degC' --k cube=2", "--fix cube.top=323.15K --k cube=2",
                           "--fix cube.top=323.15 --k 'cube=0.002 W/(mm*K)'"}) {
    const Result r = solve(dir, std::string("--physics thermal ") + same);
    ASSERT_EQ(r.rc, 0) << same << "\n" << r.out;
    EXPECT_EQ(line(r.out, "max temperature"), line(c.out, "max temperature")) << same;
    EXPECT_NEAR(top_heat(r.out), 0.1, 1e-9) << same << "\n" << r.out;
  }
}

TEST(SolveUnitsCli, PowerInWattsAndMilliwatts) {
  TempDir dir;
  test::write_text(dir / "cube.toml", kCube);
  const Result w = solve(dir, "--physics thermal --power cube=3W");
  ASSERT_EQ(w.rc, 0) << w.out;
  EXPECT_EQ(number_after(line(w.out, "energy balance"), "sources"), 3) << w.out;
  for (const char* same :
       {"--power cube=3000mW", "--power 'cube=3 W'", "--power cube=3", "--power-density 'cube=3 W/mm^3'"}) {
    const Result r = solve(dir, std::string("--physics thermal ") + same);
    ASSERT_EQ(r.rc, 0) << same << "\n" << r.out;
    EXPECT_EQ(line(r.out, "max temperature"), line(w.out, "max temperature")) << same;
  }
}

// --power on a model that loads the region already replaces the model's load and says so: the
// temperature rise over the held bottom is linear in the power, so 3 W instead of the model's 1 W
// gives three times the rise; the same region twice on the command line is a usage error.
TEST(SolveUnitsCli, PowerReplacesTheModelsLoad) {
  TempDir dir;
  test::write_text(dir / "cube.toml",
                   std::string(kCube) + "[[loads]]\ntype = \"power\"\npart = \"cube\"\nvalue = \"1 W\"\n");
  const Result model = solve(dir, "--physics thermal");
  ASSERT_EQ(model.rc, 0) << model.out;
  EXPECT_EQ(number_after(line(model.out, "energy balance"), "sources"), 1) << model.out;
  for (const char* option : {"--power cube=3W", "--power-density 'cube=3 W/mm^3'"}) {
    const Result r = solve(dir, std::string("--physics thermal ") + option);
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("replaces the model's load on"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("(1 W)"), std::string::npos) << r.out;
    EXPECT_EQ(number_after(line(r.out, "energy balance"), "sources"), 3) << r.out;
    const double rise1 = number_after(model.out, "max temperature") - 273.15,
                 rise3 = number_after(r.out, "max temperature") - 273.15;
    EXPECT_NEAR(rise3, 3 * rise1, 1e-5 * rise3) << r.out;
  }
  EXPECT_EQ(solve(dir, "--physics thermal --power cube=3W --power cube=2W").rc, 2);
}

TEST(SolveUnitsCli, WrongDimensionAndNegativeKelvinAreUsageErrors) {
  TempDir dir;
  test::write_text(dir / "cube.toml", kCube);
  struct Bad {
    const char* args;
    const char* says;
  };
  for (const Bad& b :
       {Bad{"--power cube=3m", "--power: unit mismatch: '3m' is m, not W"}, Bad{"--k cube=2W", "not W/(m*K)"},
        Bad{"--fix cube.top=5V", "--fix: unit mismatch: '5V'"},
        Bad{"--fix cube.top=-5", "not above absolute zero"},
        Bad{"--fix cube.top=-300degC", "not above absolute zero"},
        Bad{"--convect 'cube.top=10 W/(m^2*K),-1K'", "--convect: '-1K' = -1 K is not above"},
        Bad{"--convect 'cube.top=10 W/m^2,300K'", "--convect: unit mismatch"},
        Bad{"--flux cube.top=5W", "not W/m^2"}}) {
    const Result r = solve(dir, std::string("--physics thermal ") + b.args);
    EXPECT_EQ(r.rc, 2) << b.args << "\n" << r.out;
    EXPECT_NE(r.out.find(b.says), std::string::npos) << b.args << "\n" << r.out;
  }
  // refused before the meshing: a cube meshed at 1e-4 of its size would take hours
  std::string huge = kCube;
  huge.replace(huge.find("max_size = \"0.5 mm\""), 20, "max_size = \"0.1 um\"");
  test::write_text(dir / "huge.toml", huge);
  for (const char* bad : {"--physics thermal --fix cube.top=-1K", "--physics thermal --power cube=1m",
                          "--physics thermal --convect cube.top=1,2m", "--physics thermoelastic --dT 1m",
                          "--physics thermoelastic --temperature-from-thermal --tref -1"}) {
    EXPECT_EQ(
        test::run("timeout 60 '" + test::cli_path() + "' solve '" + (dir / "huge.toml").string() + "' " + bad,
                  dir / "huge.txt"),
        2)
        << bad << "\n"
        << test::read_text(dir / "huge.txt");
  }
  const Result v = solve(dir, "--physics thermoelastic --dT 5V");
  EXPECT_EQ(v.rc, 2) << v.out;
  EXPECT_NE(v.out.find("--dT"), std::string::npos) << v.out;
  const Result e = solve(dir, "--physics thermoelastic --dT 5 --E cube=100K");
  EXPECT_EQ(e.rc, 2) << e.out;
  EXPECT_NE(e.out.find("not Pa"), std::string::npos) << e.out;
}

TEST(SolveUnitsCli, TemperatureChangeIsADifference) {
  TempDir dir;
  test::write_text(dir / "cube.toml", kCube);
  const Result ten = solve(dir, "--physics thermoelastic --dT 10K");
  ASSERT_EQ(ten.rc, 0) << ten.out;
  const double u10 = number_after(ten.out, "max displacement");
  ASSERT_GT(u10, 0) << ten.out;
  for (const char* five : {"--dT 5degC", "--dT '5 degC'", "--dT 5K", "--dT 5"}) {
    const Result r = solve(dir, std::string("--physics thermoelastic ") + five);
    ASSERT_EQ(r.rc, 0) << five << "\n" << r.out;
    EXPECT_NEAR(number_after(r.out, "max displacement") / u10, 0.5, 1e-5) << five << "\n" << r.out;
  }
  const Result gpa = solve(dir, "--physics thermoelastic --dT 10K --E cube=100GPa --alpha 'cube=10 ppm/K'");
  ASSERT_EQ(gpa.rc, 0) << gpa.out;
  EXPECT_EQ(line(gpa.out, "max von Mises"), line(ten.out, "max von Mises"));
}

TEST(ModelWarningsCli, FloatingDieIsReportedByCheckAndSolve) {
  TempDir dir;
  const std::string model = std::string(kCube) + R"TOML([[parts]]
name = "die"
material = "m"
shape = "box"
origin = [0, 0, 2]
size = [1, 1, 0.5]
[[conditions]]
type = "convection"
surface = "die.top"
h = "10 W/(m^2*K)"
ambient = "25 degC"
[[loads]]
type = "power"
part = "die"
value = "0.1 W"
)TOML";
  test::write_text(dir / "cube.toml", model);
  ASSERT_EQ(test::run_cli("model check '" + (dir / "cube.toml").string() + "'", dir / "check.txt"), 0);
  const std::string check = test::read_text(dir / "check.txt");
  EXPECT_NE(check.find("warning: part 'die' touches no other part (0.5 mm^3"), std::string::npos) << check;
  // thermal is posed (the die's convection), stress is not: the die is held by nothing
  EXPECT_NE(check.find("physics thermal: ready"), std::string::npos) << check;
  EXPECT_NE(check.find("physics thermoelastic: not ready: thermoelastic: part 'die'"), std::string::npos)
      << check;
  EXPECT_NE(check.find("physics electrostatic: not ready: "), std::string::npos) << check;
  const Result r = solve(dir, "--physics thermal");
  EXPECT_EQ(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("foxi solve: warning: " + (dir / "cube.toml").string() +
                       ": part 'die' touches no other part"),
            std::string::npos)
      << r.out;
}

// A problem the solver cannot pose is bad input (exit 3), not a failure of the work (exit 1): the
// model has no conductor for electrostatics (refused by the model's conditions), and its mesh solved
// with a heat source but no fixed boundary is ill-posed (refused by the solver itself).
TEST(SolveUnitsCli, IllPosedProblemIsBadInput) {
  TempDir dir;
  test::write_text(dir / "cube.toml", kCube);
  const Result r = solve(dir, "--physics electrostatic");
  EXPECT_EQ(r.rc, 3) << r.out;
  EXPECT_NE(r.out.find("voltage or ground"), std::string::npos) << r.out;
  const std::string mesh = (dir / "cube.vtu").string();
  ASSERT_EQ(test::run_cli("mesh '" + (dir / "cube.toml").string() + "' -o '" + mesh + "'", dir / "mesh.txt"),
            0);
  EXPECT_EQ(test::run_cli("solve '" + mesh + "' --k 1=1 --power 1=1W", dir / "ill.txt"), 3);
  const std::string ill = test::read_text(dir / "ill.txt");
  EXPECT_NE(ill.find("error: ill-posed thermal problem"), std::string::npos) << ill;
  EXPECT_EQ(test::run_cli("solve '" + mesh + "' --k 1=1 --power 1=1W --fix 1=300K", dir / "ok.txt"), 0)
      << test::read_text(dir / "ok.txt");
}

}  // namespace
