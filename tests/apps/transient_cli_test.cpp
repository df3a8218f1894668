// foxi solve MODEL --physics transient: the written series read back by other programs (the .pvd
// parsed as XML by Python, each .vtu by meshio), the CSV's junction temperature against the last
// step's field, Zth(t) rising from 0, the energy check in the JSON, and bad input refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "foxi/viz/png.hpp"

#include "test_util.hpp"

namespace foxi {
namespace {

constexpr int kUsage = 2, kBadInput = 3;  // apps/foxi/exit_codes.hpp

// A 10 mm cube of rho c 1e6 J/(m^3 K) (C = 1 J/K), k 1e4 (nearly isothermal: Biot 1e-4), 0.6 W,
// cooled by h = 100 W/(m^2 K) on its six sides to 300 K: R = 1 / (h A) = 16.67 K/W, tau = R C.
const std::string kCube = R"TOML(units.length = "mm"
[parameters]
size = "2.5 mm"
[materials.m]
thermal_conductivity = 1e4
density = 1000.0
specific_heat = 1000.0
[[parts]]
name = "blk"
material = "m"
shape = "box"
origin = [0, 0, 0]
size = [10, 10, 10]
[[conditions]]
type = "convection"
surface = ["blk.top", "blk.bottom", "blk.side"]
h = "100 W/(m^2*K)"
ambient = "300 K"
[[loads]]
type = "power"
part = "blk"
value = "0.6 W"
[mesh]
max_size = "size"
)TOML";

TEST(TransientCli, DieOnSubstrateSeriesReadsBackInMeshio) {
  if (test::run("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") != 0) GTEST_SKIP() << "no meshio";
  test::TempDir dir;
  const std::string out = (dir / "run.pvd").string();
  const int status = test::run_cli("solve " + test::models_dir() +
                                       "die_on_substrate.toml --physics transient --time 2s "
                                       "--steps 20 --write-every 5 -o " +
                                       out + " --json " + (dir / "r.json").string(),
                                   dir / "solve.log");
  ASSERT_EQ(status, 0) << test::read_text(dir / "solve.log");
  const std::string script = R"PY(
import csv, json, sys, xml.etree.ElementTree as ET, os
import meshio
d = sys.argv[1]
sets = ET.parse(os.path.join(d, 'run.pvd')).getroot().find('Collection').findall('DataSet')
times = [float(s.get('timestep')) for s in sets]
assert len(sets) == 5, len(sets)
assert all(abs(t - 0.5 * i) < 1e-12 for i, t in enumerate(times)), times
rows = list(csv.reader(open(os.path.join(d, 'run_junction.csv'))))
head, rows = rows[0], [[float(x) for x in r] for r in rows[1:]]
assert len(rows) == 21, len(rows)
tj, zth = head.index('Tj[die]_K'), head.index('Zth[die]_K/W')
last = meshio.read(os.path.join(d, sets[-1].get('file')))
tmax = float(last.point_data['temperature'].max())
assert abs(tmax - rows[-1][tj]) <= 1e-6 * tmax, (tmax, rows[-1][tj])
first = meshio.read(os.path.join(d, sets[0].get('file')))
assert abs(float(first.point_data['temperature'].max()) - 300) < 1e-6
z = [r[zth] for r in rows]
assert z[0] == 0 and all(b > a for a, b in zip(z, z[1:])), z
assert abs(z[-1] - (rows[-1][tj] - 300) / 0.5) < 1e-6 * z[-1]
j = json.load(open(os.path.join(d, 'r.json')))
assert j['status'] == 'ok' and j['physics'] == 'transient', j['status']
assert any(c['name'] == 'energy' and c['passed'] for c in j['checks'])
print('ok', z[-1])
)PY";
  test::write_text(dir / "check.py", script);
  ASSERT_EQ(test::run("/usr/bin/python3 " + (dir / "check.py").string() + " " + dir.path().string(),
                      dir / "py.log"),
            0)
      << test::read_text(dir / "py.log");
}

TEST(TransientCli, BadPowerTableRowIsNamedWithFileAndLine) {
  test::TempDir dir;
  test::write_text(dir / "p.csv", "time_s,power_W\n0,1\n0.5,oops\n");
  const int status = test::run_cli("solve " + test::models_dir() +
                                       "die_on_substrate.toml --physics transient --time 1s "
                                       "--steps 4 --power die=table:" +
                                       (dir / "p.csv").string() + " -o " + (dir / "r.pvd").string(),
                                   dir / "log");
  EXPECT_EQ(status, kBadInput);
  const std::string log = test::read_text(dir / "log");
  EXPECT_NE(log.find("p.csv:3"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(dir / "r.pvd"));
}

TEST(TransientCli, MissingTimeIsAUsageError) {
  test::TempDir dir;
  EXPECT_EQ(
      test::run_cli("solve " + test::models_dir() +
                        "die_on_substrate.toml --physics transient --steps 4 -o " + (dir / "r.pvd").string(),
                    dir / "log"),
      kUsage);
}

// The charts and the structure function: OUT_zth.png two charts high, OUT_structure.csv whose
// cumulative sums add up its stages and whose total resistance is the Zth at the end of the CSV
// (the run reaches the steady state) to 1 %; a pulse gets no Zth, no structure function and says so.
TEST(TransientCli, ZthChartAndStructureFunction) {
  test::TempDir dir;
  const std::string out = (dir / "run.pvd").string();
  ASSERT_EQ(test::run_cli("solve " + test::models_dir() +
                              "die_on_substrate.toml --physics transient --time 100s "
                              "--steps 200 --write-every 200 -o " +
                              out,
                          dir / "solve.log"),
            0)
      << test::read_text(dir / "solve.log");
  const Framebuffer png = read_png(dir / "run_zth.png");
  EXPECT_EQ(png.height, 2 * 440);
  std::istringstream junction(test::read_text(dir / "run_junction.csv")),
      structure(test::read_text(dir / "run_structure.csv"));
  std::string line, last;
  std::getline(junction, line);
  EXPECT_EQ(line, "time_s,power_W,Tj[die]_K,Zth[die]_K/W");
  while (std::getline(junction, line)) last = line;
  const double zth_end = std::stod(last.substr(last.rfind(',') + 1));
  std::getline(structure, line);
  EXPECT_EQ(line, "stage,R_K/W,C_J/K,cumulative_R_K/W,cumulative_C_J/K");
  double sum_r = 0, sum_c = 0;
  int stages = 0;
  while (std::getline(structure, line)) {
    double v[5];
    std::istringstream row(line);
    for (double& x : v) {
      std::string field;
      std::getline(row, field, ',');
      x = std::stod(field);
    }
    EXPECT_EQ(v[0], ++stages);
    EXPECT_GT(v[1], 0);
    EXPECT_GT(v[2], 0);
    sum_r += v[1], sum_c += v[2];
    EXPECT_NEAR(v[3], sum_r, 1e-6 * sum_r);
    EXPECT_NEAR(v[4], sum_c, 1e-6 * sum_c);
  }
  EXPECT_GE(stages, 2);
  EXPECT_NEAR(sum_r, zth_end, 0.01 * zth_end);
  const std::string log = test::read_text(dir / "solve.log");
  EXPECT_NE(log.find("Foster fit error"), std::string::npos) << log;

  ASSERT_EQ(test::run_cli("solve " + test::models_dir() +
                              "die_on_substrate.toml --physics transient --time 4s "
                              "--steps 8 --power die=pulse:1W,1s,2s -o " +
                              (dir / "p.pvd").string(),
                          dir / "pulse.log"),
            0)
      << test::read_text(dir / "pulse.log");
  const std::string plog = test::read_text(dir / "pulse.log");
  EXPECT_NE(
      plog.find("Zth(t) of die: not computed: Zth is defined for a step of power, and its power is a pulse"),
      std::string::npos)
      << plog;
  EXPECT_TRUE(std::filesystem::exists(dir / "p_tj.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "p_zth.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "p_structure.csv"));
  // 10 BDF2 steps of 2 s overshoot (the die's Zth peaks at 16 s, then falls): no sum of rising
  // exponentials fits that within 1 %, so no structure function, and a line says why; the run is ok.
  // Backward Euler's 10 steps do not overshoot, and the structure function is written.
  ASSERT_EQ(test::run_cli("solve " + test::models_dir() +
                              "die_on_substrate.toml --physics transient --time 20s "
                              "--steps 10 -o " +
                              (dir / "c.pvd").string(),
                          dir / "coarse.log"),
            0)
      << test::read_text(dir / "coarse.log");
  const std::string clog = test::read_text(dir / "coarse.log");
  EXPECT_NE(clog.find("not written: the Foster fit misses Zth(t)"), std::string::npos) << clog;
  EXPECT_NE(clog.find("which a step response does not"), std::string::npos) << clog;
  EXPECT_TRUE(std::filesystem::exists(dir / "c_zth.png"));
  ASSERT_EQ(test::run_cli("solve " + test::models_dir() +
                              "die_on_substrate.toml --physics transient --time 20s "
                              "--steps 10 --scheme euler -o " +
                              (dir / "e.pvd").string(),
                          dir / "euler.log"),
            0)
      << test::read_text(dir / "euler.log");
  EXPECT_TRUE(std::filesystem::exists(dir / "e_structure.csv")) << test::read_text(dir / "euler.log");
  EXPECT_FALSE(std::filesystem::exists(dir / "c_structure.csv"));
}

// Rerunning into one OUT.pvd (an outside probe): a shorter run left the old frames past its own, and
// a stopped run had deleted the old frames while their .pvd stayed. The frames are now written beside
// OUT and replace the old series when the run ends: after a shorter rerun only its own frames are
// there; a rerun stopped by SIGINT (status 130) leaves the series before it whole and no temporary.
TEST(TransientCli, RerunReplacesTheSeriesWholeAndAStopKeepsTheOneBefore) {
  test::TempDir dir;
  const std::string model = kCube;
  test::write_text(dir / "cube.toml", model);
  const std::string out = (dir / "run.pvd").string(), cube = (dir / "cube.toml").string();
  auto frames = [&] {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir.path()))
      if (e.path().extension() == ".vtu") names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  };
  auto temporaries = [&] {
    int n = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir.path()))
      n += e.path().filename().string().find(".foxi-tmp-") != std::string::npos;
    return n;
  };
  auto named = [&] {  // the files the .pvd names, each of which must exist
    const std::string pvd = test::read_text(dir / "run.pvd");
    std::vector<std::string> names;
    for (std::size_t at = pvd.find("file=\""); at != std::string::npos; at = pvd.find("file=\"", at + 1)) {
      const std::size_t from = at + 6;
      names.push_back(pvd.substr(from, pvd.find('"', from) - from));
    }
    std::sort(names.begin(), names.end());
    return names;
  };
  ASSERT_EQ(
      test::run_cli("solve " + cube + " --physics transient --time 100 --steps 20 --write-every 1 -o " + out,
                    dir / "a.log"),
      0)
      << test::read_text(dir / "a.log");
  EXPECT_EQ(frames().size(), 21u);
  ASSERT_EQ(
      test::run_cli("solve " + cube + " --physics transient --time 100 --steps 4 --write-every 1 -o " + out,
                    dir / "b.log"),
      0)
      << test::read_text(dir / "b.log");
  const std::vector<std::string> four = {"run_0000.vtu", "run_0001.vtu", "run_0002.vtu", "run_0003.vtu",
                                         "run_0004.vtu"};
  EXPECT_EQ(frames(), four);
  EXPECT_EQ(named(), four);
  // A long rerun on a finer mesh, stopped once its first frames are written.
  const std::string cmd =
      "timeout -s KILL 120 '" + test::cli_path() + "' solve '" + cube +
      "' --set size=0.5mm --physics transient --time 100 --steps 100000 --write-every 1 -o '" + out +
      "' > '" + (dir / "c.log").string() + "' 2>&1 & echo $! > '" + (dir / "pid").string() +
      "'; wait $!; echo $? > '" + (dir / "status").string() + "'";
  std::thread runner([&] { test::run(cmd); });
  bool writing = false;
  for (int i = 0; i < 1200 && !writing; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    for (const auto& e : std::filesystem::directory_iterator(dir.path()))
      if (e.path().filename().string().find(".foxi-tmp-") != std::string::npos && e.is_directory())
        for (const auto& f : std::filesystem::directory_iterator(e.path()))
          writing = writing || f.path().filename() == "run_0003.vtu";
  }
  EXPECT_TRUE(writing) << test::read_text(dir / "c.log");
  test::run("kill -INT " + test::read_text(dir / "pid"));
  runner.join();
  EXPECT_EQ(std::stoi(test::read_text(dir / "status")), 130) << test::read_text(dir / "c.log");
  EXPECT_EQ(frames(), four);
  EXPECT_EQ(named(), four);
  EXPECT_EQ(temporaries(), 0);
  // The companions go with the series: a pulse's run (no Zth) leaves no Zth chart or structure
  // function of the run before (they stayed beside the new series).
  ASSERT_TRUE(std::filesystem::exists(dir / "run_zth.png"));
  ASSERT_EQ(
      test::run_cli("solve " + cube + " --physics transient --time 100 --steps 4 --write-every 1 --power " +
                        "blk=pulse:1W,10,40 -o " + out,
                    dir / "d.log"),
      0)
      << test::read_text(dir / "d.log");
  EXPECT_TRUE(std::filesystem::exists(dir / "run_tj.png"));
  for (const char* gone : {"run_zth.png", "run_structure.csv", "run_structure.png"})
    EXPECT_FALSE(std::filesystem::exists(dir / gone)) << gone;
  // A folder where a new frame would go: refused before anything is replaced (it failed half-way,
  // leaving neither series), exit 1; the series before stays whole.
  std::filesystem::create_directory(dir / "run_0006.vtu");
  EXPECT_EQ(
      test::run_cli("solve " + cube + " --physics transient --time 100 --steps 8 --write-every 1 -o " + out,
                    dir / "e.log"),
      1)
      << test::read_text(dir / "e.log");
  EXPECT_NE(test::read_text(dir / "e.log").find("run_0006.vtu: is not a file"), std::string::npos)
      << test::read_text(dir / "e.log");
  EXPECT_EQ(named(), four);
  EXPECT_TRUE(std::filesystem::exists(dir / "run_tj.png"));
  EXPECT_EQ(temporaries(), 0);
}

// The structure function of the cube: one stage, C = 1 J/K at the junction, R = 16.67 K/W, when the
// steps resolve tau = 16.7 s. Over 1e6 s in 100 steps the discrete Zth has the stepping's time
// constants (1.3e3 s), which the fit followed within 0.07 %: C 92 J/K was printed at the junction of
// this 1 J/K body (an outside probe). Its first moment, sum R tau, is then 93 times the body's, sum m
// (dT / P)^2, and the structure function is not written.
TEST(TransientCli, StructureFunctionOfALumpedBodyAndStepsTooLongForIt) {
  test::TempDir dir;
  test::write_text(dir / "cube.toml", kCube);
  const std::string cube = (dir / "cube.toml").string();
  ASSERT_EQ(test::run_cli("solve " + cube + " --physics transient --time 200 --steps 400 --scheme euler -o " +
                              (dir / "fine.pvd").string(),
                          dir / "fine.log"),
            0)
      << test::read_text(dir / "fine.log");
  std::istringstream rows(test::read_text(dir / "fine_structure.csv"));
  std::string line;
  std::getline(rows, line);
  ASSERT_TRUE(std::getline(rows, line)) << test::read_text(dir / "fine.log");
  std::istringstream first(line);
  double v[5];
  for (double& x : v) {
    std::string field;
    std::getline(first, field, ',');
    x = std::stod(field);
  }
  EXPECT_NEAR(v[2], 1.0, 0.03) << line;  // C at the junction, J/K
  EXPECT_NEAR(v[1], 16.67, 0.03 * 16.67) << line;
  ASSERT_EQ(test::run_cli("solve " + cube + " --physics transient --time 1e6 --steps 100 -o " +
                              (dir / "long.pvd").string(),
                          dir / "long.log"),
            0)
      << test::read_text(dir / "long.log");
  const std::string log = test::read_text(dir / "long.log");
  EXPECT_NE(log.find("not written: the fit's first moment"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(dir / "long_structure.csv"));
}

}  // namespace
}  // namespace foxi
