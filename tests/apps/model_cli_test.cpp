// foxi model check|plc: exit statuses, the PLC file it writes (read back and meshed by the tetgen
// program), --set, and errors that name the file and the entity.
#include <gtest/gtest.h>

#include <string>

#include "foxi/model/plc.hpp"
#include "test_util.hpp"

namespace {

using foxi::test::TempDir;
namespace test = foxi::test;

const std::string kModels = std::string(FOXI_TEST_DATA_DIR) + "/../../models/";

int foxi_cli(const std::string& args, const std::filesystem::path& log) {
  return test::run("'" + test::cli_path() + "' " + args, log);
}

TEST(ModelCli, CheckReportsPartsBoundariesAndParameters) {
  TempDir dir;
  ASSERT_EQ(foxi_cli("model check '" + kModels + "flip_chip.toml' --set die_w=7mm", dir / "out.txt"), 0);
  const std::string out = test::read_text(dir / "out.txt");
  for (const char* s :
       {"substrate", "underfill", "bumps", "die", "sac305", "bumps/die", "die.top", "from --set"})
    EXPECT_NE(out.find(s), std::string::npos) << s << " missing in:\n" << out;
  // the die is 7 x 7 x 0.5 mm with --set die_w=7mm
  EXPECT_NE(out.find("24.5 mm^3"), std::string::npos) << out;
}

TEST(ModelCli, PlcIsWrittenAndTetgenMeshesIt) {
  if (!test::have_program("tetgen")) GTEST_SKIP() << "no tetgen program";
  TempDir dir;
  ASSERT_EQ(
      foxi_cli("model plc '" + kModels + "via_in_dielectric.toml' -o '" + (dir / "v.poly").string() + "'",
               dir / "out.txt"),
      0)
      << test::read_text(dir / "out.txt");
  const foxi::Plc plc = foxi::read_poly(dir / "v.poly");
  EXPECT_EQ(plc.regions.size(), 3u);
  ASSERT_EQ(
      test::run("cd '" + dir.path().string() + "' && tetgen -pq1.414a1e-11AQ v.poly", dir / "tetgen.log"), 0)
      << test::read_text(dir / "tetgen.log");
}

TEST(ModelCli, ErrorsAndUsage) {
  TempDir dir;
  EXPECT_EQ(foxi_cli("model check '" + kModels + "die_on_substrate.toml' --set nothing=1mm", dir / "e1.txt"),
            1);
  EXPECT_NE(test::read_text(dir / "e1.txt").find("'nothing'"), std::string::npos)
      << test::read_text(dir / "e1.txt");
  EXPECT_EQ(foxi_cli("model plc '" + kModels + "die_on_substrate.toml'", dir / "e2.txt"), 2);  // no -o
  EXPECT_EQ(foxi_cli("model frobnicate x.toml", dir / "e3.txt"), 2);
  EXPECT_EQ(foxi_cli("model check '" + (dir / "missing.toml").string() + "'", dir / "e4.txt"), 1);
  EXPECT_NE(test::read_text(dir / "e4.txt").find("missing.toml"), std::string::npos)
      << test::read_text(dir / "e4.txt");
}

}  // namespace
