// foxi solve --physics current / electrostatic on the shipped models, whose conductivities span 20
// orders of magnitude (copper 6e7, solder 7.7e6, polysilicon 1e5, silicon 4.3e-4, oxide and FR-4
// 1e-14 S/m): the resistance passes its balance checks (exit status 0, no UNRELIABLE line) with the
// default solver and with AMG, and agrees with an estimate made by hand:
//
// - flip_chip (terminals on the bumps' two ends): four 16-gon solder cylinders in parallel,
//   R = h / (sigma 4 A), A = 8 r^2 sin(pi / 8): 0.2 mm / (7.7e6 S/m * 4 * 0.275532 mm^2) = 2.35672e-5
//   ohm, exact for P1 (the field in a prism between its end faces is linear); what surrounds the bumps
//   conducts 1e20 times less.
// - trench: the 0.1 um oxide liner between the polysilicon fill (1 V) and the silicon (grounded) carries
//   the whole resistance (both neighbours conduct 1e10 times better). Thomson's principle with the
//   current straight across the two side walls (0.6 um) and the bottom (0.4 um), 1 um deep, bounds it
//   from above: R <= t / (sigma A) = 0.1 um / (1e-14 S/m * 1.6 um^2) = 6.25e18 ohm (the conforming P1
//   conductance is at least the true one, so the computed R is below the true one too). Dirichlet's
//   principle with the potential linear across each wall and (x z) / t^2 in the two corner squares
//   bounds it from below: G <= sigma * 1 um * (6 + 6 + 4 + 2/3 + 2/3), R >= 5.769e18 ohm. The model's
//   mesh (0.15 um, one tet across the liner) gives 5.569e18, 3.5 % under; at 0.04 um (582k tets)
//   5.800e18, inside the bounds.
// - via_in_dielectric: copper via (1 V) on a 0.5 mm silicon block grounded below. Thomson (the current
//   straight down the 16-gon cylinder under the via) bounds R <= 0.5 mm / (4.3e-4 S/m * 0.122459 mm^2)
//   = 9.495e6 ohm; Dirichlet (the potential linear in z through the silicon, 1 V on its whole top)
//   R >= 0.5 mm / (4.3e-4 S/m * 1 mm^2) = 1.163e6 ohm; a disk on a half-space, 1 / (4 sigma a) =
//   2.907e6 ohm, lies between.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "test_util.hpp"

namespace foxi {
namespace {

class ContrastCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::have_program("tetgen")) GTEST_SKIP() << "tetgen not installed";
    if (!std::filesystem::exists(test::cli_path())) GTEST_SKIP() << "the foxi program is not built";
  }
  // Runs foxi; returns its exit status and leaves its output in log_.
  int foxi(const std::string& args) {
    const int status = test::run("'" + test::cli_path() + "' " + args, dir_ / "out.log");
    log_ = test::read_text(dir_ / "out.log");
    return status;
  }
  std::string model(const std::string& name) const { return "'" + test::models_dir() + name + "'"; }
  // The number after `key` in the log (NaN when absent).
  double number_after(const std::string& key) const {
    const auto at = log_.find(key);
    if (at == std::string::npos) return std::nan("");
    return std::strtod(log_.c_str() + at + key.size(), nullptr);
  }
  // The resistance of a current solve; every check printed and passed.
  double resistance(const std::string& name, const std::string& solver) {
    EXPECT_EQ(foxi("solve " + model(name) + " --physics current --solver " + solver), 0) << log_;
    EXPECT_EQ(log_.find("UNRELIABLE"), std::string::npos) << log_;
    for (const char* check : {"check Kirchhoff", "check Maxwell signs", "check residual", "check energy"})
      EXPECT_NE(log_.find(check), std::string::npos) << check << "\n" << log_;
    EXPECT_EQ(log_.find("FAIL"), std::string::npos) << log_;
    return number_after("resistance ");
  }
  test::TempDir dir_;
  std::string log_;
};

TEST_F(ContrastCliTest, FlipChipBumpResistance) {
  const double estimate = 0.2e-3 / (7.7e6 * 4 * 8 * 0.3e-3 * 0.3e-3 * std::sin(3.14159265358979 / 8));
  for (const char* solver : {"auto", "amg"}) {
    SCOPED_TRACE(solver);
    EXPECT_NEAR(resistance("flip_chip.toml", solver), estimate, 1e-6 * estimate);
  }
}

TEST_F(ContrastCliTest, TrenchLinerResistance) {
  for (const char* solver : {"auto", "amg"}) {
    SCOPED_TRACE(solver);
    const double r = resistance("trench.toml", solver);
    EXPECT_GT(r, 5.769e18 * 0.95);  // P1 lies below the true R (by 3.5 % on this mesh, one tet across)
    EXPECT_LT(r, 6.25e18);
  }
}

TEST_F(ContrastCliTest, ViaSpreadingResistance) {
  for (const char* solver : {"auto", "amg"}) {
    SCOPED_TRACE(solver);
    const double r = resistance("via_in_dielectric.toml", solver);
    EXPECT_GT(r, 1.163e6);
    EXPECT_LT(r, 9.495e6);
  }
}

// Electrostatics of the flip chip: the bumps are metal on the die's pad, part of its conductor (not a
// dielectric of permittivity 1); 'foxi model check' says so before any meshing.
TEST_F(ContrastCliTest, FlipChipBumpsBelongToTheDieConductor) {
  ASSERT_EQ(foxi("model check " + model("flip_chip.toml")), 0) << log_;
  EXPECT_NE(log_.find("conductor 'die'"), std::string::npos) << log_;
  EXPECT_NE(log_.find("with the metal parts bumps"), std::string::npos) << log_;
  ASSERT_EQ(foxi("solve " + model("flip_chip.toml") + " --physics electrostatic"), 0) << log_;
  EXPECT_NE(log_.find("with the metal of region 3 (bumps)"), std::string::npos) << log_;
  EXPECT_EQ(log_.find("UNRELIABLE"), std::string::npos) << log_;
}

}  // namespace
}  // namespace foxi
