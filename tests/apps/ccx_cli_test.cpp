// foxi solve MODEL --with ccx and foxi export-ccx, end to end: ccx's temperatures (and displacements,
// nodal stresses) come back on foxi's mesh and agree with foxi's own solve (recomputed here from the written
// fields, not taken from the printout); a failing ccx (a stand-in script) or a missing one exits 1 with ccx's
// own text and the work folder kept; --solver with --with ccx is a usage error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "foxi/model/mesh_io.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

// The largest |a - b| over the largest |a|, and the latter.
std::pair<double, double> relative_difference(const Field& a, const Field& b) {
  double diff = 0, hi = 0;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    diff = std::max(diff, std::abs(a.values[i] - b.values[i]));
    hi = std::max(hi, std::abs(a.values[i]));
  }
  return {diff / hi, hi};
}

class CcxCli : public ::testing::Test {
 protected:
  // The records of foxi solve --json by foxi (a) and by ccx (b) hold the same names, units and key
  // marks, and every value agrees to 1e-6 (python3 reads them): relative to the value itself, the
  // heats (W) relative to the heat that flows and the stresses (Pa) relative to the largest von
  // Mises stress (both derivatives of ccx's float32 binary .frd: its rounding of T or u, amplified by
  // k / h or E / h, shows there first; the ASCII .frd's 6 digits needed 1e-5). Not compared: where a maximum
  // sits (the nearly isothermal die has ties at ccx's precision) and the linear solver's own figures.
  void compare_records(const std::filesystem::path& a, const std::filesystem::path& b, const char* physics) {
    test::write_text(dir_ / "cmp.py", R"(import json, sys
a = json.load(open(sys.argv[1])); b = json.load(open(sys.argv[2]))
assert b["solver"] == "ccx" and b["status"] == "ok" and a["physics"] == b["physics"] == sys.argv[3], b
av = {v["name"]: v for v in a["values"]}; bv = {v["name"]: v for v in b["values"]}
assert set(av) == set(bv), set(av) ^ set(bv)
strip = lambda texts: [t for t in texts if t["name"] != "T_max_region"]
assert strip(a["texts"]) == strip(b["texts"]), (a["texts"], b["texts"])
assert [c["name"] for c in a["checks"]] == [c["name"] for c in b["checks"]] and all(c["passed"] for c in b["checks"])
scales = {"W": av.get("heat_flow", {}).get("value"), "Pa": av.get("von_mises_max", {}).get("value")}
worst = 0
for n, v in av.items():
    if n.startswith("T_max_") or n in ("nonzeros", "unknowns", "iterations", "relative_residual"): continue
    assert v["unit"] == bv[n]["unit"] and v["key"] == bv[n]["key"], n
    x, y = v["value"], bv[n]["value"]
    scale = scales.get(v["unit"]) or max(abs(x), 1e-300)
    worst = max(worst, abs(x - y) / scale)
    assert abs(x - y) <= 1e-6 * scale, (n, x, y)
print("compared", len(av), "values, worst", worst)
)");
    ASSERT_EQ(test::run("/usr/bin/python3 '" + (dir_ / "cmp.py").string() + "' '" + a.string() + "' '" +
                            b.string() + "' " + physics,
                        dir_ / "cmp.txt"),
              0)
        << test::read_text(dir_ / "cmp.txt");
    EXPECT_NE(test::read_text(dir_ / "cmp.txt").find("compared"), std::string::npos);
  }
  int foxi(const std::string& args, std::string* out = nullptr, const std::string& env = "") {
    const int status = test::run(env + "'" + test::cli_path() + "' " + args, dir_ / "log.txt");
    if (out) *out = test::read_text(dir_ / "log.txt");
    return status;
  }
  std::string model() const { return "'" + test::models_dir() + "die_on_substrate.toml'"; }
  test::TempDir dir_;
};

TEST_F(CcxCli, SolveWithCcxAgreesWithFoxi) {
  if (!test::have_program("ccx")) GTEST_SKIP() << "ccx not installed";
  std::string log;
  const std::string out = (dir_ / "out.vtu").string();
  ASSERT_EQ(foxi("solve " + model() + " --physics thermal --with ccx --compare -o '" + out + "'", &log), 0)
      << log;
  EXPECT_NE(log.find("agree to ccx's output precision"), std::string::npos) << log;
  const Mesh m = read_mesh(out);
  const Field* ccx = m.find_field("temperature");
  const Field* own = m.find_field("temperature_foxi");
  ASSERT_NE(ccx, nullptr);
  ASSERT_NE(own, nullptr);
  EXPECT_EQ(ccx->unit, "K");
  const auto [rel, hi] = relative_difference(*ccx, *own);
  EXPECT_GT(hi, 310);  // heated above the 300 K it is held at
  EXPECT_LT(rel, 1e-5);
  char max_text[64];
  std::snprintf(max_text, sizeof max_text, "max temperature %.6g K", hi);
  EXPECT_NE(log.find(max_text), std::string::npos) << log;
}

// The same conditions on a mesh file, solved by foxi and by ccx: the same report lines and the same
// --json record (parsed by python3), every value to ccx's precision (heats relative to the heat that
// flows), apart from where the nearly isothermal die's maximum sits and the solver's own figures.
TEST_F(CcxCli, MeshWithCliConditionsGivesFoxisReport) {
  if (!test::have_program("ccx") || !test::have_program("/usr/bin/python3"))
    GTEST_SKIP() << "ccx or python3 missing";
  std::string log, ccx_log;
  const std::string mesh = (dir_ / "d.vtu").string();
  ASSERT_EQ(foxi("mesh " + model() + " -o '" + mesh + "'", &log), 0) << log;
  const std::string conditions =
      " --fix substrate.bottom=300K --flux die.top=2000 --power die=0.3W --k substrate=0.5";
  ASSERT_EQ(foxi("solve '" + mesh + "'" + conditions + " --json '" + (dir_ / "a.json").string() + "'", &log),
            0)
      << log;
  ASSERT_EQ(
      foxi("solve '" + mesh + "' --with ccx" + conditions + " --json '" + (dir_ / "b.json").string() + "'",
           &ccx_log),
      0)
      << ccx_log;
  for (const char* line :
       {"max temperature ", "\nregions ", "  2 (die)  ", "\nboundaries ", "  1 (substrate.bottom)   fixed",
        "  4 (die.top)            flux", "energy balance: sources 0.3 W", "check energy         ok"})
    EXPECT_NE(ccx_log.find(line), std::string::npos) << line << "\n" << ccx_log;
  compare_records(dir_ / "a.json", dir_ / "b.json", "thermal");
  // Without a --fix or --convect ccx is not run: a usage error; a thermoelastic mesh needs a model.
  EXPECT_EQ(foxi("solve '" + mesh + "' --with ccx --power die=1W", &log), 2) << log;
  EXPECT_EQ(foxi("solve '" + mesh + "' --with ccx --physics thermoelastic", &log), 2) << log;
  EXPECT_EQ(foxi("solve '" + mesh + "' --with ccx --fix nowhere=300", &log), 2) << log;
}

// ccx's temperatures that do not balance the heat foxi puts in (a stand-in ccx that lowers the
// deck's source before running the real one): the energy check fails, exit 4 with the figures.
TEST_F(CcxCli, UnbalancedCcxResultIsUnreliable) {
  if (!test::have_program("ccx")) GTEST_SKIP() << "ccx not installed";
  std::string real;
  ASSERT_EQ(test::run("command -v ccx > '" + (dir_ / "which.txt").string() + "'"), 0);
  real = test::read_text(dir_ / "which.txt");
  real.erase(real.find_last_not_of("\n") + 1);
  const std::filesystem::path bin = dir_ / "bin";
  std::filesystem::create_directories(bin);
  test::write_text(bin / "ccx",
                   "#!/bin/sh\nsed -i 's/, BF, .*/, BF, 4e7/' \"$2.inp\"\nexec '" + real + "' \"$@\"\n");
  std::filesystem::permissions(bin / "ccx", std::filesystem::perms::owner_all);
  std::string log;
  const std::string json = (dir_ / "u.json").string();
  EXPECT_EQ(foxi("solve " + model() + " --with ccx --json '" + json + "'", &log,
                 "PATH='" + bin.string() + "':\"$PATH\" "),
            4)
      << log;
  EXPECT_NE(log.find("check energy         FAIL"), std::string::npos) << log;
  EXPECT_NE(log.find("UNRELIABLE"), std::string::npos) << log;
  EXPECT_NE(test::read_text(json).find("\"status\": \"unreliable\""), std::string::npos)
      << test::read_text(json);
}

// On a terminal (script(1) gives it one) ccx's progress shows as it runs.
TEST_F(CcxCli, ProgressOnATerminal) {
  if (!test::have_program("ccx") || !test::have_program("script"))
    GTEST_SKIP() << "ccx or script not installed";
  const int rc =
      test::run("script -qec \"'" + test::cli_path() + "' solve " + model() + " --with ccx\" /dev/null",
                dir_ / "tty.txt");
  const std::string log = test::read_text(dir_ / "tty.txt");
  ASSERT_EQ(rc, 0) << log;
  EXPECT_NE(log.find("ccx: iteration 1"), std::string::npos) << log;
  EXPECT_NE(log.find("ccx: Job finished"), std::string::npos) << log;
  // Not on a pipe or file: the printout stays as it was.
  std::string plain;
  ASSERT_EQ(foxi("solve " + model() + " --with ccx", &plain), 0) << plain;
  EXPECT_EQ(plain.find("ccx: iteration"), std::string::npos) << plain;
}

TEST_F(CcxCli, ThermoelasticWithCcxAgreesWithFoxiAndRenders) {
  if (!test::have_program("ccx")) GTEST_SKIP() << "ccx not installed";
  std::string log;
  const std::string out = (dir_ / "s.vtu").string();
  ASSERT_EQ(
      foxi("solve " + model() +
               " --physics thermoelastic --with ccx --temperature-from-thermal --compare -o '" + out + "'",
           &log),
      0)
      << log;
  const Mesh m = read_mesh(out);
  const Field* u = m.find_field("displacement");
  const Field* own = m.find_field("displacement_foxi");
  const Field* s = m.find_field("stress_nodal");
  ASSERT_TRUE(u && own && s && m.find_field("temperature"));
  EXPECT_EQ(u->components, 3u);
  EXPECT_EQ(s->components, 6u);
  const auto [rel, hi] = relative_difference(*u, *own);
  EXPECT_GT(hi, 1e-8);
  EXPECT_LT(rel, 1e-5);
  const std::string png = (dir_ / "s.png").string();
  ASSERT_EQ(foxi("render '" + out + "' --field stress_nodal --size 480x320 -o '" + png + "'", &log), 0)
      << log;
  EXPECT_TRUE(std::filesystem::exists(png));
}

// The model's thermal stress by foxi and by ccx: the same report lines and record (von Mises per
// region and interface from ccx's displacements).
TEST_F(CcxCli, ThermoelasticWithCcxGivesFoxisReport) {
  if (!test::have_program("ccx") || !test::have_program("/usr/bin/python3"))
    GTEST_SKIP() << "ccx or python3 missing";
  std::string log;
  ASSERT_EQ(
      foxi("solve " + model() + " --physics thermoelastic --json '" + (dir_ / "a.json").string() + "'", &log),
      0)
      << log;
  ASSERT_EQ(foxi("solve " + model() + " --physics thermoelastic --with ccx --json '" +
                     (dir_ / "b.json").string() + "'",
                 &log),
            0)
      << log;
  for (const char* line :
       {"linear thermoelasticity by ccx (C3D4)", "\nmax von Mises stress ", "\nmax displacement ",
        "\nregions:\n  1 (substrate)        E 2.2e+10", "material interfaces (tets touching them):"})
    EXPECT_NE(log.find(line), std::string::npos) << line << "\n" << log;
  compare_records(dir_ / "a.json", dir_ / "b.json", "thermoelastic");
}

// C3D10: the deck's mid-edge nodes are dropped on reading; the corners' displacements agree with
// foxi's P2 solve.
TEST_F(CcxCli, QuadraticThermoelasticWithCcxAgreesWithFoxi) {
  if (!test::have_program("ccx")) GTEST_SKIP() << "ccx not installed";
  std::string log;
  const std::string out = (dir_ / "q.vtu").string();
  ASSERT_EQ(
      foxi("solve " + model() + " --physics thermoelastic --with ccx --order 2 --compare -o '" + out + "'",
           &log),
      0)
      << log;
  EXPECT_NE(log.find("linear thermoelasticity by ccx (C3D10)"), std::string::npos) << log;
  EXPECT_NE(log.find("\nmax von Mises stress "), std::string::npos) << log;  // from the mid-edge nodes too
  const Mesh m = read_mesh(out);
  const Field* u = m.find_field("displacement");
  const Field* own = m.find_field("displacement_foxi");
  ASSERT_TRUE(u && own);
  ASSERT_EQ(u->values.size(), 3 * m.node_count());
  const auto [rel, hi] = relative_difference(*u, *own);
  EXPECT_GT(hi, 1e-8);
  EXPECT_LT(rel, 1e-5);
}

// Ctrl-C while ccx runs: exit 130, ccx killed, the work folder (under TMPDIR) removed, no output.
TEST_F(CcxCli, InterruptStopsCcxAndRemovesTheWorkFolder) {
  if (!test::have_program("ccx")) GTEST_SKIP() << "ccx not installed";
  const auto tmp = dir_ / "tmp";
  std::filesystem::create_directories(tmp);
  test::write_text(dir_ / "stop.sh", "TMPDIR='" + tmp.string() + "' '" + test::cli_path() + "' solve " +
                                         model() + " --physics thermoelastic --with ccx --order 2 -o '" +
                                         (dir_ / "never.vtu").string() +
                                         "' &\npid=$!\n"
                                         "for i in $(seq 600); do ls '" +
                                         tmp.string() +
                                         "'/*/stress.inp > /dev/null 2>&1 && break; sleep 0.05; done\n"
                                         "sleep 0.5\nkill -INT $pid\nwait $pid\necho $?\n");
  ASSERT_EQ(test::run("bash '" + (dir_ / "stop.sh").string() + "'", dir_ / "stop.log"), 0);
  const std::string log = test::read_text(dir_ / "stop.log");
  EXPECT_NE(log.find("stopped by SIGINT"), std::string::npos) << log;
  EXPECT_NE(log.find("\n130\n"), std::string::npos) << log;
  EXPECT_TRUE(std::filesystem::is_empty(tmp)) << log;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "never.vtu"));
}

TEST_F(CcxCli, ExportWritesTheDeck) {
  std::string log;
  const std::string deck = (dir_ / "deck.inp").string();
  ASSERT_EQ(foxi("export-ccx " + model() + " -o '" + deck + "'", &log), 0) << log;
  const std::string text = test::read_text(deck);
  EXPECT_NE(text.find("*NODE"), std::string::npos);
  EXPECT_NE(text.find("*FILM"), std::string::npos);
  EXPECT_NE(text.find("*END STEP"), std::string::npos);
  if (!test::have_program("ccx")) return;
  // ccx runs the exported deck as it is.
  ASSERT_EQ(test::run("cd '" + dir_.path().string() + "' && OMP_NUM_THREADS=1 ccx -i deck", dir_ / "ccx.log"),
            0);
  EXPECT_TRUE(std::filesystem::exists(dir_ / "deck.frd"));
  // The thermal-stress deck too: ccx runs it and writes displacements and stresses.
  const std::string stress = (dir_ / "stress.inp").string();
  ASSERT_EQ(foxi("export-ccx " + model() + " --physics thermoelastic -o '" + stress + "'", &log), 0) << log;
  EXPECT_NE(test::read_text(stress).find("*EXPANSION"), std::string::npos);
  ASSERT_EQ(
      test::run("cd '" + dir_.path().string() + "' && OMP_NUM_THREADS=1 ccx -i stress", dir_ / "ccx.log"), 0);
  const std::string frd = test::read_text(dir_ / "stress.frd");
  EXPECT_NE(frd.find("DISP"), std::string::npos);
  EXPECT_NE(frd.find("STRESS"), std::string::npos);
  EXPECT_EQ(foxi("export-ccx " + model() + " --order 2 -o '" + stress + "'", &log), 2);
}

// A .frd that cannot be read (a stand-in ccx leaves a truncated or a mutated copy of a real one) is
// bad input: exit 3, the message naming the file, its line and the reason; the work folder is kept.
TEST_F(CcxCli, MalformedFrdExitsThreeNamingFileAndLine) {
  const std::filesystem::path bin = dir_ / "bin";
  std::filesystem::create_directories(bin);
  test::write_text(bin / "ccx", "#!/bin/sh\ncp '" + (dir_ / "bad.frd").string() + "' heat.frd\n");
  std::filesystem::permissions(bin / "ccx", std::filesystem::perms::owner_all);
  const std::string frd = test::read_text(test::data_dir() + "/fields/ccx_two_steps.frd");
  // The first node record's x coordinate (columns 14-25) made a word.
  std::string mutated = frd;
  const std::size_t node = mutated.find("\n -1", mutated.find("    2C"));
  ASSERT_NE(node, std::string::npos);
  mutated.replace(node + 14, 12, "  not-a-num ");
  const std::size_t mutated_line =
      static_cast<std::size_t>(std::count(frd.begin(), frd.begin() + node, '\n')) + 2;
  const std::pair<std::string, std::string> cases[] = {
      {frd.substr(0, frd.size() / 2), "expected"},  // cut inside a record: the reader says what it expected
      {mutated, "heat.frd:" + std::to_string(mutated_line) + ":"}};
  for (const auto& [text, what] : cases) {
    test::write_text(dir_ / "bad.frd", text);
    std::string log;
    EXPECT_EQ(foxi("solve " + model() + " --with ccx", &log, "PATH='" + bin.string() + "':\"$PATH\" "), 3)
        << log;
    EXPECT_NE(log.find("ccx's results cannot be read"), std::string::npos) << log;
    EXPECT_NE(log.find("heat.frd:"), std::string::npos) << log;  // the file and its line
    EXPECT_NE(log.find(what), std::string::npos) << log;
    const std::size_t at = log.find("kept in ");
    ASSERT_NE(at, std::string::npos) << log;
    const std::string kept = log.substr(at + 8, log.find('\n', at) - at - 8);
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(kept) / "heat.frd")) << kept;
    std::filesystem::remove_all(kept);
  }
}

TEST_F(CcxCli, FailingOrMissingCcxExitsOneWithItsText) {
  std::string log;
  const std::filesystem::path bin = dir_ / "bin";
  std::filesystem::create_directories(bin);
  test::write_text(bin / "ccx",
                   "#!/bin/sh\necho ' *ERROR reading *NODE: something ccx-specific'\nexit 201\n");
  std::filesystem::permissions(bin / "ccx", std::filesystem::perms::owner_all);
  const std::string out = (dir_ / "never.vtu").string();
  EXPECT_EQ(foxi("solve " + model() + " --with ccx -o '" + out + "'", &log,
                 "PATH='" + bin.string() + "':\"$PATH\" "),
            1);
  EXPECT_NE(log.find("something ccx-specific"), std::string::npos) << log;
  const std::size_t at = log.find("kept in ");
  ASSERT_NE(at, std::string::npos) << log;
  const std::string kept = log.substr(at + 8, log.find('\n', at) - at - 8);
  EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(kept) / "heat.inp")) << kept;
  std::filesystem::remove_all(kept);
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove(bin / "ccx");
  EXPECT_EQ(foxi("solve " + model() + " --with ccx", &log, "PATH='" + bin.string() + "' "), 1);
  EXPECT_NE(log.find("ccx (CalculiX) is not installed"), std::string::npos) << log;
  EXPECT_EQ(foxi("solve " + model() + " --with ccx --solver direct", &log), 2);
  EXPECT_EQ(foxi("solve " + model() + " --with abaqus", &log), 2);
  EXPECT_EQ(foxi("solve " + model() + " --physics thermal --with ccx --order 2", &log), 2);
}

}  // namespace
}  // namespace foxi
