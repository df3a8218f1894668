// foxi's thermal solver against CalculiX (ccx) on the same mesh and problem (P1 tets = C3D4): the
// nodal temperatures must agree to the precision of ccx's .frd (binary since the deck asks for
// *NODE OUTPUT: float32 values, about 6e-8 relative; the ASCII file's 6 digits gave 2e-6).
#include "foxi/solver/calculix.hpp"

#include <gtest/gtest.h>

#include <stdlib.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include "foxi/model/io_error.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/solver/results.hpp"
#include "foxi/solver/thermoelastic.hpp"
#include "layered_box.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

Mesh package_mesh(const test::TempDir& dir, const std::string& max_volume) {
  test::write_text(dir / "pkg.poly",
                   test::read_text(test::data_dir() + "/../../examples/die_on_substrate.poly"));
  if (test::run("tetgen -pq1.414AQa" + max_volume + " '" + (dir / "pkg.poly").string() + "'",
                dir / "tetgen.log") != 0)
    throw std::runtime_error("tetgen failed");
  Mesh m = read_tetgen(dir / "pkg.1");
  validate_and_repair(m);
  return m;
}

// Runs ccx on the deck written for (mesh, params); returns its NDTEMP per mesh node.
std::vector<double> ccx_temperatures(const test::TempDir& dir, const Mesh& mesh,
                                     const ThermalParams& params) {
  write_calculix_thermal(mesh, params, dir / "heat.inp");
  const int rc =
      test::run("cd '" + dir.path().string() + "' && OMP_NUM_THREADS=1 ccx -i heat", dir / "ccx.log");
  EXPECT_EQ(rc, 0) << test::read_text(dir / "ccx.log");
  std::vector<double> t(mesh.node_count(), std::nan(""));
  for (const FrdBlock& b : read_frd(dir / "heat.frd")) {
    if (b.name != "NDTEMP") continue;
    EXPECT_EQ(b.components, 1u);
    for (std::size_t i = 0; i < b.node.size(); ++i)
      if (b.node[i] >= 1 && b.node[i] <= t.size()) t[b.node[i] - 1] = b.values[i];
  }
  return t;
}

// A micrometre model's tets (6 V below 1e-20 m^3) made ccx stop with "nonpositive jacobian
// determinant" (an outside probe, trench.toml): the deck writers refuse them, naming the smallest;
// the same mesh in millimetres is written.
TEST(CalculixDeck, TetsTooSmallForCcxAreRefused) {
  if (!test::have_program("tetgen")) GTEST_SKIP() << "tetgen not installed";
  test::TempDir dir;
  Mesh tiny = test::layered_box_mesh(2e-6, 2e-6, {0, 1e-6}, 1e-20);
  ThermalParams p;
  p.conductivity = {{1, 1.0}};
  p.fixed = {{5, 300}};
  try {
    write_calculix_thermal(tiny, p, dir / "t.inp");
    ADD_FAILURE() << "written";
  } catch (const SolverInputError& e) {
    EXPECT_NE(std::string(e.what()).find("ccx refuses elements whose Jacobian determinant"),
              std::string::npos)
        << e.what();
  }
  Mesh mm = tiny;
  for (double& x : mm.xyz) x *= 1e3;
  write_calculix_thermal(mm, p, dir / "mm.inp");
  EXPECT_TRUE(std::filesystem::exists(dir / "mm.inp"));
}

class CalculixTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::have_program("tetgen") || !test::have_program("ccx"))
      GTEST_SKIP() << "tetgen or ccx not installed";
  }
};

// Every kind of condition at once: fixed bottom, convection on the tops, a flux into the substrate
// sides, a heat source in the die. ccx integrates *FILM at the face centroid; with the same rule foxi
// must reproduce ccx to its float32 output. With foxi's exact (consistent) rule the two differ by
// the quadrature of h T on the convective faces only, which is small but well above the print
// precision here (the exact rule is the one the analytic Robin test checks).
TEST_F(CalculixTest, PackageTemperaturesAgreeWithCcx) {
  test::TempDir dir;
  Mesh m = package_mesh(dir, "4e-11");
  ThermalParams p;
  p.conductivity = {{1, 0.3}, {2, 148}};
  p.fixed = {{1, 300}};
  p.convection = {{3, 10, 310}, {6, 25, 290}};
  p.flux = {{2, 150}};
  p.sources = {{2, 0.5, true}};
  const std::vector<double> ccx = ccx_temperatures(dir, m, p);
  ASSERT_EQ(ccx.size(), m.node_count());
  for (std::size_t v = 0; v < m.node_count(); ++v)
    ASSERT_FALSE(std::isnan(ccx[v])) << "no ccx value, node " << v + 1;
  auto worst_difference = [&] {
    const std::vector<double>& t = m.find_field("temperature")->values;
    double worst = 0;
    for (std::size_t v = 0; v < m.node_count(); ++v)
      worst = std::max(worst, std::abs(t[v] - ccx[v]) / std::abs(ccx[v]));
    return worst;
  };
  p.convection_centroid_rule = true;
  const ThermalReport r = solve_thermal(m, p);
  const double same_rule = worst_difference();
  p.convection_centroid_rule = false;
  solve_thermal(m, p);
  const double exact_rule = worst_difference();
  std::printf(
      "%zu nodes, max T %.6g K; max relative difference to ccx: %.3g (centroid film rule), %.3g (exact)\n",
      m.node_count(), r.max_temperature, same_rule, exact_rule);
  EXPECT_LT(same_rule, 1e-6);  // ccx's binary .frd: float32 values (ASCII's 6 digits gave about 2e-6)
  EXPECT_LT(exact_rule, 1e-3);
  EXPECT_GT(r.max_temperature - 300, 10.0);  // a problem with a real temperature rise
}

// The nodal block `name` of ccx's .frd per mesh node (NaN where ccx gave none), `components` each.
std::vector<double> frd_nodal(const std::filesystem::path& frd, const std::string& name,
                              std::uint32_t components, std::size_t nodes) {
  std::vector<double> out(components * nodes, std::nan(""));
  for (const FrdBlock& b : read_frd(frd)) {
    if (b.name != name) continue;
    EXPECT_GE(b.components, components);
    for (std::size_t i = 0; i < b.node.size(); ++i)
      if (b.node[i] >= 1 && b.node[i] <= nodes)
        for (std::uint32_t c = 0; c < components; ++c)
          out[(b.node[i] - 1) * components + c] = b.values[i * b.components + c];
  }
  return out;
}

// Runs foxi and ccx on the same thermal-stress problem; returns the largest differences of the nodal
// displacements (relative to the largest |u|) and of the nodal stresses (relative to the largest von
// Mises stress). ccx writes C3D4 stresses at the nodes as the mean over the elements around each
// node, so foxi's constant tet stresses are averaged the same way.
std::pair<double, double> thermal_stress_difference(const test::TempDir& dir, Mesh& m,
                                                    const ThermoelasticParams& p) {
  const ThermoelasticReport r = solve_thermoelastic(m, p);
  write_calculix_thermoelastic(m, p, dir / "stress.inp");
  const int rc =
      test::run("cd '" + dir.path().string() + "' && OMP_NUM_THREADS=1 ccx -i stress", dir / "ccx.log");
  EXPECT_EQ(rc, 0) << test::read_text(dir / "ccx.log");
  const std::size_t nn = m.node_count();
  const std::vector<double> u_ccx = frd_nodal(dir / "stress.frd", "DISP", 3, nn);
  const std::vector<double> s_ccx = frd_nodal(dir / "stress.frd", "STRESS", 6, nn);
  const std::vector<double>& u = m.find_field("displacement")->values;
  const std::vector<double>& s = m.find_field("stress")->values;
  std::vector<double> s_node(6 * nn, 0.0), count(nn, 0.0);
  for (std::size_t t = 0; t < m.tet_count(); ++t)
    for (int a = 0; a < 4; ++a) {
      const std::uint32_t v = m.tet[4 * t + a];
      count[v] += 1;
      for (int c = 0; c < 6; ++c) s_node[6 * v + c] += s[6 * t + c];
    }
  double u_worst = 0, s_worst = 0;
  for (std::size_t v = 0; v < nn; ++v) {
    for (int c = 0; c < 3; ++c)  // a missing value (NaN) counts as a total mismatch
      u_worst = std::max(u_worst, std::isnan(u_ccx[3 * v + c])
                                      ? HUGE_VAL
                                      : std::abs(u[3 * v + c] - u_ccx[3 * v + c]) / r.max_displacement);
    for (int c = 0; c < 6; ++c)
      s_worst = std::max(s_worst,
                         std::isnan(s_ccx[6 * v + c])
                             ? HUGE_VAL
                             : std::abs(s_node[6 * v + c] / count[v] - s_ccx[6 * v + c]) / r.max_von_mises);
  }
  std::printf(
      "%zu nodes, max |u| %.4g m, max von Mises %.4g Pa; relative difference to ccx: u %.3g, stress %.3g\n",
      nn, r.max_displacement, r.max_von_mises, u_worst, s_worst);
  return {u_worst, s_worst};
}

// The same problem with quadratic tets against ccx C3D10 (mid-edge nodes written by foxi): the displacements
// at the mesh's nodes agree to ccx's printed digits, and foxi's centroid stress per tet equals the mean of
// ccx's stresses at the element's 4 integration points (the stress is linear in a straight-sided C3D10; ccx's
// .dat prints sxx syy szz sxy sxz syz).
std::pair<double, double> quadratic_difference(const test::TempDir& dir, Mesh& m, ThermoelasticParams p) {
  p.order = 2;
  const ThermoelasticReport r = solve_thermoelastic(m, p);
  write_calculix_thermoelastic(m, p, dir / "quad.inp");
  EXPECT_EQ(test::run("cd '" + dir.path().string() + "' && OMP_NUM_THREADS=1 ccx -i quad", dir / "ccx.log"),
            0)
      << test::read_text(dir / "ccx.log");
  const std::size_t nn = m.node_count(), nt = m.tet_count();
  const std::vector<double> u_ccx = frd_nodal(dir / "quad.frd", "DISP", 3, nn);
  const std::vector<double>& u = m.find_field("displacement")->values;
  double u_worst = 0;
  for (std::size_t i = 0; i < 3 * nn; ++i)
    u_worst =
        std::max(u_worst, std::isnan(u_ccx[i]) ? HUGE_VAL : std::abs(u[i] - u_ccx[i]) / r.max_displacement);
  // Integration-point stresses: lines "elem point sxx syy szz sxy sxz syz" after each "stresses" header.
  std::vector<double> s_ccx(6 * nt, 0.0), points(nt, 0.0);
  std::istringstream dat(test::read_text(dir / "quad.dat"));
  std::string line;
  bool in_stress = false;
  while (std::getline(dat, line)) {
    if (line.find("stresses") != std::string::npos) {
      in_stress = true;
      continue;
    }
    std::istringstream fields(line);
    std::size_t elem = 0, point = 0;
    double v[6];
    if (!in_stress || !(fields >> elem >> point >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5])) continue;
    if (elem < 1 || elem > nt) return {HUGE_VAL, HUGE_VAL};
    const int order[6] = {0, 1, 2, 3, 5, 4};  // ccx xz, yz -> foxi yz, xz
    for (int c = 0; c < 6; ++c) s_ccx[6 * (elem - 1) + static_cast<std::size_t>(order[c])] += v[c];
    points[elem - 1] += 1;
  }
  const std::vector<double>& s = m.find_field("stress")->values;
  double s_worst = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    EXPECT_EQ(points[t], 4.0) << "tet " << t;
    for (std::size_t c = 0; c < 6; ++c)
      s_worst = std::max(s_worst, std::abs(s[6 * t + c] - s_ccx[6 * t + c] / 4) / r.max_von_mises);
  }
  std::printf("C3D10: %zu tets, %zu unknowns; relative difference to ccx: u %.3g, centroid stress %.3g\n", nt,
              r.unknowns, u_worst, s_worst);
  return {u_worst, s_worst};
}

ThermoelasticParams two_layer_params(const Mesh& m) {
  ThermoelasticParams p;
  p.materials = {{1, 130e9, 0.28, 2.6e-6}, {2, 117e9, 0.34, 16.5e-6}};
  p.reference_temperature = 293.15;
  p.temperature.resize(m.node_count());
  for (std::size_t v = 0; v < m.node_count(); ++v)
    p.temperature[v] = 350 + 2e4 * m.xyz[3 * v] - 3e4 * m.xyz[3 * v + 2];
  p.solver.kind = LinearSolverKind::direct;
  return p;
}

// Thermal stress on the same C3D4 mesh: a two-layer box (E, nu, alpha per layer), its bottom fixed,
// x = 0 sliding, a nodal temperature field varying in x and z: displacements and nodal stresses agree
// with ccx to its float32 binary .frd (1e-6; the centroid stresses of C3D10 come from the .dat's 7
// digits), on C3D4 and C3D10.
TEST_F(CalculixTest, ThermalStressAgreesWithCcx) {
  test::TempDir dir;
  Mesh m = test::layered_box_mesh(2e-3, 1e-3, {0, 0.4e-3, 1e-3}, 4e-12);
  ThermoelasticParams p = two_layer_params(m);
  p.fixed = {{5}};
  p.sliding = {{1}};
  const auto [du, ds] = thermal_stress_difference(dir, m, p);
  EXPECT_LT(du, 1e-6);
  EXPECT_LT(ds, 1e-6);
  const auto [qu, qs] = quadratic_difference(dir, m, p);  // the mid-edge nodes' constraints too
  EXPECT_LT(qu, 1e-6);
  EXPECT_LT(qs, 1e-6);
}

// The same box turned off the axes, held only by three sliding planes: ccx gets them as *EQUATIONs.
TEST_F(CalculixTest, SlidingPlanesOffTheAxesAgreeWithCcx) {
  test::TempDir dir;
  Mesh m = test::layered_box_mesh(2e-3, 1e-3, {0, 0.4e-3, 1e-3}, 4e-12);
  ThermoelasticParams p = two_layer_params(m);
  const double c = std::cos(0.5), s = std::sin(0.5);
  for (std::size_t v = 0; v < m.node_count(); ++v) {  // a turn of 0.5 rad about z, then about x
    double* x = &m.xyz[3 * v];
    const double x0 = c * x[0] - s * x[1], y0 = s * x[0] + c * x[1];
    const double y1 = c * y0 - s * x[2], z1 = s * y0 + c * x[2];
    x[0] = x0, x[1] = y1, x[2] = z1;
  }
  p.sliding = {{1}, {3}, {5}};
  const auto [du, ds] = thermal_stress_difference(dir, m, p);
  EXPECT_LT(du, 1e-6);
  EXPECT_LT(ds, 1e-6);
  const auto [qu, qs] = quadratic_difference(dir, m, p);  // the mid-edge nodes' constraints too
  EXPECT_LT(qu, 1e-6);
  EXPECT_LT(qs, 1e-6);
}

// The files and children in a private TMPDIR of a test (the CalculiX runs' work folders go there).
class CalculixRunTest : public CalculixTest {
 protected:
  void SetUp() override {
    CalculixTest::SetUp();
    const char* old = std::getenv("TMPDIR");
    old_tmpdir_ = old ? old : "";
    std::filesystem::create_directories(dir_ / "tmp");
    ::setenv("TMPDIR", (dir_ / "tmp").c_str(), 1);
  }
  void TearDown() override {
    if (old_tmpdir_.empty())
      ::unsetenv("TMPDIR");
    else
      ::setenv("TMPDIR", old_tmpdir_.c_str(), 1);
  }
  std::size_t work_folders() const {
    std::size_t n = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir_ / "tmp")) n += e.is_directory();
    return n;
  }
  // A stand-in for ccx at `name` in the test's folder, running `body` (sh).
  std::string stand_in(const std::string& name, const std::string& body) {
    const std::filesystem::path p = dir_ / name;
    test::write_text(p, "#!/bin/sh\n" + body);
    std::filesystem::permissions(p, std::filesystem::perms::owner_all);
    return p.string();
  }
  test::TempDir dir_;
  std::string old_tmpdir_;
};

// One call runs the whole pipeline: ccx's displacements come back on the mesh (the fields foxi's
// solve stores, ccx's nodal stress too) and equal foxi's own to the .frd's float32 (1e-6, as
// ThermalStressAgreesWithCcx finds them by hand); with temperature_from its temperatures are ccx's
// steady ones, equal to foxi's solve with ccx's *FILM rule (1e-6). The work folder goes, or with
// KeepWorkFolder::always stays with the decks and ccx's results in it.
TEST_F(CalculixRunTest, ThermoelasticRunEqualsFoxiAndCleansUp) {
  Mesh m = test::layered_box_mesh(2e-3, 1e-3, {0, 0.4e-3, 1e-3}, 4e-12);
  ThermoelasticParams p = two_layer_params(m);
  p.fixed = {{5}};
  p.sliding = {{1}};
  Mesh own = m;
  const ThermoelasticReport mine = solve_thermoelastic(own, p);
  const CalculixThermoelastic c = solve_thermoelastic_calculix(m, p);
  EXPECT_EQ(c.report.solver, "ccx");
  EXPECT_FALSE(c.thermal.has_value());
  EXPECT_TRUE(c.work_folder.empty());
  EXPECT_EQ(work_folders(), 0u) << "the work folder removed";
  for (const char* name : {"displacement", "stress", "von_mises", "principal_stress", "stress_nodal"})
    EXPECT_NE(m.find_field(name), nullptr) << name;
  const std::vector<double>& u = m.find_field("displacement")->values;
  const std::vector<double>& u_own = own.find_field("displacement")->values;
  double du = 0;
  for (std::size_t i = 0; i < u.size(); ++i)
    du = std::max(du, std::abs(u[i] - u_own[i]) / mine.max_displacement);
  EXPECT_LT(du, 1e-6);
  EXPECT_NEAR(c.report.max_von_mises, mine.max_von_mises, 1e-6 * mine.max_von_mises);
  EXPECT_GT(c.max_nodal_von_mises, 0.1 * mine.max_von_mises);  // ccx's averages at the nodes: smoothed
  EXPECT_LT(c.max_nodal_von_mises, 1.0 * mine.max_von_mises);

  // The temperatures from ccx's thermal run first, in the same (kept) folder.
  ThermalParams heat;
  heat.conductivity = {{1, 0.3}, {2, 148}};
  heat.fixed = {{5, 300}};
  heat.convection = {{6, 20, 290}};
  heat.sources = {{2, 0.05, true}};
  CalculixRunOptions keep;
  keep.keep = KeepWorkFolder::always;
  std::vector<std::string> lines;
  keep.on_output = [&](const std::string& line) { lines.push_back(line); };
  const CalculixThermoelastic t = solve_thermoelastic_calculix(m, p, keep, &heat);
  ASSERT_TRUE(t.thermal.has_value());
  EXPECT_TRUE(all_passed(thermal_results(m, *t.thermal).checks));
  ASSERT_FALSE(t.work_folder.empty());
  for (const char* f : {"heat.inp", "heat.frd", "stress.inp", "stress.frd"})
    EXPECT_TRUE(std::filesystem::exists(t.work_folder / f)) << f;
  EXPECT_FALSE(lines.empty());
  EXPECT_EQ(lines.back(), "Job finished") << "ccx's progress lines, the end last";
  heat.convection_centroid_rule = true;
  solve_thermal(own, heat);
  const std::vector<double>& tc = m.find_field("temperature")->values;
  const std::vector<double>& to = own.find_field("temperature")->values;
  double dt = 0;
  for (std::size_t i = 0; i < tc.size(); ++i) dt = std::max(dt, std::abs(tc[i] - to[i]) / to[i]);
  EXPECT_LT(dt, 1e-6);
  EXPECT_GT(t.thermal->max_temperature, 301);  // heated
  std::filesystem::remove_all(t.work_folder);
}

// A failing ccx (a stand-in) is a CalculixError with its exit status and last output, the folder kept
// only on request; a missing one is CalculixError::Kind::not_installed; a cancel kills a running one
// (SolverCancelled at once, not after it ends) and leaves no folder.
TEST_F(CalculixRunTest, FailingMissingAndCancelledRuns) {
  Mesh m = test::layered_box_mesh(2e-3, 1e-3, {0, 0.4e-3, 1e-3}, 4e-12);
  ThermalParams heat;
  heat.conductivity = {{1, 0.3}, {2, 148}};
  heat.fixed = {{5, 300}};
  CalculixRunOptions o;
  o.program = stand_in("bad-ccx", "echo ' *ERROR reading *NODE: something ccx-specific'\nexit 201\n");
  for (KeepWorkFolder keep : {KeepWorkFolder::never, KeepWorkFolder::on_failure}) {
    o.keep = keep;
    try {
      solve_thermal_calculix(m, heat, o);
      ADD_FAILURE() << "no error";
    } catch (const CalculixError& e) {
      EXPECT_EQ(e.kind, CalculixError::Kind::failed);
      EXPECT_EQ(e.exit_status, 201);
      EXPECT_NE(e.log_tail.find("something ccx-specific"), std::string::npos) << e.log_tail;
      EXPECT_NE(std::string(e.what()).find("something ccx-specific"), std::string::npos);
      EXPECT_EQ(e.work_folder.empty(), keep == KeepWorkFolder::never);
      if (!e.work_folder.empty()) {
        EXPECT_TRUE(std::filesystem::exists(e.work_folder / "heat.inp"));
        std::filesystem::remove_all(e.work_folder);
      }
    }
    EXPECT_EQ(work_folders(), 0u);
  }
  EXPECT_EQ(m.find_field("temperature"), nullptr) << "nothing stored from a failed run";
  o.program = (dir_ / "no-such-ccx").string();
  try {
    solve_thermal_calculix(m, heat, o);
    ADD_FAILURE() << "no error";
  } catch (const CalculixError& e) {
    EXPECT_EQ(e.kind, CalculixError::Kind::not_installed) << e.what();
    EXPECT_TRUE(e.work_folder.empty());
  }
  EXPECT_EQ(work_folders(), 0u);
  // A ccx that would run for a minute, cancelled after its first polls.
  o.program = stand_in("slow-ccx", "sleep 60\n");
  o.keep = KeepWorkFolder::always;
  int polls = 0;
  o.progress = [&](std::string_view stage, double) { return stage == "ccx" && ++polls < 4; };
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_THROW(solve_thermal_calculix(m, heat, o), SolverCancelled);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10);
  EXPECT_EQ(polls, 4);
  EXPECT_EQ(work_folders(), 0u) << "removed on cancel, even when asked to keep it";
}

TEST(FrdReader, RejectsMalformedFiles) {
  test::TempDir dir;
  test::write_text(dir / "bad.frd", "    1C\n -4  NDTEMP      1    1\n -1         1 3.0000\n -3\n");
  EXPECT_THROW(read_frd(dir / "bad.frd"), IoError);
  test::write_text(dir / "ok.frd",
                   "    1C\n    2C                             2                                     1\n"
                   " -1         1 0.00000E+00 0.00000E+00 0.00000E+00\n"
                   " -1         2 1.00000E+00 0.00000E+00 0.00000E+00\n -3\n"
                   "  100CL  101 1.000000000           2                     0    1           1\n"
                   " -4  NDTEMP      1    1\n -5  T           1    1    0    0\n"
                   " -1         1 3.00000E+02\n -1         2-1.25000E+01\n -3\n9999\n");
  const auto blocks = read_frd(dir / "ok.frd");
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_EQ(blocks[0].name, "NDTEMP");
  EXPECT_EQ(blocks[0].node, (std::vector<std::uint32_t>{1, 2}));
  EXPECT_EQ(blocks[0].values, (std::vector<double>{300.0, -12.5}));
  EXPECT_THROW(read_frd(dir / "missing.frd"), IoError);
}

}  // namespace
}  // namespace foxi
