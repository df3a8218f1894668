// The results record (foxi/solver/results.hpp): the values taken from a thermal report on one tet
// solved by hand, the JSON round trip (every double back bit for bit, NaN as null, escapes), the
// refusal of text that is not a record, and the observed order and Richardson extrapolation on
// values made from f(h) = f* + C h^p with known f*, p.
#include "foxi/solver/results.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "foxi/model/validate.hpp"
#include "foxi/solver/thermal.hpp"

namespace foxi {
namespace {

// The tet (0,0,0) (1,0,0) (0,1,0) (0,0,1), its face x = 0 tagged 1 ("cold"), the others 2; region
// 1 "block". With k = 1 W/(m K), T = 300 K on the face x = 0 and 1 W spread evenly in the tet, node 1
// is the only unknown: K_11 = k |grad phi_1|^2 V = 1 * 1 * 1/6, its load 1 W / 4, so T_1 = 300 + 1.5 K;
// the volume mean of the linear field is the mean of the four nodes, 300.375 K.
Mesh one_tet() {
  Mesh m;
  m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.tet = {0, 1, 2, 3};
  m.tet_region = {1};
  m.bface = {0, 2, 3, 0, 1, 2, 0, 1, 3, 1, 2, 3};
  m.bface_tag = {1, 2, 2, 2};
  m.regions.push_back({1, "block", kNone});
  m.boundaries.push_back({1, "cold"});
  m.boundaries.push_back({2, "other"});
  validate_and_repair(m);
  return m;
}

TEST(Results, ThermalValuesFromOneTetByHand) {
  Mesh m = one_tet();
  ThermalParams p;
  p.conductivity.push_back({1, 1.0});
  p.fixed.push_back({1, 300});
  p.sources.push_back({1, 1.0, true});
  p.resistances.push_back({{ThermalProbeKind::region_max, 1}, {ThermalProbeKind::boundary_mean, 1}});
  const ThermalReport report = solve_thermal(m, p);
  const RunResults r = thermal_results(m, report);
  EXPECT_EQ(r.physics, "thermal");
  EXPECT_EQ(r.status, RunStatus::ok);
  EXPECT_EQ(r.nodes, 4u);
  EXPECT_EQ(r.tets, 1u);
  ASSERT_NE(r.find("T_max"), nullptr);
  EXPECT_NEAR(r.find("T_max")->value, 301.5, 1e-9);
  EXPECT_TRUE(r.find("T_max")->key);
  EXPECT_EQ(r.find("T_max")->unit, "K");
  ASSERT_NE(r.find("T_mean[block]"), nullptr);
  EXPECT_NEAR(r.find("T_mean[block]")->value, 300.375, 1e-9);
  // theta = (301.5 - 300) K / 1 W, named as the CLI takes it
  ASSERT_NE(r.find("theta[block:cold]"), nullptr);
  EXPECT_NEAR(r.find("theta[block:cold]")->value, 1.5, 1e-9);
  EXPECT_EQ(r.find("theta[block:cold]")->unit, "K/W");
  // all the heat leaves through the cold face; the other faces are insulated and carry no value
  ASSERT_NE(r.find("heat_in[cold]"), nullptr);
  EXPECT_NEAR(r.find("heat_in[cold]")->value, -1.0, 1e-9);
  EXPECT_FALSE(r.find("heat_in[cold]")->key);
  EXPECT_EQ(r.checks.size(), report.checks.size());
  ASSERT_FALSE(r.texts.empty());
  EXPECT_EQ(r.texts[0].name, "T_max_region");
  EXPECT_EQ(r.texts[0].text, "block");
}

TEST(Results, JsonRoundTripsEveryFigure) {
  RunResults r;
  r.model = "a \"quoted\"\\ model\n.toml";
  r.physics = "current";
  r.parameters = {{"die_w", "2.5mm"}, {"h", "10 W/(m^2*K)"}};
  r.status = RunStatus::unreliable;
  r.error = "tab\there";
  r.nodes = 123456789;
  r.tets = 987654321;
  r.mesh_seconds = 0.1;
  r.solve_seconds = 1.0 / 3.0;
  r.wall_seconds = 1e-300;
  r.error_indicator = NAN;
  r.solver = "CG+SmoothedAggregationAMG";
  r.values = {{"R", "ohm", 6.670000000000001e10, true},
              {"G[a,b]", "S", -1.2345678901234567e-17, true},
              {"odd", "", std::numeric_limits<double>::infinity(), false},
              {"tiny", "m", 5e-324, false}};
  r.texts = {{"condition[cold]", "fixed"}, {"metal[a]", "bump+pad \u00b5"}};
  r.checks = {make_check("Kirchhoff", "column sums", 2e-3, 1e-6), make_check("energy", "ok", 0, 1e-6)};
  const RunResults back = parse_results_json(results_json(r));
  EXPECT_EQ(back.model, r.model);
  EXPECT_EQ(back.physics, r.physics);
  ASSERT_EQ(back.parameters.size(), 2u);
  EXPECT_EQ(back.parameters[1].text, "10 W/(m^2*K)");
  EXPECT_EQ(back.status, RunStatus::unreliable);
  EXPECT_EQ(back.error, r.error);
  EXPECT_EQ(back.nodes, r.nodes);
  EXPECT_EQ(back.tets, r.tets);
  EXPECT_EQ(back.mesh_seconds, r.mesh_seconds);
  EXPECT_EQ(back.solve_seconds, r.solve_seconds);
  EXPECT_EQ(back.wall_seconds, r.wall_seconds);
  EXPECT_TRUE(std::isnan(back.error_indicator));
  EXPECT_EQ(back.solver, r.solver);
  ASSERT_EQ(back.values.size(), r.values.size());
  for (std::size_t i = 0; i < r.values.size(); ++i) {
    EXPECT_EQ(back.values[i].name, r.values[i].name);
    EXPECT_EQ(back.values[i].unit, r.values[i].unit);
    EXPECT_EQ(back.values[i].key, r.values[i].key);
    if (std::isfinite(r.values[i].value))
      EXPECT_EQ(back.values[i].value, r.values[i].value) << r.values[i].name;  // bit for bit
    else
      EXPECT_TRUE(std::isnan(back.values[i].value));  // JSON has no infinity: null
  }
  ASSERT_EQ(back.texts.size(), 2u);
  EXPECT_EQ(back.texts[1].name, "metal[a]");
  EXPECT_EQ(back.texts[1].text, r.texts[1].text);
  ASSERT_EQ(back.checks.size(), 2u);
  EXPECT_FALSE(back.checks[0].passed);
  EXPECT_EQ(back.checks[0].figure, 2e-3);
  EXPECT_TRUE(back.checks[1].passed);
}

TEST(Results, RefusesWhatIsNotARecord) {
  EXPECT_THROW(parse_results_json(""), std::runtime_error);
  EXPECT_THROW(parse_results_json("{\"model\": \"x\"}"), std::runtime_error);  // no foxi_results tag
  EXPECT_THROW(parse_results_json("{\"foxi_results\": 1, \"values\": [{\"name\": }]}"), std::runtime_error);
  EXPECT_THROW(parse_results_json("{\"foxi_results\": 1} trailing"), std::runtime_error);
  EXPECT_THROW(parse_results_json("{\"foxi_results\": 1, \"model\": \"unfinished}"), std::runtime_error);
  // members it does not know, of any type, are skipped
  const RunResults r =
      parse_results_json("{\"foxi_results\": 1, \"later\": {\"a\": [1, true, null, \"x\"]}, \"tets\": 7}");
  EXPECT_EQ(r.tets, 7u);
}

TEST(Results, ObservedOrderOfAKnownPowerLaw) {
  // f = 4 + 3 h^2 at non-uniform ratios
  auto f = [](double h) { return 4 + 3 * h * h; };
  EXPECT_NEAR(observed_order(f(1), f(0.7), f(0.45), 1, 0.7, 0.45), 2, 1e-9);
  // and of order 1.3, decreasing
  auto g = [](double h) { return 10 - 2 * std::pow(h, 1.3); };
  EXPECT_NEAR(observed_order(g(0.3), g(0.2), g(0.11), 0.3, 0.2, 0.11), 1.3, 1e-9);
  // no asymptotic range: differences of opposite signs, or a zero one
  EXPECT_TRUE(std::isnan(observed_order(1, 2, 1.5, 1, 0.5, 0.25)));
  EXPECT_TRUE(std::isnan(observed_order(1, 1, 1, 1, 0.5, 0.25)));
}

TEST(Results, ConvergenceTableExtrapolatesThreeAndMoreLevels) {
  const std::vector<double> h3 = {1, 0.66, 0.43}, h5 = {1, 0.8, 0.61, 0.5, 0.37};
  for (const auto& h : {h3, h5}) {
    std::vector<RunResults> levels(h.size());
    for (std::size_t k = 0; k < h.size(); ++k) {
      levels[k].values = {{"T_max", "K", 350 - 8 * std::pow(h[k], 1.7), true},
                          {"iterations", "", double(k), false}};
    }
    const std::vector<ConvergenceRow> rows = convergence_table(levels, h);
    ASSERT_EQ(rows.size(), 1u);  // the key value only
    EXPECT_EQ(rows[0].name, "T_max");
    EXPECT_EQ(rows[0].level_values.size(), h.size());
    EXPECT_NEAR(rows[0].order, 1.7, 1e-6);
    EXPECT_NEAR(rows[0].extrapolated, 350, 1e-6);
    EXPECT_NEAR(rows[0].error_estimate, 8 * std::pow(h.back(), 1.7), 1e-6);
  }
  // two levels: no order
  std::vector<RunResults> two(2);
  two[0].values = {{"R", "ohm", 1, true}};
  two[1].values = {{"R", "ohm", 2, true}};
  const auto rows = convergence_table(two, {1, 0.5});
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(std::isnan(rows[0].order));
  EXPECT_THROW(convergence_table(two, {1}), std::invalid_argument);
}

}  // namespace
}  // namespace foxi
