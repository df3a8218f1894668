// Transient heat conduction against exact solutions: a uniformly heated body with adiabatic walls
// (T rises at P / (rho c V), exactly for the lumped capacity), a convectively cooled body at Biot
// 1e-3 (exponential), the semi-infinite slab with a fixed surface temperature (erfc), the order of
// accuracy in time of both schemes against a fine-step reference, the long-time limit against the
// steady solver on the same mesh, and the energy balance asserted in every run.
#include "foxi/solver/transient.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "foxi/model/io_error.hpp"
#include "layered_box.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

// Layered box tags: 1 x = 0, 2 x = lx, 3 y = 0, 4 y = ly, 5 z = 0, 6 z = lz.
TransientParams base(const Mesh& m, double k, double rho_c) {
  TransientParams p;
  for (const Region& r : m.regions) {
    p.thermal.conductivity.push_back({r.id, k});
    p.heat_capacity.push_back({r.id, rho_c});
  }
  p.thermal.solver.kind = LinearSolverKind::direct;
  return p;
}

void expect_balanced(const TransientReport& rep) {
  ASSERT_FALSE(rep.checks.empty());
  for (const BalanceCheck& c : rep.checks)
    EXPECT_TRUE(c.passed) << c.name << " " << c.figure << " > " << c.tolerance;
}

const std::vector<double>& temperature(const Mesh& m) {
  for (const Field& f : m.fields)
    if (f.name == "temperature") return f.values;
  throw std::runtime_error("no temperature");
}

TEST(Transient, AdiabaticBodyHeatedUniformlyRisesLinearly) {
  Mesh m = test::layered_box_mesh(0.02, 0.01, {0, 0.005}, 1e-8);
  const double V = 0.02 * 0.01 * 0.005, rho_c = 2e6, P = 3;
  for (TimeScheme scheme : {TimeScheme::euler, TimeScheme::bdf2}) {
    TransientParams p = base(m, 50, rho_c);
    p.power.push_back({1, PowerWaveform::step_of(P)});
    p.initial_temperature = 300;
    p.end_time = 10;
    p.steps = 7;
    p.scheme = scheme;
    p.junctions = {1};
    const TransientReport r = solve_transient_thermal(m, p);
    expect_balanced(r);
    // Every node at 300 + P t / (rho c V): the source density is uniform and the lumped capacity is
    // proportional to the same nodal volume shares, so no gradient ever forms.
    const double exact = 300 + P * 10 / (rho_c * V);
    for (double t : temperature(m)) EXPECT_NEAR(t, exact, 1e-9 * exact);
    ASSERT_EQ(r.times.size(), 8u);
    for (std::size_t n = 0; n < r.times.size(); ++n)
      EXPECT_NEAR(r.junction_temperature[0][n], 300 + P * r.times[n] / (rho_c * V), 1e-9 * exact);
    EXPECT_NEAR(r.stored_energy, P * 10, 1e-9 * P * 10);
  }
}

TEST(Transient, ConvectivelyCooledBodyDecaysExponentially) {
  // 10 x 10 x 10 mm, k 400, h 40: Biot h L / k = 1e-3, so the body is one lumped capacity with
  // tau = rho c V / (h A). Lumped-body error O(Bi) ~ 1e-3 and BDF2's O((dt/tau)^2) = 1e-4 at 100 steps
  // over one tau: the drop within 3e-3 of itself.
  const double L = 0.01, h = 40, rho_c = 3e6, tinf = 300, t0 = 400;
  Mesh m = test::layered_box_mesh(L, L, {0, L}, 1e-8);
  for (TimeScheme scheme : {TimeScheme::euler, TimeScheme::bdf2}) {
    TransientParams p = base(m, 400, rho_c);
    for (std::int32_t tag = 1; tag <= 6; ++tag) p.thermal.convection.push_back({tag, h, tinf});
    p.initial_temperature = t0;
    const double tau = rho_c * L * L * L / (h * 6 * L * L);
    p.end_time = tau;
    p.steps = scheme == TimeScheme::euler ? 2000 : 100;  // Euler's O(dt / tau) error: 5e-4 at 2000
    p.scheme = scheme;
    p.junctions = {1};
    const TransientReport r = solve_transient_thermal(m, p);
    expect_balanced(r);
    for (std::size_t n = 0; n < r.times.size(); n += p.steps / 10) {
      const double exact = tinf + (t0 - tinf) * std::exp(-r.times[n] / tau);
      EXPECT_NEAR(r.junction_temperature[0][n], exact, 3e-3 * (t0 - tinf)) << "t = " << r.times[n];
    }
    // The heat that left against the stored energy lost, in joules: exact for Euler; BDF2 within
    // its O(dt) end terms (TransientReport::heat_in), about 0.3% here.
    const double exact_loss = rho_c * L * L * L * (t0 - tinf) * (1 - std::exp(-1.0));
    EXPECT_NEAR(-r.stored_energy, exact_loss, 3e-3 * exact_loss);
    EXPECT_NEAR(r.heat_in, r.stored_energy,
                (scheme == TimeScheme::euler ? 1e-6 : 1e-2) * std::abs(r.stored_energy));
  }
}

// No power and the body at its ambient (an outside probe): nothing flows but round-off, and the energy
// check failed (0.83) measuring that round-off against itself. It passes now, with either solver and
// scheme, and the temperature stays at the ambient.
TEST(Transient, BodyAtItsAmbientWithNoPowerPassesItsChecks) {
  const double L = 0.01;
  Mesh m = test::layered_box_mesh(L, L, {0, L}, 1e-8);
  for (LinearSolverKind kind : {LinearSolverKind::direct, LinearSolverKind::cg_amg})
    for (TimeScheme scheme : {TimeScheme::euler, TimeScheme::bdf2}) {
      TransientParams p = base(m, 1e4, 1e6);
      p.thermal.solver.kind = kind;
      for (std::int32_t tag = 1; tag <= 6; ++tag) p.thermal.convection.push_back({tag, 100, 300});
      p.initial_temperature = 300;
      p.end_time = 100;
      p.steps = 20;
      p.scheme = scheme;
      const TransientReport r = solve_transient_thermal(m, p);
      expect_balanced(r);
      for (double t : temperature(m)) EXPECT_NEAR(t, 300, 1e-7);  // the CG stops at 1e-10 of the right side
    }
}

TEST(Transient, SemiInfiniteSlabFollowsErfc) {
  // A column 0.5 m along z, alpha = k / (rho c) = 1 m^2/s, T = 1 at z = 0 from t = 0, 0 inside:
  // T = erfc(z / (2 sqrt(alpha t))). At t = 0.01 s the front reaches ~0.3 m, well short of the far
  // end. Mesh edge ~ 0.015 m, 200 BDF2 steps: every node with z >= 0.03 within 2e-3 of erfc.
  Mesh m = test::layered_box_mesh(0.03, 0.03, {0, 0.5}, 3e-7);
  TransientParams p = base(m, 1, 1);
  p.thermal.fixed.push_back({5, 1.0});
  p.initial_temperature = 0;
  p.end_time = 0.01;
  p.steps = 200;
  const TransientReport r = solve_transient_thermal(m, p);
  expect_balanced(r);
  const std::vector<double>& t = temperature(m);
  double worst = 0;
  for (std::size_t v = 0; v < m.node_count(); ++v) {
    const double z = m.xyz[3 * v + 2];
    if (z < 0.03) continue;
    worst = std::max(worst, std::abs(t[v] - std::erfc(z / (2 * std::sqrt(0.01)))));
  }
  EXPECT_LT(worst, 2e-3);  // measured 4.2e-4 (1948 nodes)
}

// The junction temperature at t_end of a convectively cooled body at Biot 0.5 (a real gradient).
double cooled_at_end(const Mesh& m, TimeScheme scheme, std::size_t steps) {
  Mesh copy = m;
  TransientParams p = base(m, 1, 1e6);
  for (std::int32_t tag = 1; tag <= 6; ++tag) p.thermal.convection.push_back({tag, 50, 300});
  p.power.push_back({1, PowerWaveform::step_of(0.5)});
  p.initial_temperature = 300;
  p.end_time = 200;
  p.steps = steps;
  p.scheme = scheme;
  p.junctions = {1};
  const TransientReport r = solve_transient_thermal(copy, p);
  expect_balanced(r);
  return r.junction_temperature[0].back();
}

// Measured (78 nodes): Euler errors 0.0839, 0.0421, 0.0211 K (orders 1.00, 1.00); BDF2 8.9e-4,
// 2.2e-4, 5.2e-5 K (orders 2.05, 2.05).
TEST(Transient, OrderOfAccuracyInTimeIsOneForEulerAndTwoForBdf2) {
  Mesh m = test::layered_box_mesh(0.02, 0.02, {0, 0.02}, 2e-7);
  const double reference = cooled_at_end(m, TimeScheme::bdf2, 1280);
  for (TimeScheme scheme : {TimeScheme::euler, TimeScheme::bdf2}) {
    const double e1 = std::abs(cooled_at_end(m, scheme, 20) - reference);
    const double e2 = std::abs(cooled_at_end(m, scheme, 40) - reference);
    const double e4 = std::abs(cooled_at_end(m, scheme, 80) - reference);
    const double order1 = std::log2(e1 / e2), order2 = std::log2(e2 / e4);
    const double want = scheme == TimeScheme::euler ? 1 : 2;
    EXPECT_NEAR(order1, want, 0.2) << "errors " << e1 << " " << e2 << " " << e4;
    EXPECT_NEAR(order2, want, 0.2) << "errors " << e1 << " " << e2 << " " << e4;
  }
}

TEST(Transient, LongTimeLimitIsTheSteadySolution) {
  // Two layers, 1 W in the top one, bottom fixed at 300 K: after 30 time constants of the slowest
  // mode the transient is the steady solution of the same mesh to 1e-8 of the rise.
  Mesh m = test::layered_box_mesh(0.01, 0.01, {0, 0.002, 0.003}, 2e-10);
  TransientParams p = base(m, 10, 2e6);
  p.thermal.conductivity[1].k = 100;
  p.thermal.fixed.push_back({5, 300});
  p.power.push_back({2, PowerWaveform::step_of(1.0)});
  p.junctions = {2};
  const double tau = 2e6 * 0.003 * 0.003 / 10;  // L^2 / alpha of the slow layer
  p.end_time = 30 * tau;
  p.steps = 300;
  const TransientReport r = solve_transient_thermal(m, p);
  expect_balanced(r);
  const std::vector<double> transient = temperature(m);
  Mesh s = m;
  ThermalParams sp = p.thermal;
  sp.sources.push_back({2, 1.0, true});
  const ThermalReport steady = solve_thermal(s, sp);
  const std::vector<double>& ts = temperature(s);
  const double rise = steady.max_temperature - 300;
  ASSERT_GT(rise, 0);
  for (std::size_t v = 0; v < ts.size(); ++v) EXPECT_NEAR(transient[v], ts[v], 1e-8 * rise);
  // Starting from the steady state without power, the junction starts at 300 K.
  EXPECT_NEAR(r.junction_temperature[0][0], 300, 1e-9);
}

TEST(Transient, PulseAndTableWaveforms) {
  PowerWaveform pulse;
  pulse.kind = PowerWaveform::Kind::pulse;
  pulse.power = 2.0;
  pulse.width = 1e-3;
  pulse.period = 4e-3;
  pulse.count = 2;
  EXPECT_EQ(pulse.at(0), 2.0);
  EXPECT_EQ(pulse.at(0.5e-3), 2.0);
  EXPECT_EQ(pulse.at(1.5e-3), 0.0);
  EXPECT_EQ(pulse.at(4.5e-3), 2.0);
  EXPECT_EQ(pulse.at(8.5e-3), 0.0);  // count 2: over
  PowerWaveform table;
  table.kind = PowerWaveform::Kind::table;
  table.table = {{0, 0}, {1, 2}, {3, 0}};
  EXPECT_DOUBLE_EQ(table.at(0.5), 1.0);
  EXPECT_DOUBLE_EQ(table.at(2), 1.0);
  EXPECT_DOUBLE_EQ(table.at(5), 0.0);
}

// A waveform's energy against a brute-force sum of its values (1e6 midpoint samples).
TEST(Transient, WaveformEnergyIsTheIntegralOfItsPower) {
  PowerWaveform pulse;
  pulse.kind = PowerWaveform::Kind::pulse;
  pulse.power = 3.0;
  pulse.width = 0.7e-3;
  pulse.period = 2e-3;
  pulse.count = 4;
  PowerWaveform table;
  table.kind = PowerWaveform::Kind::table;
  table.table = {{1e-3, 2}, {4e-3, -1}, {6e-3, 5}};
  for (const PowerWaveform* w : {&pulse, &table})
    for (double t : {0.3e-3, 2.1e-3, 5.55e-3, 9e-3, 20e-3}) {
      const int n = 1000000;
      double sum = 0;
      for (int i = 0; i < n; ++i) sum += w->at((i + 0.5) * t / n);
      EXPECT_NEAR(w->energy(t), sum * t / n, 1e-5 * (std::abs(sum * t / n) + 1e-9)) << t;
      EXPECT_NEAR(w->mean(t, t + 1e-3), (w->energy(t + 1e-3) - w->energy(t)) / 1e-3, 1e-12);
    }
}

// Pulses shorter than a time step (0.5 ms every 2 ms, steps of 1 ms) into a body with adiabatic walls:
// the energy stored is the pulses' (10 x 3 W x 0.5 ms = 15 mJ). Sampling the power at each step's
// end stored 30 mJ (an outside probe), with the energy check passing.
TEST(Transient, PulsesShorterThanAStepPutInTheirEnergy) {
  Mesh m = test::layered_box_mesh(0.02, 0.01, {0, 0.005}, 1e-8);
  PowerWaveform pulse;
  pulse.kind = PowerWaveform::Kind::pulse;
  pulse.power = 3.0;
  pulse.width = 0.5e-3;
  pulse.period = 2e-3;
  for (TimeScheme scheme : {TimeScheme::euler, TimeScheme::bdf2}) {
    TransientParams p = base(m, 50, 2e6);
    p.power.push_back({1, pulse});
    p.initial_temperature = 300;
    p.end_time = 20e-3;
    p.steps = 20;
    p.scheme = scheme;
    const TransientReport r = solve_transient_thermal(m, p);
    expect_balanced(r);
    // Euler: exactly; BDF2 too (the steps near a pulse's edges are Euler steps).
    EXPECT_NEAR(r.stored_energy, 15e-3, 1e-9 * 15e-3);
  }
}

// BDF2 after a pulse (an outside probe): its history carried the pulse's last increment, and it kept
// adding half of it, 2.25 mJ stored for a 1.5 mJ pulse with the energy check passing. Two pulses of
// 3 W for 0.4 ms, at 0 and 5 ms, steps of 1 ms into adiabatic walls: 2.4 mJ stored, and after each
// pulse the temperature holds still; the steps away from the edges stay BDF2 (a smooth power keeps
// second order: OrderOfAccuracyInTimeIsOneForEulerAndTwoForBdf2).
TEST(Transient, Bdf2DoesNotOvershootAfterAPulse) {
  Mesh m = test::layered_box_mesh(0.02, 0.01, {0, 0.005}, 1e-8);
  PowerWaveform pulse;
  pulse.kind = PowerWaveform::Kind::pulse;
  pulse.power = 3.0;
  pulse.width = 0.4e-3;
  pulse.period = 5e-3;
  pulse.count = 2;
  TransientParams p = base(m, 50, 2e6);
  p.power.push_back({1, pulse});
  p.junctions = {1};
  p.initial_temperature = 300;
  p.end_time = 20e-3;
  p.steps = 20;
  p.scheme = TimeScheme::bdf2;
  const TransientReport r = solve_transient_thermal(m, p);
  expect_balanced(r);
  EXPECT_NEAR(r.stored_energy, 2.4e-3, 1e-9 * 2.4e-3);
  const double c = 2e6 * 0.02 * 0.01 * 0.005;  // J/K
  const std::vector<double>& tj = r.junction_temperature[0];
  ASSERT_EQ(tj.size(), 21u);
  for (std::size_t n = 1; n <= 4; ++n) EXPECT_NEAR(tj[n], 300 + 1.2e-3 / c, 1e-9) << n;
  for (std::size_t n = 6; n <= 20; ++n) EXPECT_NEAR(tj[n], 300 + 2.4e-3 / c, 1e-9) << n;
  // The edges: rises at 0 and 5 ms, falls at 0.4 and 5.4 ms.
  EXPECT_TRUE(pulse.jumps_in(-1e-3, 0.0));
  EXPECT_TRUE(pulse.jumps_in(0.0, 0.5e-3));
  EXPECT_FALSE(pulse.jumps_in(0.4e-3, 4.9e-3));
  EXPECT_TRUE(pulse.jumps_in(4.9e-3, 5e-3));
  EXPECT_TRUE(pulse.jumps_in(5.3e-3, 5.4e-3));
  EXPECT_FALSE(pulse.jumps_in(5.4e-3, 1.0));  // no third pulse
  EXPECT_FALSE(PowerWaveform::step_of(3).jumps_in(0.0, 1.0));
  EXPECT_TRUE(PowerWaveform::step_of(3).jumps_in(-1.0, 0.0));

  // A table that drops from 3 W to 0 within a microsecond at 5 s (15 J) is such a jump too (it stored
  // 18.9 J over 7 BDF2 steps; an outside probe); a gentle table is not.
  PowerWaveform drop;
  drop.kind = PowerWaveform::Kind::table;
  drop.table = {{0, 3}, {5, 3}, {5.000001, 0}, {100, 0}};
  EXPECT_TRUE(drop.jumps_in(4, 6));
  EXPECT_FALSE(drop.jumps_in(6, 10));
  PowerWaveform gentle;
  gentle.kind = PowerWaveform::Kind::table;
  gentle.table = {{0, 3}, {100, 3.1}};
  EXPECT_FALSE(gentle.jumps_in(-1, 200));
  for (const std::size_t steps : {3u, 7u}) {
    TransientParams q = base(m, 50, 2e6);
    q.power.push_back({1, drop});
    q.initial_temperature = 300;
    q.end_time = 25;
    q.steps = steps;
    const TransientReport t = solve_transient_thermal(m, q);
    expect_balanced(t);
    EXPECT_NEAR(t.stored_energy, 15 + 1.5e-6, 1e-9 * 15) << steps;  // the drop itself holds 1.5 uJ
  }
  // A ramp from 0 to 3 W over 2 s, then held: 12 J by 5 s. The BDF2 step after the Euler restart at
  // the ramp's top centres its power window too (one starting where Euler's ended stored 11.917 J).
  PowerWaveform ramp;
  ramp.kind = PowerWaveform::Kind::table;
  ramp.table = {{0, 0}, {2, 3}, {100, 3}};
  TransientParams q = base(m, 50, 2e6);
  q.power.push_back({1, ramp});
  q.initial_temperature = 300;
  q.end_time = 5;
  q.steps = 10;
  const TransientReport t = solve_transient_thermal(m, q);
  expect_balanced(t);
  EXPECT_NEAR(t.stored_energy, 12, 1e-9 * 12);
}

// A power drawn out of a body with adiabatic walls: 300 K - P t / C goes below 0 K with 100 W over 10 s
// (C = 2 J/K), which the absolute-zero check fails (-1362 K was printed with exit 0; an outside
// probe), and stays above with 3 W.
TEST(Transient, TemperaturesBelowAbsoluteZeroFailTheirCheck) {
  Mesh m = test::layered_box_mesh(0.02, 0.01, {0, 0.005}, 1e-8);
  for (const double watts : {3.0, 100.0}) {
    TransientParams p = base(m, 50, 2e6);
    p.power.push_back({1, PowerWaveform::step_of(-watts)});
    p.initial_temperature = 300;
    p.end_time = 10;
    p.steps = 5;
    const TransientReport r = solve_transient_thermal(m, p);
    const auto zero = std::find_if(r.checks.begin(), r.checks.end(),
                                   [](const BalanceCheck& c) { return c.name == "absolute zero"; });
    ASSERT_NE(zero, r.checks.end());
    EXPECT_NEAR(zero->figure, -(300 - watts * 10 / 2.0), 1e-6);
    EXPECT_EQ(zero->passed, watts < 60);
  }
}

TEST(TransientBadInput, PowerTableRowsAreRefusedWithTheirLine) {
  test::TempDir dir;
  test::write_text(dir / "ok.csv", "time_s,power_W\n# comment\n0,1\n0.5, 2\n\n1,0\n");
  const auto rows = read_power_table((dir / "ok.csv").string());
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[1].second, 2.0);
  const std::pair<const char*, std::uint64_t> bad[] = {{"0,1\n0.5,x\n", 2},
                                                       {"0,1\n0.5\n", 2},
                                                       {"0,1\n1,2\n1,3\n", 3},
                                                       {"0,1\n2,inf\n", 2},
                                                       {"# nothing\n", 1}};
  for (const auto& [text, line] : bad) {
    test::write_text(dir / "bad.csv", text);
    try {
      read_power_table((dir / "bad.csv").string());
      ADD_FAILURE() << "accepted: " << text;
    } catch (const IoError& e) {
      EXPECT_EQ(e.line(), line) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.csv"), std::string::npos) << e.what();
    }
  }
}

TEST(TransientBadInput, MissingHeatCapacityIsNamed) {
  Mesh m = test::layered_box_mesh(0.01, 0.01, {0, 0.01}, 1e-7);
  TransientParams p;
  p.thermal.conductivity.push_back({1, 1});
  p.thermal.fixed.push_back({5, 300});
  p.end_time = 1;
  p.steps = 1;
  try {
    solve_transient_thermal(m, p);
    ADD_FAILURE();
  } catch (const SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("heat capacity"), std::string::npos) << e.what();
  }
}

TEST(TransientBadInput, CancelThrowsFoxiCancelled) {
  Mesh m = test::layered_box_mesh(0.01, 0.01, {0, 0.01}, 1e-7);
  TransientParams p = base(m, 1, 1e6);
  p.thermal.fixed.push_back({5, 300});
  p.end_time = 1;
  p.steps = 10;
  p.on_step = [](std::size_t step, double, std::span<const double>) { return step < 3; };
  EXPECT_THROW(solve_transient_thermal(m, p), Cancelled);
}

}  // namespace
}  // namespace foxi
