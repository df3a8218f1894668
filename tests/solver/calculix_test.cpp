// foxi's thermal solver against CalculiX (ccx) on the same mesh and problem (P1 tets = C3D4): the
// nodal temperatures must agree to the precision of ccx's ASCII .frd (6 significant digits).
#include "foxi/solver/calculix.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "foxi/model/io_error.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/solver/thermal.hpp"
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

class CalculixTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::have_program("tetgen") || !test::have_program("ccx"))
      GTEST_SKIP() << "tetgen or ccx not installed";
  }
};

// Every kind of condition at once: fixed bottom, convection on the tops, a flux into the substrate
// sides, a heat source in the die. ccx integrates *FILM at the face centroid; with the same rule foxi
// must reproduce ccx to its 6 printed digits. With foxi's exact (consistent) rule the two differ by
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
  EXPECT_LT(same_rule, 1e-5);
  EXPECT_LT(exact_rule, 1e-3);
  EXPECT_GT(r.max_temperature - 300, 10.0);  // a problem with a real temperature rise
}

TEST(FrdReader, RejectsMalformedFiles) {
  test::TempDir dir;
  test::write_text(dir / "bad.frd", "    1C\n -4  NDTEMP      1    1\n -1         1 3.0000\n -3\n");
  EXPECT_THROW(read_frd(dir / "bad.frd"), IoError);
  test::write_text(dir / "ok.frd",
                   "    1C\n -4  NDTEMP      1    1\n -5  T           1    1    0    0\n"
                   " -1         1 3.00000E+02\n -1         2-1.25000E+01\n -3\n");
  const auto blocks = read_frd(dir / "ok.frd");
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_EQ(blocks[0].name, "NDTEMP");
  EXPECT_EQ(blocks[0].node, (std::vector<std::uint32_t>{1, 2}));
  EXPECT_EQ(blocks[0].values, (std::vector<double>{300.0, -12.5}));
  EXPECT_THROW(read_frd(dir / "missing.frd"), IoError);
}

}  // namespace
}  // namespace foxi
