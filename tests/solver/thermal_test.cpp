// Steady heat conduction against analytic 1D solutions on TetGen meshes of a box (x along the slab),
// and against conservation of energy on the example package.
#include "foxi/solver/thermal.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/validate.hpp"
#include "layered_box.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr double kL = 1.0, kW = 0.4;  // slab length (x) and cross-section side (y, z)
constexpr double kArea = kW * kW;

// A box [0, kL] x [0, kW]^2 as a TetGen PLC. Facet markers: 1 at x = 0, 2 at x = kL, 3 the sides,
// 4 the interface x = split (only when `split` is in (0, kL); then regions 1 (x < split), 2).
std::string box_poly(double split) {
  const bool two = split > 0 && split < kL;
  std::vector<double> xs = two ? std::vector<double>{0, split, kL} : std::vector<double>{0, kL};
  std::ostringstream s;
  s.precision(17);
  s << 4 * xs.size() << " 3 0 0\n";
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const double yz[4][2] = {{0, 0}, {kW, 0}, {kW, kW}, {0, kW}};
    for (int c = 0; c < 4; ++c)
      s << 4 * i + c + 1 << ' ' << xs[i] << ' ' << yz[c][0] << ' ' << yz[c][1] << '\n';
  }
  const std::size_t slabs = xs.size() - 1;
  s << (2 + 4 * slabs + (two ? 1 : 0)) << " 1\n";
  auto quad = [&](std::size_t a, std::size_t b, std::size_t c, std::size_t d, int marker) {
    s << "1 0 " << marker << "\n4 " << a << ' ' << b << ' ' << c << ' ' << d << '\n';
  };
  quad(1, 2, 3, 4, 1);
  const std::size_t last = 4 * slabs;
  quad(last + 1, last + 2, last + 3, last + 4, 2);
  if (two) quad(5, 6, 7, 8, 4);
  for (std::size_t i = 0; i < slabs; ++i)
    for (std::size_t c = 0; c < 4; ++c) {
      const std::size_t a = 4 * i + c + 1, b = 4 * i + (c + 1) % 4 + 1;
      quad(a, b, b + 4, a + 4, 3);
    }
  s << "0\n";
  if (two) {
    s << "2\n1 " << split / 2 << ' ' << kW / 2 << ' ' << kW / 2 << " 1 0\n";
    s << "2 " << (split + kL) / 2 << ' ' << kW / 2 << ' ' << kW / 2 << " 2 0\n";
  } else {
    s << "1\n1 " << kL / 2 << ' ' << kW / 2 << ' ' << kW / 2 << " 1 0\n";
  }
  return s.str();
}

// Meshes a PLC with TetGen (quality 1.414, max volume `max_volume`) and reads it back.
Mesh tetgen_mesh(const std::string& poly, double max_volume) {
  test::TempDir dir;
  test::write_text(dir / "box.poly", poly);
  std::ostringstream cmd;
  cmd << "tetgen -pq1.414AQa" << max_volume << " '" << (dir / "box.poly").string() << "'";
  if (test::run(cmd.str(), dir / "log") != 0)
    throw std::runtime_error("tetgen failed: " + test::read_text(dir / "log"));
  Mesh mesh = read_tetgen(dir / "box.1");
  validate_and_repair(mesh);
  return mesh;
}

Mesh box_mesh(double max_volume, double split = 0) { return tetgen_mesh(box_poly(split), max_volume); }

double x_of(const Mesh& m, std::size_t v) { return m.xyz[3 * v]; }

const BoundaryHeat& heat_of(const ThermalReport& r, std::int32_t tag) {
  for (const BoundaryHeat& b : r.boundaries)
    if (b.tag == tag) return b;
  throw std::runtime_error("no boundary heat for tag " + std::to_string(tag));
}

const RegionTemperature& region_of(const ThermalReport& r, std::int32_t id) {
  for (const RegionTemperature& t : r.regions)
    if (t.region == id) return t;
  throw std::runtime_error("no region " + std::to_string(id));
}

// max over nodes |T - exact(x)|
template <class F>
double max_nodal_error(const Mesh& m, F exact) {
  const Field* t = m.find_field("temperature");
  EXPECT_NE(t, nullptr);
  double e = 0;
  for (std::size_t v = 0; v < m.node_count(); ++v)
    e = std::max(e, std::abs(t->values[v] - exact(x_of(m, v))));
  return e;
}

class ThermalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::have_program("tetgen")) GTEST_SKIP() << "tetgen not installed";
  }
};

TEST_F(ThermalTest, SlabBetweenTwoTemperaturesIsLinearAndExact) {
  Mesh m = box_mesh(0.002);
  const double k = 2.5, t0 = 300, t1 = 400;
  ThermalParams p;
  p.conductivity = {{1, k}};
  p.fixed = {{1, t0}, {2, t1}};
  for (LinearSolverKind kind :
       {LinearSolverKind::direct, LinearSolverKind::cg_ichol, LinearSolverKind::cg_amg}) {
    p.solver.kind = kind;
    p.solver.relative_tolerance = 1e-13;
    const ThermalReport r = solve_thermal(m, p);
    EXPECT_LT(max_nodal_error(m, [&](double x) { return t0 + (t1 - t0) * x / kL; }), 1e-10 * t1);
    const double q = k * (t1 - t0) / kL * kArea;  // W, from x = kL to x = 0
    EXPECT_NEAR(heat_of(r, 2).heat_in, q, 1e-9 * q);
    EXPECT_NEAR(heat_of(r, 1).heat_in, -q, 1e-9 * q);
    EXPECT_NEAR(heat_of(r, 1).area, kArea, 1e-12);
    // With no sources the balance is measured against the heat that flows through, not against the
    // (vanishing) net boundary heat.
    EXPECT_NEAR(r.heat_flow, q, 1e-9 * q);
    ASSERT_EQ(r.checks.size(), 3u);
    EXPECT_EQ(r.checks[0].name, "energy");
    EXPECT_TRUE(r.checks[0].passed);
    EXPECT_LT(r.checks[0].figure, 1e-9);
    EXPECT_LE(r.checks[0].figure, std::abs(r.imbalance) / q * (1 + 1e-12));
    // The lowest temperature, the cold face's.
    EXPECT_EQ(r.checks[1].name, "absolute zero");
    EXPECT_TRUE(r.checks[1].passed);
    EXPECT_NEAR(r.checks[1].figure, -t0, 1e-9 * t0);
    EXPECT_EQ(r.checks[2].name, "resolution");
    EXPECT_TRUE(r.checks[2].passed);
    EXPECT_LT(r.checks[2].figure, 1e-9);
    const Field* flux = m.find_field("heat_flux");
    ASSERT_NE(flux, nullptr);
    ASSERT_EQ(flux->values.size(), 3 * m.tet_count());
    for (std::size_t t = 0; t < m.tet_count(); ++t) {
      EXPECT_NEAR(flux->values[3 * t], -k * (t1 - t0) / kL, 1e-8);
      EXPECT_NEAR(flux->values[3 * t + 1], 0, 1e-8);
    }
    EXPECT_NEAR(region_of(r, 1).max_temperature, t1, 1e-9);
    EXPECT_NEAR(region_of(r, 1).mean_temperature, (t0 + t1) / 2, 1e-9);
    EXPECT_NEAR(r.max_temperature, t1, 1e-9);
    EXPECT_NEAR(x_of(m, r.max_node), kL, 1e-12);
    if (kind == LinearSolverKind::cg_ichol) {
      EXPECT_GT(r.iterations, 0u);
    }
  }
}

// The iterative solve reports each CG iteration: counted 1, 2, ..., N with N the report's count (over
// the restarts on the true residual), the last residual within the tolerance, the "solve" progress
// never going back; false from the callback at iteration 3 stops the solve there (SolverCancelled,
// no temperature stored); a direct solve reports none.
TEST_F(ThermalTest, IterationReportsCountEveryCgIterationAndCancel) {
  Mesh m = box_mesh(0.0005);
  ThermalParams p;
  p.conductivity = {{1, 2.5}};
  p.fixed = {{1, 300}, {2, 400}};
  for (LinearSolverKind kind : {LinearSolverKind::cg_ichol, LinearSolverKind::cg_amg}) {
    Mesh mesh = m;
    std::vector<IterationReport> seen;
    std::vector<double> solve_fractions;
    p.solver.kind = kind;
    p.solver.iterations = [&](const IterationReport& r) {
      seen.push_back(r);
      return true;
    };
    p.solver.progress = [&](std::string_view stage, double f) {
      if (stage == "solve") solve_fractions.push_back(f);
      return true;
    };
    const ThermalReport r = solve_thermal(mesh, p);
    ASSERT_GT(r.iterations, 0u);
    ASSERT_EQ(seen.size(), r.iterations);
    for (std::size_t i = 0; i < seen.size(); ++i) {
      EXPECT_EQ(seen[i].iteration, i + 1);
      EXPECT_TRUE(std::isfinite(seen[i].relative_residual));
    }
    EXPECT_LE(seen.back().relative_residual, p.solver.relative_tolerance);
    for (std::size_t i = 1; i < solve_fractions.size(); ++i)
      EXPECT_GE(solve_fractions[i], solve_fractions[i - 1]);
    // Stopped at iteration 3 (where there are more: AMG on this small mesh is a direct solve).
    if (kind == LinearSolverKind::cg_amg) continue;
    ASSERT_GT(r.iterations, 3u);
    Mesh stopped = m;
    seen.clear();
    p.solver.iterations = [&](const IterationReport& rep) {
      seen.push_back(rep);
      return rep.iteration < 3;
    };
    EXPECT_THROW(solve_thermal(stopped, p), SolverCancelled);
    EXPECT_EQ(seen.size(), 3u);
    EXPECT_EQ(stopped.find_field("temperature"), nullptr);
  }
  p.solver.kind = LinearSolverKind::direct;
  p.solver.progress = nullptr;  // (it refers to the loop's vectors)
  std::size_t calls = 0;
  p.solver.iterations = [&](const IterationReport&) { return ++calls, true; };
  Mesh direct = m;
  solve_thermal(direct, p);
  EXPECT_EQ(calls, 0u);
}

// -k T'' = Q, T(0) = T(L) = 0: T = Q x (L - x) / (2k). L2 error of P1 must fall as h^2.
TEST_F(ThermalTest, HeatGenerationConvergesAtSecondOrder) {
  const double k = 3, q = 1200;
  auto exact = [&](double x) { return q * x * (kL - x) / (2 * k); };
  std::vector<double> hs, errors;
  std::vector<std::size_t> tets;
  for (double max_volume : {0.00025, 0.00003125, 0.0000039}) {
    Mesh m = box_mesh(max_volume);
    ThermalParams p;
    p.conductivity = {{1, k}};
    p.fixed = {{1, 0}, {2, 0}};
    p.sources = {{1, q * kL * kArea, true}};  // total W
    p.solver.kind = LinearSolverKind::cg_amg;
    p.solver.relative_tolerance = 1e-12;
    const ThermalReport r = solve_thermal(m, p);
    EXPECT_NEAR(r.total_power, q * kL * kArea, 1e-9 * r.total_power);
    // Energy balance: what is generated leaves through the two ends, half each by symmetry.
    EXPECT_NEAR(heat_of(r, 1).heat_in + heat_of(r, 2).heat_in, -r.total_power, 1e-8 * r.total_power);
    const std::vector<double>& t = m.find_field("temperature")->values;
    // L2 error by a degree-5 rule would be overkill: the 4-point degree-2 rule on each tet.
    const double a = 0.5854101966249685, b = 0.1381966011250105;
    double e2 = 0, vol = 0;
    for (std::size_t e = 0; e < m.tet_count(); ++e) {
      const std::uint32_t* v = &m.tet[4 * e];
      double x[4], tv[4];
      for (int i = 0; i < 4; ++i) x[i] = x_of(m, v[i]), tv[i] = t[v[i]];
      const double* p0 = &m.xyz[3 * v[0]];
      double d[3][3];
      for (int i = 0; i < 3; ++i)
        for (int c = 0; c < 3; ++c) d[i][c] = m.xyz[3 * v[i + 1] + c] - p0[c];
      const double det = d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) -
                         d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0]) +
                         d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
      const double volume = det / 6;
      vol += volume;
      for (int qp = 0; qp < 4; ++qp) {
        double xq = 0, tq = 0;
        for (int i = 0; i < 4; ++i) {
          const double w = i == qp ? a : b;
          xq += w * x[i];
          tq += w * tv[i];
        }
        e2 += volume / 4 * (tq - exact(xq)) * (tq - exact(xq));
      }
    }
    hs.push_back(std::cbrt(vol / static_cast<double>(m.tet_count())));
    errors.push_back(std::sqrt(e2));
    tets.push_back(m.tet_count());
    // The other solvers agree with the one used (AMG, several levels on the finer meshes): LDL^T on
    // the coarser meshes, incomplete-Cholesky CG on the finest (where LDL^T is slow under ASan).
    EXPECT_EQ(r.solver, "CG+SmoothedAggregationAMG");
    EXPECT_LT(r.iterations, 40u);  // multigrid: iterations nearly independent of the mesh size
    const std::vector<double> first = t;
    p.solver.kind = max_volume < 1e-5 ? LinearSolverKind::cg_ichol : LinearSolverKind::direct;
    const ThermalReport rc = solve_thermal(m, p);
    const std::vector<double>& tc = m.find_field("temperature")->values;
    double diff = 0;
    for (std::size_t v = 0; v < tc.size(); ++v) diff = std::max(diff, std::abs(tc[v] - first[v]));
    EXPECT_LT(diff, 1e-8 * q * kL * kL / (8 * k)) << rc.solver;
    EXPECT_LT(rc.relative_residual, 1e-11) << rc.solver;
    std::printf("%zu unknowns: AMG %zu iterations, %s %zu iterations, max difference %.3g K\n", r.unknowns,
                r.iterations, rc.solver.c_str(), rc.iterations, diff);
  }
  for (std::size_t i = 1; i < hs.size(); ++i) {
    const double rate = std::log(errors[i - 1] / errors[i]) / std::log(hs[i - 1] / hs[i]);
    RecordProperty("rate" + std::to_string(i), std::to_string(rate));
    std::printf("%zu tets, h %.4g -> %.4g: L2 error %.4g -> %.4g, rate %.3f\n", tets[i], hs[i - 1], hs[i],
                errors[i - 1], errors[i], rate);
    EXPECT_GT(rate, 1.8);
    EXPECT_LT(rate, 2.3);
  }
  // And the error is small in absolute terms (max of T is q L^2 / 8k = 50).
  EXPECT_LT(errors.back() / std::sqrt(kL * kArea), 0.01 * q * kL * kL / (8 * k));
}

// Two materials in series: the heat is dT / (L1 / (k1 A) + L2 / (k2 A)), the profile piecewise linear.
TEST_F(ThermalTest, TwoMaterialSlabIsASeriesResistance) {
  Mesh m = box_mesh(0.002, 0.3);
  const double k1 = 1.5, k2 = 6, t0 = 250, t1 = 350, l1 = 0.3, l2 = kL - 0.3;
  // Region 1 takes its conductivity from its material, region 2 from the parameters.
  m.materials.push_back({"mat", k1});
  for (Region& r : m.regions)
    if (r.id == 1) r.material = 0;
  ThermalParams p;
  p.conductivity = {{2, k2}};
  p.fixed = {{1, t0}, {2, t1}};
  const ThermalReport r = solve_thermal(m, p);
  const double q = (t1 - t0) / (l1 / (k1 * kArea) + l2 / (k2 * kArea));
  const double ti = t0 + q * l1 / (k1 * kArea);  // interface temperature
  auto exact = [&](double x) { return x < l1 ? t0 + (ti - t0) * x / l1 : ti + (t1 - ti) * (x - l1) / l2; };
  EXPECT_LT(max_nodal_error(m, exact), 1e-10 * t1);
  EXPECT_NEAR(heat_of(r, 2).heat_in, q, 1e-9 * q);
  EXPECT_NEAR(heat_of(r, 1).heat_in, -q, 1e-9 * q);
  EXPECT_NEAR(region_of(r, 1).mean_temperature, (t0 + ti) / 2, 1e-9);
  EXPECT_NEAR(region_of(r, 2).mean_temperature, (ti + t1) / 2, 1e-9);
  EXPECT_NEAR(region_of(r, 1).max_temperature, ti, 1e-9);
  EXPECT_NEAR(region_of(r, 1).volume, l1 * kArea, 1e-12);
}

// Conductivities 1e12 apart in series (an outside probe): the heat through the good conductor's fixed
// face is a difference of terms K_vj T_j some 1e14 times larger and came out 6.8% off, every check
// passing. Against the series formula: the heats either agree within the printed digits or the
// resolution check fails; at 1e12:1 it fails, at 1e4:1 the heats are exact and every check passes.
TEST_F(ThermalTest, ConductivitiesFarApartFailTheResolutionCheckRatherThanMisstateTheHeat) {
  Mesh m = box_mesh(0.004, 0.5);
  const double t0 = 300, t1 = 400;
  for (const double contrast : {1e4, 1e9, 1e12}) {
    ThermalParams p;
    p.conductivity = {{1, contrast}, {2, 1.0}};
    p.fixed = {{1, t0}, {2, t1}};
    const ThermalReport r = solve_thermal(m, p);
    const double q = (t1 - t0) / (0.5 / (contrast * kArea) + 0.5 / kArea);
    const BalanceCheck* resolution = nullptr;
    for (const BalanceCheck& c : r.checks)
      if (c.name == "resolution") resolution = &c;
    ASSERT_NE(resolution, nullptr);
    const double error = std::abs(heat_of(r, 1).heat_in + q) / q;
    EXPECT_TRUE(!resolution->passed || error < 1e-5)
        << contrast << ": " << error << " " << resolution->figure;
    EXPECT_NEAR(heat_of(r, 2).heat_in, q, 1e-9 * q);
    if (contrast == 1e4) {
      EXPECT_LT(error, 1e-9);
      for (const BalanceCheck& c : r.checks) EXPECT_TRUE(c.passed) << c.name << " " << c.figure;
    }
    if (contrast == 1e12) EXPECT_FALSE(resolution->passed) << resolution->figure;
  }
}

// A small heat through a good conductor (an outside probe): three layers in z, 1 W made in the bottom
// one (k 1), a poor middle (k 1e-4) and a top of k3, both ends held at 300 K. With k3 = 1e10 the top's
// heat, 5e-5 W of the 1 W, came out +1.6e-4 W with every check passing: the resolution check measures
// each heat against its own size (or 1e-4 of the flow), and fails. With k3 = 1 the heats agree with
// the 1D solution and every check passes. Oracle: q_top = s L1^2 / (2 k1 (R_up + L1 / k1)) with s the
// source density and R_up = L2 / k2 + L3 / k3 (per area).
TEST_F(ThermalTest, SmallHeatThroughAGoodConductorIsMeasuredAgainstItself) {
  const double w = 0.004, l1 = 0.001, l2 = 0.001, l3 = 0.001, area = w * w;
  Mesh m = test::layered_box_mesh(w, w, {0, l1, l1 + l2, l1 + l2 + l3}, 1e-10);
  for (const double k3 : {1.0, 1e10}) {
    ThermalParams p;
    p.conductivity = {{1, 1.0}, {2, 1e-4}, {3, k3}};
    p.fixed = {{5, 300}, {6, 300}};
    p.sources = {{1, 1.0, true}};
    p.solver.kind = LinearSolverKind::direct;
    const ThermalReport r = solve_thermal(m, p);
    const double s = 1.0 / (area * l1), r_up = l2 / 1e-4 + l3 / k3;
    const double q_top = s * l1 * l1 / (2 * (r_up + l1)) * area;  // W leaving through the top
    const BalanceCheck* resolution = nullptr;
    for (const BalanceCheck& c : r.checks)
      if (c.name == "resolution") resolution = &c;
    ASSERT_NE(resolution, nullptr);
    const double error = std::abs(heat_of(r, 6).heat_in + q_top) / q_top;
    EXPECT_TRUE(!resolution->passed || error < 0.02)
        << k3 << ": " << heat_of(r, 6).heat_in << " vs " << -q_top;
    if (k3 == 1.0) {
      EXPECT_LT(error, 0.02) << heat_of(r, 6).heat_in << " vs " << -q_top;
      for (const BalanceCheck& c : r.checks) EXPECT_TRUE(c.passed) << c.name << " " << c.figure;
    } else {
      EXPECT_FALSE(resolution->passed) << resolution->figure;
    }
  }
}

// A body at its convective ambient with no power (an outside probe: the energy check failed, 0.78,
// on 2.4e-15 W of round-off, the solve's own residual 2.5e-13 in this ill-conditioned system): the
// imbalance is within the heats' bounds, every check passes.
TEST_F(ThermalTest, BodyAtItsConvectiveAmbientPassesItsChecks) {
  Mesh m = box_mesh(0.002);
  ThermalParams p;
  p.conductivity = {{1, 1.0}};
  p.convection = {{1, 10, 300}};
  p.sources = {{1, 0.0}};
  p.solver.kind = LinearSolverKind::direct;
  const ThermalReport r = solve_thermal(m, p);
  for (const BalanceCheck& c : r.checks) EXPECT_TRUE(c.passed) << c.name << " " << c.figure;
  EXPECT_LE(std::abs(r.imbalance), heat_of(r, 1).heat_bound);
}

// A body held by convection alone, so weakly that double precision cannot fix its temperature (an
// outside probe: h 1e-8 W/(m^2 K) on a conductor of k 1e4 printed 431.9 K for a 300 K ambient, every
// check passing): refused, naming the convection and the conduction; a usual h solves to the ambient.
TEST_F(ThermalTest, BodyHeldTooWeaklyForDoublePrecisionIsRefused) {
  Mesh m = box_mesh(0.002);
  ThermalParams p;
  p.conductivity = {{1, 1e4}};
  p.sources = {{1, 0.0}};
  p.solver.kind = LinearSolverKind::direct;
  p.convection = {{1, 1e-8, 300}};
  try {
    solve_thermal(m, p);
    ADD_FAILURE() << "solved";
  } catch (const SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("held too weakly for double precision"), std::string::npos)
        << e.what();
  }
  p.convection = {{1, 10, 300}};
  const ThermalReport r = solve_thermal(m, p);
  EXPECT_NEAR(r.max_temperature, 300, 1e-6);
  for (const BalanceCheck& c : r.checks) EXPECT_TRUE(c.passed) << c.name << " " << c.figure;
}

// A body held at one temperature moves no heat: every boundary's heat is round-off and every check
// passes, with a direct solve and an iterative one (whose temperatures carry its residual).
TEST_F(ThermalTest, BodyHeldAtOneTemperaturePassesItsChecks) {
  Mesh m = box_mesh(0.002);
  ThermalParams p;
  p.conductivity = {{1, 400}};
  p.fixed = {{1, 300}, {2, 300}};
  for (LinearSolverKind kind : {LinearSolverKind::direct, LinearSolverKind::cg_amg}) {
    p.solver.kind = kind;
    const ThermalReport r = solve_thermal(m, p);
    ASSERT_EQ(r.checks.size(), 3u);
    for (const BalanceCheck& c : r.checks) EXPECT_TRUE(c.passed) << c.name << " " << c.figure;
    EXPECT_LT(std::abs(heat_of(r, 1).heat_in), 1e-6);
  }
}

// Fixed T0 at x = 0, convection (h, Tinf) at x = L: q = (Tinf - T0) / (L/k + 1/h), linear profile.
TEST_F(ThermalTest, ConvectionBoundaryMatchesRobinSolution) {
  Mesh m = box_mesh(0.002);
  const double k = 4, h = 10, t0 = 300, tinf = 500;
  ThermalParams p;
  p.conductivity = {{1, k}};
  p.fixed = {{1, t0}};
  p.convection = {{2, h, tinf}};
  const ThermalReport r = solve_thermal(m, p);
  const double flux = (tinf - t0) / (kL / k + 1 / h);  // W/m^2 into the body at x = L
  EXPECT_LT(max_nodal_error(m, [&](double x) { return t0 + flux * x / k; }), 1e-10 * tinf);
  EXPECT_NEAR(heat_of(r, 2).heat_in, flux * kArea, 1e-9 * flux * kArea);
  EXPECT_NEAR(heat_of(r, 1).heat_in, -flux * kArea, 1e-9 * flux * kArea);
  // The cooled surface sits between the wall and the air: T(L) = T0 + flux L / k.
  EXPECT_NEAR(heat_of(r, 2).mean_temperature, t0 + flux * kL / k, 1e-9 * tinf);
  EXPECT_NEAR(heat_of(r, 1).mean_temperature, t0, 1e-12 * t0);
}

// thermal_report on temperatures from elsewhere (here the analytic Robin profile, which P1 holds
// exactly): the boundary heats are the analytic ones, the fields stored; rounded to 6 digits as
// ccx prints them, the check passes within the rounding tolerance; a wrong profile fails it.
TEST_F(ThermalTest, ReportOfGivenTemperaturesMatchesTheAnalyticHeat) {
  Mesh m = box_mesh(0.002);
  const double k = 4, h = 10, t0 = 300, tinf = 500;
  ThermalParams p;
  p.conductivity = {{1, k}};
  p.fixed = {{1, t0}};
  p.convection = {{2, h, tinf}};
  p.convection_centroid_rule = true;  // a linear field: the centroid rule is exact on it too
  const double flux = (tinf - t0) / (kL / k + 1 / h);
  auto profile = [&](double slope_factor, bool rounded) {
    std::vector<double> t(m.node_count());
    for (std::size_t v = 0; v < t.size(); ++v) {
      t[v] = t0 + slope_factor * flux * x_of(m, v) / k;
      if (rounded) {
        char text[32];
        std::snprintf(text, sizeof text, "%.5E", t[v]);
        t[v] = std::strtod(text, nullptr);
      }
    }
    return t;
  };
  const ThermalReport r = thermal_report(m, p, profile(1, false));
  EXPECT_NEAR(heat_of(r, 2).heat_in, flux * kArea, 1e-9 * flux * kArea);
  EXPECT_NEAR(heat_of(r, 1).heat_in, -flux * kArea, 1e-9 * flux * kArea);
  EXPECT_NEAR(r.max_temperature, t0 + flux * kL / k, 1e-9 * tinf);
  EXPECT_NEAR(region_of(r, 1).mean_temperature, t0 + flux * kL / (2 * k), 1e-9 * tinf);
  ASSERT_EQ(r.checks.size(), 3u);
  EXPECT_TRUE(r.checks[2].passed);
  EXPECT_TRUE(r.checks[1].passed);
  EXPECT_TRUE(r.checks[0].passed);
  EXPECT_LT(r.checks[0].figure, 1e-9);
  EXPECT_EQ(r.solver, "given");
  ASSERT_NE(m.find_field("heat_flux"), nullptr);
  EXPECT_NEAR(m.find_field("heat_flux")->values[0], -flux, 1e-8 * flux);
  const ThermalReport rounded = thermal_report(m, p, profile(1, true), 5e-6);
  // The rounding's imbalance is within the heats' bounds (3 sqrt(sum of squares) of precision |K_vj T_j|).
  EXPECT_TRUE(rounded.checks[0].passed) << rounded.checks[0].figure << " " << rounded.checks[0].tolerance;
  EXPECT_LT(std::abs(rounded.imbalance), heat_of(rounded, 1).heat_bound + heat_of(rounded, 2).heat_bound);
  EXPECT_GT(heat_of(rounded, 1).heat_bound, 0);
  EXPECT_LT(heat_of(rounded, 1).heat_bound, 0.01 * flux * kArea);
  // Six digits carry these heats (a tet's temperatures differ by some 1e-3 of themselves).
  EXPECT_TRUE(rounded.checks[2].passed) << rounded.checks[2].figure;
  EXPECT_GT(rounded.checks[2].figure, 1e-5);
  const ThermalReport wrong = thermal_report(m, p, profile(1.05, false), 5e-6);
  EXPECT_FALSE(wrong.checks[0].passed) << wrong.checks[0].figure << " " << wrong.checks[0].tolerance;
  EXPECT_THROW(thermal_report(m, p, std::vector<double>(3, t0)), SolverError);
  std::vector<double> nan = profile(1, false);
  nan[m.tet[0]] = NAN;
  EXPECT_THROW(thermal_report(m, p, nan), SolverError);
}

// Convection only (no fixed temperature) with a source: T at the cooled end is Tinf + P / (h A).
TEST_F(ThermalTest, ConvectionAloneMakesItWellPosed) {
  Mesh m = box_mesh(0.002);
  const double k = 4, h = 25, tinf = 290, q = 5000;
  ThermalParams p;
  p.conductivity = {{1, k}};
  p.convection = {{1, h, tinf}};
  p.flux = {{2, q}};
  const ThermalReport r = solve_thermal(m, p);
  const double t_cool = tinf + q / h;
  EXPECT_LT(max_nodal_error(m, [&](double x) { return t_cool + q * x / k; }), 1e-9 * t_cool);
  EXPECT_NEAR(heat_of(r, 1).heat_in, -q * kArea, 1e-9 * q * kArea);
}

// Fixed T0 at x = 0, heat flux q into the body at x = L: T = T0 + q x / k.
TEST_F(ThermalTest, FluxBoundaryGivesLinearProfile) {
  Mesh m = box_mesh(0.002);
  const double k = 0.8, t0 = 273.15, q = 150;
  ThermalParams p;
  p.conductivity = {{1, k}};
  p.fixed = {{1, t0}};
  p.flux = {{2, q}};
  const ThermalReport r = solve_thermal(m, p);
  EXPECT_LT(max_nodal_error(m, [&](double x) { return t0 + q * x / k; }), 1e-10 * (t0 + q / k));
  EXPECT_NEAR(heat_of(r, 2).heat_in, q * kArea, 1e-12);
  EXPECT_NEAR(heat_of(r, 1).heat_in, -q * kArea, 1e-9 * q * kArea);
  EXPECT_NEAR(heat_of(r, 2).area, kArea, 1e-12);
}

void expect_error(Mesh& m, const ThermalParams& p, const std::string& words) {
  try {
    solve_thermal(m, p);
    ADD_FAILURE() << "no error; expected one saying '" << words << "'";
  } catch (const SolverError& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

// The box split along y at `split` into regions 1 (y < split) and 2, both spanning x = 0 .. kL: two
// conductors in parallel. Facet markers as box_poly: 1 at x = 0, 2 at x = kL, 3 the sides, 4 the
// interface.
Mesh parallel_box_mesh(double max_volume, double split) {
  const double ys[3] = {0, split, kW};
  auto id = [](int ix, int iy, int iz) { return 1 + 6 * ix + 2 * iy + iz; };
  std::ostringstream s;
  s.precision(17);
  s << "12 3 0 0\n";
  for (int ix = 0; ix < 2; ++ix)
    for (int iy = 0; iy < 3; ++iy)
      for (int iz = 0; iz < 2; ++iz)
        s << id(ix, iy, iz) << ' ' << ix * kL << ' ' << ys[iy] << ' ' << iz * kW << '\n';
  s << "11 1\n";
  auto quad = [&](int a, int b, int c, int d, int marker) {
    s << "1 0 " << marker << "\n4 " << a << ' ' << b << ' ' << c << ' ' << d << '\n';
  };
  for (int ix = 0; ix < 2; ++ix)
    for (int iy = 0; iy < 2; ++iy)
      quad(id(ix, iy, 0), id(ix, iy + 1, 0), id(ix, iy + 1, 1), id(ix, iy, 1), 1 + ix);
  for (int iy = 0; iy < 3; iy += 2) quad(id(0, iy, 0), id(1, iy, 0), id(1, iy, 1), id(0, iy, 1), 3);
  for (int iz = 0; iz < 2; ++iz)
    for (int iy = 0; iy < 2; ++iy)
      quad(id(0, iy, iz), id(1, iy, iz), id(1, iy + 1, iz), id(0, iy + 1, iz), 3);
  quad(id(0, 1, 0), id(1, 1, 0), id(1, 1, 1), id(0, 1, 1), 4);
  s << "0\n2\n";
  s << "1 " << kL / 2 << ' ' << split / 2 << ' ' << kW / 2 << " 1 0\n";
  s << "2 " << kL / 2 << ' ' << (split + kW) / 2 << ' ' << kW / 2 << " 2 0\n";
  return tetgen_mesh(s.str(), max_volume);
}

ThermalResistanceSpec theta_spec(ThermalProbeKind junction, std::int32_t j, ThermalProbeKind reference,
                                 std::int32_t r) {
  return {{junction, j}, {reference, r}};
}

// Fixed T0 at x = 0, flux q into x = L: the hottest point (x = L) is T0 + q L / k and the power q A,
// so junction-to-end theta = L / (k A), the conductance of a slab; the volume mean sits half-way.
TEST_F(ThermalTest, SlabThermalResistanceIsLengthOverConductance) {
  Mesh m = box_mesh(0.002);
  const double k = 2.5, t0 = 300, q = 400;
  ThermalParams p;
  p.conductivity = {{1, k}};
  p.fixed = {{1, t0}};
  p.flux = {{2, q}};
  using K = ThermalProbeKind;
  p.resistances = {theta_spec(K::region_max, 1, K::boundary_mean, 1),
                   theta_spec(K::boundary_mean, 2, K::boundary_mean, 1),
                   theta_spec(K::region_mean, 1, K::boundary_mean, 1)};
  const ThermalReport r = solve_thermal(m, p);
  ASSERT_EQ(r.resistances.size(), 3u);
  const double theta = kL / (k * kArea);
  for (int i = 0; i < 2; ++i) {
    const ThermalResistance& t = r.resistances[static_cast<std::size_t>(i)];
    EXPECT_NEAR(t.power, q * kArea, 1e-12 * q);
    EXPECT_NEAR(t.junction_temperature, t0 + q * kL / k, 1e-9 * t0);
    EXPECT_NEAR(t.reference_temperature, t0, 1e-12 * t0);
    EXPECT_NEAR(t.theta, theta, 1e-9 * theta);
    EXPECT_NEAR(t.reference_heat_out, q * kArea, 1e-9 * q * kArea);  // all the heat leaves at x = 0
    EXPECT_NEAR(t.path_theta, theta, 1e-9 * theta);
  }
  EXPECT_NEAR(r.resistances[2].theta, theta / 2, 1e-9 * theta);
}

// Two materials in series between a heat flux and a convective end: the resistances add,
// theta_JA = 1 / (h A) + L1 / (k1 A) + L2 / (k2 A), and to the cooled surface without the film term.
TEST_F(ThermalTest, SeriesThermalResistancesAdd) {
  Mesh m = box_mesh(0.002, 0.3);
  const double k1 = 1.5, k2 = 6, h = 20, tinf = 290, q = 300, l1 = 0.3, l2 = kL - 0.3;
  ThermalParams p;
  p.conductivity = {{1, k1}, {2, k2}};
  p.convection = {{1, h, tinf}};
  p.flux = {{2, q}};
  using K = ThermalProbeKind;
  p.resistances = {theta_spec(K::region_max, 2, K::ambient, 1),
                   theta_spec(K::region_max, 2, K::boundary_mean, 1),
                   theta_spec(K::region_max, 1, K::boundary_mean, 1)};
  const ThermalReport r = solve_thermal(m, p);
  const double film = 1 / (h * kArea), r1 = l1 / (k1 * kArea), r2 = l2 / (k2 * kArea);
  const double expected[3] = {film + r1 + r2, r1 + r2, r1};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(r.resistances[i].theta, expected[i], 1e-9 * expected[i]) << i;
    EXPECT_NEAR(r.resistances[i].path_theta, expected[i], 1e-9 * expected[i]) << i;
  }
  EXPECT_NEAR(r.resistances[0].reference_temperature, tinf, 1e-12);
}

// Two materials side by side between two fixed temperatures: no power at all, so theta is undefined,
// and the path resistance is the parallel combination 1 / (k1 A1 / L + k2 A2 / L).
TEST_F(ThermalTest, ParallelThermalResistancesCombine) {
  const double split = 0.1, k1 = 2, k2 = 7, t0 = 300, t1 = 350;
  Mesh m = parallel_box_mesh(0.002, split);
  ThermalParams p;
  p.conductivity = {{1, k1}, {2, k2}};
  p.fixed = {{1, t0}, {2, t1}};
  using K = ThermalProbeKind;
  p.resistances = {theta_spec(K::boundary_mean, 2, K::boundary_mean, 1)};
  const ThermalReport r = solve_thermal(m, p);
  const double expected = 1 / (k1 * split * kW / kL + k2 * (kW - split) * kW / kL);
  const ThermalResistance& t = r.resistances[0];
  EXPECT_NEAR(t.delta_t, t1 - t0, 1e-9);
  EXPECT_EQ(t.power, 0.0);
  EXPECT_TRUE(std::isnan(t.theta));
  EXPECT_NEAR(t.path_theta, expected, 1e-9 * expected);
  EXPECT_NEAR(region_of(r, 1).volume, split * kW * kL, 1e-12);
}

TEST_F(ThermalTest, ThermalResistanceProbesAreChecked) {
  Mesh m = box_mesh(0.01);
  ThermalParams p;
  p.conductivity = {{1, 1}};
  p.fixed = {{1, 300}};
  p.flux = {{2, 10}};
  using K = ThermalProbeKind;
  ThermalParams ambient = p;
  ambient.resistances = {theta_spec(K::region_max, 1, K::ambient, 1)};
  expect_error(m, ambient, "boundary tag 1: it has no convection condition");
  ThermalParams region = p;
  region.resistances = {theta_spec(K::region_max, 5, K::boundary_mean, 1)};
  expect_error(m, region, "maximum temperature of region 5, which has no tets");
  ThermalParams tag = p;
  tag.resistances = {theta_spec(K::region_max, 1, K::boundary_mean, 8)};
  expect_error(m, tag, "boundary tag 8, which tags no boundary triangle");
  // An insulated reference takes no heat: the path resistance is undefined, theta is not.
  p.resistances = {theta_spec(K::region_max, 1, K::boundary_mean, 3)};
  const ThermalReport r = solve_thermal(m, p);
  EXPECT_EQ(r.resistances[0].reference_heat_out, 0.0);
  EXPECT_TRUE(std::isnan(r.resistances[0].path_theta));
  EXPECT_GT(r.resistances[0].theta, 0.0);
  // No power at all, the body held at 300 K: theta and dT/heat are undefined, not a ratio of
  // round-off (10.3 K/W was printed).
  ThermalParams still = p;
  still.flux.clear();
  still.resistances = {theta_spec(K::region_max, 1, K::boundary_mean, 1)};
  const ThermalReport s = solve_thermal(m, still);
  EXPECT_TRUE(std::isnan(s.resistances[0].theta));
  EXPECT_TRUE(std::isnan(s.resistances[0].path_theta)) << s.resistances[0].path_theta;
}

TEST_F(ThermalTest, IllPosedAndIncompleteProblemsGiveClearErrors) {
  Mesh m = box_mesh(0.01, 0.5);
  ThermalParams p;
  p.conductivity = {{1, 1}, {2, 2}};
  p.flux = {{1, 10}};
  expect_error(m, p, "ill-posed");  // only a flux: T up to a constant
  p.fixed = {{2, 300}};
  ThermalParams missing = p;
  missing.conductivity = {{1, 1}};
  expect_error(m, missing, "region 2 has no thermal conductivity");
  ThermalParams unknown = p;
  unknown.convection = {{9, 5, 300}};
  expect_error(m, unknown, "boundary tag 9");
  ThermalParams twice = p;
  twice.convection = {{2, 5, 300}};
  expect_error(m, twice, "more than one boundary condition");
  ThermalParams bad_h = p;
  bad_h.convection = {{3, 0, 300}};
  expect_error(m, bad_h, "must be positive");
  ThermalParams bad_region = p;
  bad_region.sources = {{7, 1, true}};
  expect_error(m, bad_region, "region 7");
  EXPECT_NO_THROW(solve_thermal(m, p));
}

// Two separate boxes (regions 1 and 2, the second shifted away): a condition on the first alone
// leaves the second floating.
TEST_F(ThermalTest, FloatingPartIsIllPosed) {
  Mesh m = box_mesh(0.01);
  const Mesh second = box_mesh(0.01);
  const auto offset = static_cast<std::uint32_t>(m.node_count());
  for (std::size_t v = 0; v < second.node_count(); ++v) {
    m.xyz.push_back(second.xyz[3 * v] + 2 * kL);
    m.xyz.push_back(second.xyz[3 * v + 1]);
    m.xyz.push_back(second.xyz[3 * v + 2]);
  }
  if (m.tet_region.empty()) m.tet_region.assign(m.tet_count(), 1);
  for (std::uint32_t v : second.tet) m.tet.push_back(v + offset);
  m.tet_region.resize(m.tet_count(), 2);
  for (std::size_t f = 0; f < second.bface_count(); ++f) {
    for (int i = 0; i < 3; ++i) m.bface.push_back(second.bface[3 * f + i] + offset);
    m.bface_tag.push_back(second.bface_tag[f] + 10);
  }
  m.regions.push_back({2, "floating", kNone});
  ThermalParams p;
  p.conductivity = {{1, 1}, {2, 1}};
  p.fixed = {{1, 300}, {2, 400}};
  expect_error(m, p, "region 2 ('floating')");
  p.convection = {{13, 5, 300}};  // the second box's sides
  const ThermalReport r = solve_thermal(m, p);
  EXPECT_NEAR(region_of(r, 2).max_temperature, 300, 1e-9);  // no source: it settles at T_inf
  EXPECT_NEAR(region_of(r, 2).mean_temperature, 300, 1e-9);
}

// A jittered Kuhn grid with more unknowns than the AMG keeps on one thread (20,000 rows): the hybrid
// Gauss-Seidel smoother (each thread its own block of rows) must converge like the serial one, to the
// exact linear profile between two fixed ends (exact for P1, so what is left is solver error).
TEST(ThermalAmg, ThreadedHierarchyReachesTheExactLinearProfile) {
  Mesh m = bench::kuhn_grid_mesh(28, 0.15, 7);
  ThermalParams p;
  p.conductivity = {{1, 2.0}, {2, 2.0}};
  p.fixed = {{1, 300}, {2, 500}};
  p.solver.kind = LinearSolverKind::cg_amg;
  p.solver.relative_tolerance = 1e-12;
  for (unsigned threads : {2u, 3u}) {  // one thread: the smaller meshes above
    p.solver.threads = threads;
    const ThermalReport r = solve_thermal(m, p);
    ASSERT_GT(r.unknowns, 20000u);
    std::printf("[ amg ] %u threads: %zu unknowns, %zu iterations\n", threads, r.unknowns, r.iterations);
    EXPECT_LT(r.iterations, 30u) << threads << " threads";
    EXPECT_LT(r.relative_residual, 1e-12);
    EXPECT_LT(max_nodal_error(m, [](double x) { return 300 + 200 * x; }), 1e-8) << threads << " threads";
    EXPECT_NEAR(heat_of(r, 2).heat_in, 2.0 * 200, 1e-7);  // k dT/L over the unit square
  }
}

TEST_F(ThermalTest, ProgressCanCancel) {
  Mesh m = box_mesh(0.002);
  ThermalParams p;
  p.conductivity = {{1, 1}};
  p.fixed = {{1, 0}, {2, 1}};
  int calls = 0;
  p.solver.progress = [&](std::string_view stage, double f) {
    ++calls;
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0);
    return stage != "solve";
  };
  EXPECT_THROW(solve_thermal(m, p), SolverCancelled);
  EXPECT_THROW(solve_thermal(m, p), Cancelled);  // the one cancellation outcome of every library
  EXPECT_GT(calls, 1);
  EXPECT_EQ(m.find_field("temperature"), nullptr);  // nothing written on cancel
}

// The example package: die (region 2) dissipating 2 W on an FR-4 substrate (region 1), cooled from
// below (tag 1, fixed) and by convection on top (tags 3, 6). Direct and CG agree; energy balances;
// the hottest point is on the die.
TEST_F(ThermalTest, DieOnSubstrateBalancesEnergyAndSolversAgree) {
  test::TempDir dir;
  test::write_text(dir / "pkg.poly",
                   test::read_text(test::data_dir() + "/../../examples/die_on_substrate.poly"));
  ASSERT_EQ(test::run("tetgen -pq1.414AQa5e-10 '" + (dir / "pkg.poly").string() + "'", dir / "log"), 0);
  Mesh m = read_tetgen(dir / "pkg.1");
  validate_and_repair(m);
  ThermalParams p;
  p.conductivity = {{1, 0.3}, {2, 148}};
  p.fixed = {{1, 300}};
  p.convection = {{3, 10, 300}, {6, 10, 300}};
  p.sources = {{2, 2.0, true}};
  p.solver.kind = LinearSolverKind::direct;
  const ThermalReport direct = solve_thermal(m, p);
  const std::vector<double> t_direct = m.find_field("temperature")->values;
  p.solver.kind = LinearSolverKind::cg_ichol;
  p.solver.relative_tolerance = 1e-12;
  const ThermalReport cg = solve_thermal(m, p);
  const std::vector<double>& t_cg = m.find_field("temperature")->values;
  double rise = direct.max_temperature - 300, diff = 0;
  for (std::size_t v = 0; v < t_cg.size(); ++v) diff = std::max(diff, std::abs(t_cg[v] - t_direct[v]));
  EXPECT_GT(rise, 0.1);
  EXPECT_LT(diff, 1e-8 * rise);
  EXPECT_GT(cg.iterations, 0u);
  double heat = 0;
  for (const BoundaryHeat& b : direct.boundaries) heat += b.heat_in;
  EXPECT_NEAR(heat + direct.total_power, 0, 1e-9 * direct.total_power);
  EXPECT_NEAR(direct.total_power, 2.0, 1e-12);
  EXPECT_EQ(m.region_of(0) == 1 || m.region_of(0) == 2, true);
  EXPECT_GT(region_of(direct, 2).max_temperature, region_of(direct, 1).mean_temperature);
  EXPECT_GE(x_of(m, direct.max_node), 0.003 - 1e-12);
  EXPECT_LE(x_of(m, direct.max_node), 0.007 + 1e-12);
  EXPECT_GE(m.xyz[3 * direct.max_node + 2], 0.001 - 1e-12);  // on the die (z >= 1 mm)
}

}  // namespace
}  // namespace foxi
